// EglContext: an OpenGL context with no window, no display server and no GPU required.
//
// Design note. A headless renderer must start on a bare server, in a container, in CI. So:
//   * EGL, not GLX: GLX needs an X server (Xvfb would be one more process to babysit).
//   * eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA) first: it needs neither a display nor
//     a DRM node and lands on llvmpipe when there is no GPU. Fallback: EGL_EXT_platform_device
//     (enumerate EGL devices; what NVIDIA's driver offers). eglGetDisplay(EGL_DEFAULT_DISPLAY) is
//     not tried: it guesses a window system and fails without one.
//   * A surfaceless context (EGL_KHR_surfaceless_context) rendering into our own framebuffer
//     object, not a pbuffer: FBOs behave the same on every driver, can be resized without
//     recreating the context, and readback comes straight from the colour renderbuffer.
//     Rejected: pbuffers (need a config with EGL_PBUFFER_BIT and a new surface for every size),
//     OSMesa (deprecated, removed from Mesa 25.1), MSAA by default (about 4× the cost on llvmpipe).
// This header stays free of EGL and GL headers: everything driver-side lives in src/.
//
// Threading: an OpenGL context is current on one thread at a time. create() leaves the new context
// current on the calling thread; to draw from another thread call release() here and
// makeCurrent() there. Destroy the context after every renderer that uses it.
#pragma once

#include <weft/Result.h>
#include <weft/render/Image.h>

#include <memory>
#include <string>

namespace weft {

/// What EglContext::create() asks for.
struct ContextSettings {
  int width = 1280;        ///< pixels, framebuffer width (resizable later)
  int height = 720;        ///< pixels, framebuffer height
  int glMajorVersion = 3;  ///< minimum OpenGL core version; drivers return their newest (4.5 on llvmpipe)
  int glMinorVersion = 3;  ///< minimum OpenGL core minor version
  bool debugContext = false;  ///< asks for a debug context (slower; for chasing GL errors)
};

/// Headless EGL display + OpenGL core context + an RGBA8/depth-24 framebuffer object.
class EglContext {
 public:
  /// EGL and GL handles; defined in src/, never touched by callers.
  class Impl;

  /// Opens a display (surfaceless Mesa, else an EGL device), creates a core context, makes it
  /// current and builds the framebuffer. Never throws; the error names the missing package,
  /// extension or environment variable.
  static Result<EglContext> create(const ContextSettings& settings = {});

  /// Move-only; a moved-from context may only be destroyed or assigned to.
  EglContext(EglContext&&) noexcept;
  /// Move-only; destroys this context first.
  EglContext& operator=(EglContext&&) noexcept;
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;
  /// Deletes the framebuffer and the context; terminates the display with its last context.
  ~EglContext();

  /// Makes this context current on the calling thread.
  Status makeCurrent();
  /// Detaches this context from the calling thread (so another thread can make it current).
  void release();

  /// Reallocates the framebuffer at width × height pixels (no-op when the size is unchanged).
  Status resizeFramebuffer(int width, int height);
  /// Binds the framebuffer for drawing and sets the viewport to cover it.
  void bindFramebuffer();
  /// Framebuffer width in pixels.
  int width() const;
  /// Framebuffer height in pixels.
  int height() const;

  /// Reads the framebuffer into image (resized as needed, allocation reused), flipped so that
  /// rows run top-down. Waits for drawing to finish.
  void readPixels(Image& image);

  /// GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string& renderer() const;
  /// GL_VERSION, e.g. "4.5 (Core Profile) Mesa 22.3.6".
  const std::string& glVersion() const;
  /// Which EGL platform served the display: "surfaceless" or "device".
  const std::string& platform() const;

 private:
  friend class ClothRenderer;  // keeps a pointer to Impl, which survives moves of this object
  explicit EglContext(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> m_impl;
};

}  // namespace weft
