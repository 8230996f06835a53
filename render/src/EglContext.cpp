// Headless EGL context creation: surfaceless Mesa display, else an EGL device; core profile
// context with no surface; an FBO as the render target. See EglContext.h for why.
//
// Failure is expected on misconfigured machines (the build needs only libegl-dev and libgl-dev,
// the run needs Mesa's vendor library and DRI drivers), so every step returns an Error that says
// what to install or which variable to check, and nothing here aborts.
#include "EglContextImpl.h"

#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <sstream>
#include <vector>

namespace weft {
namespace {

constexpr const char* kInstallHint =
    "install libegl-mesa0 and libgl1-mesa-dri (Mesa's EGL and software rasteriser), or check "
    "__EGL_VENDOR_LIBRARY_FILENAMES / EGL_PLATFORM";

// Environment variables that change which EGL vendor or DRI driver gets loaded; echoed in errors
// when set, since a stale value is a common cause of "works on my machine".
constexpr const char* kEnvironmentVariables[] = {
    "__EGL_VENDOR_LIBRARY_FILENAMES", "__EGL_VENDOR_LIBRARY_DIRS", "EGL_PLATFORM",
    "LIBGL_DRIVERS_PATH", "MESA_LOADER_DRIVER_OVERRIDE", "GALLIUM_DRIVER", "LIBGL_ALWAYS_SOFTWARE"};

std::string environmentNote() {
  std::string note;
  for (const char* name : kEnvironmentVariables) {
    if (const char* value = std::getenv(name)) {
      note += note.empty() ? " (set: " : ", ";
      note += std::string(name) + "=" + value;
    }
  }
  return note.empty() ? note : note + ")";
}

bool hasExtension(const char* list, const char* name) {
  if (list == nullptr) return false;
  const std::size_t length = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += length) {
    // Whole words only: EGL_EXT_device_base must not match EGL_EXT_device_base_foo.
    const bool startsWord = p == list || p[-1] == ' ';
    const bool endsWord = p[length] == '\0' || p[length] == ' ';
    if (startsWord && endsWord) return true;
  }
  return false;
}

// eglTerminate() destroys every context on a display, and EGL hands out one display per platform
// and device, so two EglContexts share it. Count users; terminate with the last.
std::mutex g_displayMutex;
std::map<EGLDisplay, int> g_displayUsers;

void retainDisplay(EGLDisplay display) {
  std::lock_guard lock(g_displayMutex);
  ++g_displayUsers[display];
}

void releaseDisplay(EGLDisplay display) {
  std::lock_guard lock(g_displayMutex);
  auto it = g_displayUsers.find(display);
  if (it == g_displayUsers.end()) return;
  if (--it->second == 0) {
    g_displayUsers.erase(it);
    eglTerminate(display);
  }
}

struct OpenedDisplay {
  EGLDisplay display = EGL_NO_DISPLAY;
  std::string platform;
};

// Tries the surfaceless platform, then each EGL device. `tried` collects what failed, for the error.
OpenedDisplay openDisplay(std::string& tried) {
  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (clientExtensions == nullptr) {
    // libglvnd found no vendor library at all: the EGL ICD json or libEGL_mesa.so is missing.
    tried = "libEGL reports no client extensions (no EGL vendor library was loaded)";
    return {};
  }

  if (hasExtension(clientExtensions, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay display = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA,
                                               reinterpret_cast<void*>(EGL_DEFAULT_DISPLAY), nullptr);
    if (display != EGL_NO_DISPLAY && eglInitialize(display, nullptr, nullptr)) {
      return {display, "surfaceless"};
    }
    tried += std::string("surfaceless platform: eglInitialize failed (") + eglErrorName(eglGetError()) +
             "; usually the DRI driver swrast_dri.so from libgl1-mesa-dri is missing)";
  } else {
    tried += "EGL_MESA_platform_surfaceless not offered";
  }

  const bool canEnumerate = hasExtension(clientExtensions, "EGL_EXT_platform_device") &&
                            (hasExtension(clientExtensions, "EGL_EXT_device_enumeration") ||
                             hasExtension(clientExtensions, "EGL_EXT_device_base"));
  if (!canEnumerate) {
    tried += "; EGL_EXT_platform_device not offered";
    return {};
  }
  auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  if (queryDevices == nullptr) {
    tried += "; eglQueryDevicesEXT missing";
    return {};
  }
  constexpr EGLint kMaxDevices = 16;
  EGLDeviceEXT devices[kMaxDevices];
  EGLint deviceCount = 0;
  if (!queryDevices(kMaxDevices, devices, &deviceCount) || deviceCount == 0) {
    tried += "; no EGL devices enumerated";
    return {};
  }
  for (EGLint i = 0; i < deviceCount; ++i) {
    EGLDisplay display = eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    if (display != EGL_NO_DISPLAY && eglInitialize(display, nullptr, nullptr)) {
      return {display, "device"};
    }
  }
  tried += "; " + std::to_string(deviceCount) + " EGL device(s) found, none initialised";
  return {};
}

}  // namespace

const char* eglErrorName(EGLint error) {
  switch (error) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    default: return "unknown EGL error";
  }
}

EglContext::Impl::~Impl() {
  if (display == EGL_NO_DISPLAY) return;
  if (context != EGL_NO_CONTEXT) {
    // The FBO and renderbuffers die with the context; delete them early only if we can.
    if (eglGetCurrentContext() == context) {
      if (framebuffer != 0) glDeleteFramebuffers(1, &framebuffer);
      const GLuint buffers[] = {colorBuffer, depthBuffer};
      glDeleteRenderbuffers(2, buffers);
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    eglDestroyContext(display, context);
  }
  releaseDisplay(display);
}

Status EglContext::Impl::makeCurrent() {
  if (eglGetCurrentContext() == context) return {};
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    return Error{std::string("eglMakeCurrent failed (") + eglErrorName(eglGetError()) +
                 "); is the context current on another thread? call release() there first"};
  }
  return {};
}

Status EglContext::Impl::allocateFramebuffer(int newWidth, int newHeight) {
  GLint maxSize = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &maxSize);
  if (newWidth <= 0 || newHeight <= 0 || newWidth > maxSize || newHeight > maxSize) {
    return Error{"framebuffer size " + std::to_string(newWidth) + "x" + std::to_string(newHeight) +
                 " is out of range; width and height must be 1.." + std::to_string(maxSize) + " pixels"};
  }
  if (framebuffer == 0) {
    glGenFramebuffers(1, &framebuffer);
    glGenRenderbuffers(1, &colorBuffer);
    glGenRenderbuffers(1, &depthBuffer);
  }
  glBindRenderbuffer(GL_RENDERBUFFER, colorBuffer);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, newWidth, newHeight);
  glBindRenderbuffer(GL_RENDERBUFFER, depthBuffer);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, newWidth, newHeight);
  glBindRenderbuffer(GL_RENDERBUFFER, 0);

  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colorBuffer);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depthBuffer);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    std::ostringstream message;
    message << "framebuffer " << newWidth << "x" << newHeight << " (RGBA8 + depth24) is incomplete, status 0x"
            << std::hex << status << "; the driver does not support this format or size";
    return Error{message.str()};
  }
  width = newWidth;
  height = newHeight;
  bind();
  return {};
}

void EglContext::Impl::bind() {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glViewport(0, 0, width, height);
}

void EglContext::Impl::readPixels(Image& image) {
  image.resize(width, height);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
  // GL's rows run bottom-up; swap them in place so row 0 is the top.
  const std::size_t rowBytes = static_cast<std::size_t>(width) * 4;
  rowScratch.resize(rowBytes);
  for (int top = 0, bottom = height - 1; top < bottom; ++top, --bottom) {
    std::uint8_t* a = image.rgba.data() + static_cast<std::size_t>(top) * rowBytes;
    std::uint8_t* b = image.rgba.data() + static_cast<std::size_t>(bottom) * rowBytes;
    std::memcpy(rowScratch.data(), a, rowBytes);
    std::memcpy(a, b, rowBytes);
    std::memcpy(b, rowScratch.data(), rowBytes);
  }
}

Result<EglContext> EglContext::create(const ContextSettings& settings) {
  if (settings.width <= 0 || settings.height <= 0) {
    return Error{"ContextSettings: width and height must be positive (got " + std::to_string(settings.width) +
                 "x" + std::to_string(settings.height) + ")"};
  }
  if (settings.glMajorVersion < 3 || (settings.glMajorVersion == 3 && settings.glMinorVersion < 2)) {
    return Error{"ContextSettings: core profiles start at OpenGL 3.2; ask for 3.3 or later"};
  }

  std::string tried;
  OpenedDisplay opened = openDisplay(tried);
  if (opened.display == EGL_NO_DISPLAY) {
    return Error{std::string("no EGL display: ") + kInstallHint + environmentNote() + " [tried: " + tried + "]"};
  }
  auto impl = std::make_unique<Impl>();
  impl->display = opened.display;
  impl->platform = opened.platform;
  retainDisplay(impl->display);  // from here on, ~Impl releases it

  const char* displayExtensions = eglQueryString(impl->display, EGL_EXTENSIONS);
  if (!hasExtension(displayExtensions, "EGL_KHR_surfaceless_context")) {
    return Error{"EGL display (" + impl->platform + ") lacks EGL_KHR_surfaceless_context; " + kInstallHint};
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    return Error{"EGL display (" + impl->platform + ") offers no desktop OpenGL (only GLES?); " + kInstallHint};
  }

  // Without a surface the config only matters for compatibility; ask for nothing but GL support.
  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!hasExtension(displayExtensions, "EGL_KHR_no_config_context")) {
    const EGLint configAttributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_DONT_CARE,
                                       EGL_NONE};
    EGLint configCount = 0;
    if (!eglChooseConfig(impl->display, configAttributes, &config, 1, &configCount) || configCount == 0) {
      return Error{"EGL display (" + impl->platform + ") has no config with OpenGL support; " + kInstallHint};
    }
  }

  const EGLint contextAttributes[] = {
      EGL_CONTEXT_MAJOR_VERSION, settings.glMajorVersion,
      EGL_CONTEXT_MINOR_VERSION, settings.glMinorVersion,
      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
      EGL_CONTEXT_OPENGL_DEBUG, settings.debugContext ? EGL_TRUE : EGL_FALSE,
      EGL_NONE};
  impl->context = eglCreateContext(impl->display, config, EGL_NO_CONTEXT, contextAttributes);
  if (impl->context == EGL_NO_CONTEXT) {
    return Error{"could not create an OpenGL " + std::to_string(settings.glMajorVersion) + "." +
                 std::to_string(settings.glMinorVersion) + " core context on the " + impl->platform +
                 " EGL display (" + eglErrorName(eglGetError()) +
                 "); Mesa's llvmpipe offers 4.5 core: install libgl1-mesa-dri, and unset "
                 "MESA_GL_VERSION_OVERRIDE if it is set lower" + environmentNote()};
  }
  if (!eglMakeCurrent(impl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl->context)) {
    return Error{std::string("eglMakeCurrent without a surface failed (") + eglErrorName(eglGetError()) +
                 "); the driver does not honour EGL_KHR_surfaceless_context"};
  }

  auto glString = [](GLenum name) {
    const GLubyte* value = glGetString(name);
    return value != nullptr ? std::string(reinterpret_cast<const char*>(value)) : std::string("unknown");
  };
  impl->renderer = glString(GL_RENDERER);
  impl->version = glString(GL_VERSION);

  if (Status status = impl->allocateFramebuffer(settings.width, settings.height); !status) {
    return status.error();
  }
  return EglContext(std::move(impl));
}

EglContext::EglContext(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
EglContext::EglContext(EglContext&&) noexcept = default;
EglContext& EglContext::operator=(EglContext&&) noexcept = default;
EglContext::~EglContext() = default;

Status EglContext::makeCurrent() { return m_impl->makeCurrent(); }

void EglContext::release() {
  if (eglGetCurrentContext() == m_impl->context) {
    eglMakeCurrent(m_impl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
}

Status EglContext::resizeFramebuffer(int width, int height) {
  if (width == m_impl->width && height == m_impl->height) return {};
  if (Status status = m_impl->makeCurrent(); !status) return status;
  return m_impl->allocateFramebuffer(width, height);
}

void EglContext::bindFramebuffer() {
  if (m_impl->makeCurrent()) m_impl->bind();
}
int EglContext::width() const { return m_impl->width; }
int EglContext::height() const { return m_impl->height; }
void EglContext::readPixels(Image& image) {
  if (m_impl->makeCurrent()) m_impl->readPixels(image);
}
const std::string& EglContext::renderer() const { return m_impl->renderer; }
const std::string& EglContext::glVersion() const { return m_impl->version; }
const std::string& EglContext::platform() const { return m_impl->platform; }

}  // namespace weft
