// PRIVATE to pvrr/gl .cpp files and tests/gl: the GL entry points (glad2) and GL error checking.
// Never include this from a public header. Include it before <GL/osmesa.h> (glad defines the GL/gl.h guard and
// GLAPI) and never together with VTK's vtk_glew.h.
//
// All gl* calls go through glad's function pointers, loaded for the current pvrr::gl::GlContext by
// GlContext::makeCurrent(). libOSMesa and GLVND's libOpenGL both export gl* symbols, so a direct call could reach
// the wrong library; glad's macros (glClear -> glad_glClear) make that impossible in files that include this.
#pragma once
#include <glad/gl.h>

#include <memory>
#include <string>

#include "pvrr/gl/context.h"

namespace pvrr::gl {

// The name of a glGetError code ("GL_INVALID_OPERATION"), or "0x...." for an unknown one.
std::string glErrorName(unsigned int code);

// Drains glGetError and throws pvrr::Error("GL error after <where>: GL_INVALID_ENUM, ...") if there was any.
void checkGlError(const char* where);

// Throws pvrr::Error naming `what` if no GlContext is current on this thread (a gl* call through an unloaded glad
// pointer would crash instead).
void requireCurrentContext(const char* what);

namespace detail {

// The backend behind GlContext's pimpl (context.cpp, context_egl.cpp, context_osmesa.cpp).
class ContextBackend {
 public:
  virtual ~ContextBackend() = default;
  // Makes the context current on this thread. Throws pvrr::Error naming the step on failure.
  virtual void makeCurrent() = 0;
  // Detaches the context from this thread if it is current (no-op otherwise). Never throws.
  virtual void releaseCurrent() noexcept = 0;
  // The proc-address function glad loads entry points with while this context is current.
  virtual GLADloadfunc loader() const = 0;
  virtual std::string backendName() const = 0;
  // True for a non-software EGL device; the renderer string is checked separately in context.cpp.
  virtual bool deviceIsHardware() const = 0;
};

// Which EGL display to try. DeviceHardware: the first EGL_EXT_platform_device device whose extensions lack
// EGL_MESA_device_software (each such device is tried in turn); DeviceSoftware: Mesa's software device;
// Surfaceless: EGL_MESA_platform_surfaceless.
enum class EglPath { DeviceHardware, DeviceSoftware, Surfaceless };

// Each returns a context that is current on this thread, or throws pvrr::Error naming the failed step (with the
// EGL error name). major.minor is the core profile version requested.
std::unique_ptr<ContextBackend> createEglContext(EglPath path, int major, int minor);
std::unique_ptr<ContextBackend> createOsMesaContext(int major, int minor);

// "EGL_BAD_MATCH" etc. for an eglGetError() code.
std::string eglErrorName(int code);

}  // namespace detail
}  // namespace pvrr::gl
