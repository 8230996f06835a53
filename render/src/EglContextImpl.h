// EglContext::Impl: the EGL and GL handles behind EglContext; shared with ClothRenderer.
#pragma once

#include "GlHeaders.h"

#include <weft/Result.h>
#include <weft/render/EglContext.h>

#include <string>
#include <vector>

namespace weft {

class EglContext::Impl {
 public:
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  GLuint framebuffer = 0;
  GLuint colorBuffer = 0;
  GLuint depthBuffer = 0;
  int width = 0;
  int height = 0;
  std::string renderer;
  std::string version;
  std::string platform;
  std::vector<std::uint8_t> rowScratch;  ///< one row, for the top-down flip

  ~Impl();
  /// Makes the context current on this thread unless it already is.
  Status makeCurrent();
  /// (Re)allocates the renderbuffers at width × height; the context must be current.
  Status allocateFramebuffer(int newWidth, int newHeight);
  /// Binds the FBO for drawing and sets the viewport.
  void bind();
  /// glReadPixels into image, flipped to top-down rows.
  void readPixels(Image& image);
};

/// Name of an EGL error code, e.g. "EGL_BAD_MATCH".
const char* eglErrorName(EGLint error);

}  // namespace weft
