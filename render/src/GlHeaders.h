// The one place that includes EGL and OpenGL headers. Internal to weft::render: public headers and
// everything the engine sees stay free of graphics headers.
//
// GL_GLEXT_PROTOTYPES makes <GL/glext.h> declare the core 4.5 entry points, which libglvnd's
// libOpenGL.so exports and forwards to the current context's vendor (Mesa); hence no loader.
// EGL extension functions (eglQueryDevicesEXT) are not exported by libEGL and go through
// eglGetProcAddress instead.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>
