// Headless OpenGL contexts: EGL (a GPU device, Mesa's software device, or surfaceless Mesa) and OSMesa, chosen at
// run time. There is no default framebuffer to draw into: all rendering goes to a pvrr::gl::Framebuffer.
// A third kind is adopted, not created: a context someone else made (a window's, `pvrr view`), which the
// renderer draws into the same way (GlContext::adopt).
//
// Threading: GL entry points are process-wide (glad), so use GL from one thread at a time; makeCurrent() reloads
// them whenever a different context becomes current.
#pragma once
#include <functional>
#include <memory>
#include <string>

#include "pvrr/method/map_limits.h"

namespace pvrr::gl {

namespace detail {
class ContextBackend;
}
class GlContext;

// Auto: EGL device (hardware, then Mesa software) > EGL surfaceless > OSMesa. Egl: only the EGL paths.
// OsMesa: only OSMesa.
enum class GlBackend { Auto, Egl, OsMesa };

// "auto" | "egl" | "osmesa" (exactly, lower case). Throws pvrr::Error listing the choices otherwise.
GlBackend parseGlBackend(const std::string& name);
// The inverse of parseGlBackend.
std::string glBackendName(GlBackend backend);

// The backend named by the environment variable PVRR_GL, or `fallback` when it is unset or empty. Throws
// pvrr::Error naming PVRR_GL and the choices when it is set to something else. The CLI combines
// --gl flag > PVRR_GL > auto.
GlBackend glBackendFromEnvironment(GlBackend fallback = GlBackend::Auto);

// The lowest GL version pvrr runs on (core profile). create() tries the requested version first, then this one.
inline constexpr int kGlFloorMajor = 3;
inline constexpr int kGlFloorMinor = 3;

// A context pvrr did not create (a window toolkit's), for GlContext::adopt. pvrr never destroys it.
struct ForeignContext {
  using Proc = void (*)();
  std::string backend_name;              // what backendName() reports, e.g. "glfw-glx"
  std::function<void()> make_current;    // makes it current on this thread (throws pvrr::Error on failure)
  std::function<void()> release_current; // detaches it from this thread; never throws
  Proc (*get_proc_address)(const char* name) = nullptr;  // the entry-point loader while it is current
  // Another adopted context whose entry points are this one's: a second context of the same toolkit on the same
  // display (GLX's and EGL's entry points do not depend on the context). glad's process-wide pointers are then
  // not reloaded for this one, so that it can be current on a worker thread while the other draws on its own.
  const GlContext* entry_points_of = nullptr;
};

class GlContext {
 public:
  // Creates a core-profile context of version major.minor (falling back to 3.3 core where that fails), makes it
  // current on this thread and loads the GL entry points. Throws pvrr::Error listing every path tried and why
  // each failed (the step and the EGL error name, e.g. "eglCreateContext: EGL_BAD_MATCH").
  static std::unique_ptr<GlContext> create(GlBackend requested, int major = 4, int minor = 5);

  // Wraps a context that is current on this thread (a window's): loads the GL entry points from it and reads
  // its strings. Throws pvrr::Error when it is below the 3.3 core floor or no entry points load.
  static std::unique_ptr<GlContext> adopt(ForeignContext foreign);

  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // Makes this context current on this thread (releasing any other pvrr context first) and, when the last
  // current context was a different one, reloads the GL entry points for it.
  void makeCurrent();
  // The context current on this thread through makeCurrent()/create(), or nullptr.
  static GlContext* current();

  // "egl-device" (a non-software EGL device), "egl-device-software" (Mesa's software device),
  // "egl-surfaceless" or "osmesa".
  const std::string& backendName() const { return backend_name_; }
  const std::string& glVersion() const { return gl_version_; }    // GL_VERSION
  const std::string& glRenderer() const { return gl_renderer_; }  // GL_RENDERER
  const std::string& glVendor() const { return gl_vendor_; }      // GL_VENDOR
  const std::string& glslVersion() const { return glsl_version_; }  // GL_SHADING_LANGUAGE_VERSION
  int glMajor() const { return gl_major_; }  // GL_MAJOR_VERSION of the context actually created
  int glMinor() const { return gl_minor_; }
  // True on a GPU: an EGL device without EGL_MESA_device_software whose renderer is not a Mesa software
  // rasteriser (llvmpipe, softpipe, swrast).
  bool isHardware() const { return is_hardware_; }
  // Why the paths tried before this one failed, one "\n  <path>, <version>: <reason>" line each ("" when the first
  // path worked), e.g. for a verbose report of why Auto fell back to software.
  const std::string& creationNotes() const { return creation_notes_; }

 private:
  explicit GlContext(std::unique_ptr<detail::ContextBackend> backend);
  void loadEntryPoints();
  // Whether glad's pointers serve this context: loaded for it, or for the context it shares them with.
  bool entryPointsLoaded() const;
  void queryStrings();  // GL_VERSION etc. of the current context; throws below the floor

  std::unique_ptr<detail::ContextBackend> backend_;
  const GlContext* entry_points_of_ = nullptr;  // ForeignContext::entry_points_of
  std::string backend_name_, gl_version_, gl_renderer_, gl_vendor_, glsl_version_, creation_notes_;
  int gl_major_ = 0, gl_minor_ = 0;
  bool is_hardware_ = false;
};

// The current context's limits on map sizes (pvrr/method/map_limits.h): GL_MAX_TEXTURE_SIZE,
// GL_MAX_CUBE_MAP_TEXTURE_SIZE, GL_MAX_RENDERBUFFER_SIZE, and the memory budget: the environment variable
// PVRR_GPU_MEMORY_MB when set (a positive number of MiB; anything else throws pvrr::Error naming it), else the
// free video memory the GL reports (GL_NVX_gpu_memory_info, GL_ATI_meminfo), else three quarters of the
// machine's memory (a software rasteriser's textures live there; a GPU that reports nothing shares it or has
// less, so the check refuses only what cannot fit).
GlLimits queryGlLimits();

}  // namespace pvrr::gl
