// GlContext: backend choice, version fallback, entry-point loading and current-context bookkeeping. The EGL and
// OSMesa specifics are in context_egl.cpp and context_osmesa.cpp.
#include "pvrr/gl/context.h"

#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <functional>
#include <sstream>
#include <utility>
#include <vector>

#include "pvrr/base/error.h"
#include "pvrr/gl/gl.h"

namespace pvrr::gl {
namespace {

// The context current on this thread through GlContext (nullptr when none).
thread_local GlContext* t_current = nullptr;
// The context whose entry points glad's (process-wide) function pointers hold. Atomic: a context that shares
// another's entry points (ForeignContext::entry_points_of) reads it on its own thread.
std::atomic<const GlContext*> g_loaded_for{nullptr};

std::string glString(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? reinterpret_cast<const char*>(s) : std::string();
}

std::string versionLabel(int major, int minor) {
  return "GL " + std::to_string(major) + "." + std::to_string(minor) + " core";
}

bool containsSoftwareRasteriser(const std::string& renderer) {
  for (const char* s : {"llvmpipe", "softpipe", "swrast", "Software Rasterizer"}) {
    if (renderer.find(s) != std::string::npos) return true;
  }
  return false;
}

bool hasExtension(const char* name) {
  GLint n = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &n);
  for (GLint i = 0; i < n; ++i) {
    const GLubyte* e = glGetStringi(GL_EXTENSIONS, GLuint(i));
    if (e && std::string(reinterpret_cast<const char*>(e)) == name) return true;
  }
  return false;
}

// The memory budget of queryGlLimits and where it comes from.
void memoryBudget(GlLimits& g) {
  if (const char* env = std::getenv("PVRR_GPU_MEMORY_MB"); env && *env) {
    char* end = nullptr;
    const double mb = std::strtod(env, &end);
    if (end == env || *end != '\0' || !(mb > 0) || !(mb < 1e12))
      throw Error(std::string("PVRR_GPU_MEMORY_MB: expected a positive number of MiB, got \"") + env + "\"");
    g.memory_bytes = mb * 1024.0 * 1024.0;
    g.memory_source = "PVRR_GPU_MEMORY_MB";
    return;
  }
  constexpr GLenum kNvxCurrentAvailableKb = 0x9049, kAtiTextureFreeKb = 0x87FC;
  GLint kb[4] = {0, 0, 0, 0};
  if (hasExtension("GL_NVX_gpu_memory_info")) {
    glGetIntegerv(kNvxCurrentAvailableKb, kb);
    g.memory_source = "the free video memory GL_NVX_gpu_memory_info reports; PVRR_GPU_MEMORY_MB sets it";
  } else if (hasExtension("GL_ATI_meminfo")) {
    glGetIntegerv(kAtiTextureFreeKb, kb);
    g.memory_source = "the free texture memory GL_ATI_meminfo reports; PVRR_GPU_MEMORY_MB sets it";
  }
  while (glGetError() != GL_NO_ERROR) {
  }
  if (kb[0] > 0) {
    g.memory_bytes = double(kb[0]) * 1024.0;
    return;
  }
  g.memory_bytes = 0.75 * double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
  g.memory_source = "three quarters of the machine's memory; PVRR_GPU_MEMORY_MB sets it";
}

}  // namespace

GlLimits queryGlLimits() {
  GlLimits g;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &g.max_texture_size);
  glGetIntegerv(GL_MAX_CUBE_MAP_TEXTURE_SIZE, &g.max_cube_map_size);
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &g.max_renderbuffer_size);
  memoryBudget(g);
  return g;
}

GlBackend parseGlBackend(const std::string& name) {
  if (name == "auto") return GlBackend::Auto;
  if (name == "egl") return GlBackend::Egl;
  if (name == "osmesa") return GlBackend::OsMesa;
  throw Error("unknown GL backend \"" + name + "\": expected one of auto, egl, osmesa");
}

std::string glBackendName(GlBackend backend) {
  switch (backend) {
    case GlBackend::Auto: return "auto";
    case GlBackend::Egl: return "egl";
    case GlBackend::OsMesa: return "osmesa";
  }
  return "auto";
}

GlBackend glBackendFromEnvironment(GlBackend fallback) {
  const char* value = std::getenv("PVRR_GL");
  if (value == nullptr || *value == '\0') return fallback;
  try {
    return parseGlBackend(value);
  } catch (const Error& e) {
    throw Error(std::string("environment variable PVRR_GL: ") + e.what());
  }
}

GlContext::GlContext(std::unique_ptr<detail::ContextBackend> backend)
    : backend_(std::move(backend)), backend_name_(backend_->backendName()) {}

GlContext::~GlContext() {
  if (t_current == this) {
    backend_->releaseCurrent();
    t_current = nullptr;
  }
  if (g_loaded_for == this) g_loaded_for = nullptr;
}

GlContext* GlContext::current() { return t_current; }

bool GlContext::entryPointsLoaded() const {
  return g_loaded_for == this || (entry_points_of_ != nullptr && g_loaded_for == entry_points_of_);
}

void GlContext::loadEntryPoints() {
  const int version = gladLoadGL(backend_->loader());
  if (version == 0) {
    throw Error(backend_name_ + ": gladLoadGL failed (glGetString(GL_VERSION) returned nothing: no current context?)");
  }
  g_loaded_for = this;
}

std::unique_ptr<GlContext> GlContext::create(GlBackend requested, int major, int minor) {
  if (major * 10 + minor < kGlFloorMajor * 10 + kGlFloorMinor) {
    throw Error("GL " + std::to_string(major) + "." + std::to_string(minor) + " requested: pvrr needs at least GL " +
                std::to_string(kGlFloorMajor) + "." + std::to_string(kGlFloorMinor) + " core");
  }
  std::vector<std::pair<int, int>> versions{{major, minor}};
  if (major != kGlFloorMajor || minor != kGlFloorMinor) versions.emplace_back(kGlFloorMajor, kGlFloorMinor);

  using Factory = std::function<std::unique_ptr<detail::ContextBackend>(int, int)>;
  std::vector<std::pair<std::string, Factory>> paths;
  const auto egl = [](detail::EglPath p) { return [p](int a, int b) { return detail::createEglContext(p, a, b); }; };
  if (requested != GlBackend::OsMesa) {
    paths.emplace_back("EGL device (hardware)", egl(detail::EglPath::DeviceHardware));
    paths.emplace_back("EGL device (Mesa software)", egl(detail::EglPath::DeviceSoftware));
    paths.emplace_back("EGL surfaceless (Mesa)", egl(detail::EglPath::Surfaceless));
  }
  if (requested != GlBackend::Egl) paths.emplace_back("OSMesa", detail::createOsMesaContext);

  // A new context becomes current, so the previous one is detached first (and restored if all paths fail).
  GlContext* previous = t_current;
  if (previous != nullptr) {
    previous->backend_->releaseCurrent();
    t_current = nullptr;
  }

  std::ostringstream failures;
  for (const auto& path : paths) {
    const std::string& label = path.first;
    const Factory& factory = path.second;
    // One line per path; versions that failed for the same reason share it.
    std::vector<std::pair<std::string, std::string>> path_failures;  // (versions, reason)
    const auto flush = [&] {
      for (const auto& [v, reason] : path_failures) failures << "\n  " << label << ", " << v << ": " << reason;
    };
    for (const auto& [maj, min] : versions) {
      try {
        std::unique_ptr<GlContext> context(new GlContext(factory(maj, min)));
        t_current = context.get();
        context->loadEntryPoints();
        context->queryStrings();
        context->is_hardware_ =
            context->backend_->deviceIsHardware() && !containsSoftwareRasteriser(context->gl_renderer_);
        checkGlError("GL context creation");
        flush();
        context->creation_notes_ = failures.str();
        return context;
      } catch (const Error& e) {
        if (!path_failures.empty() && path_failures.back().second == e.what()) {
          path_failures.back().first += ", " + versionLabel(maj, min);
        } else {
          path_failures.emplace_back(versionLabel(maj, min), e.what());
        }
      }
    }
    flush();
  }
  if (previous != nullptr) {
    try {
      previous->makeCurrent();
    } catch (const Error&) {
      // The creation failure below is the error to report.
    }
  }
  throw Error("could not create an OpenGL context (--gl " + glBackendName(requested) + "); tried:" + failures.str());
}

void GlContext::queryStrings() {
  gl_version_ = glString(GL_VERSION);
  gl_renderer_ = glString(GL_RENDERER);
  gl_vendor_ = glString(GL_VENDOR);
  glsl_version_ = glString(GL_SHADING_LANGUAGE_VERSION);
  glGetIntegerv(GL_MAJOR_VERSION, &gl_major_);
  glGetIntegerv(GL_MINOR_VERSION, &gl_minor_);
  if (gl_major_ * 10 + gl_minor_ < kGlFloorMajor * 10 + kGlFloorMinor) {
    throw Error("context reports GL_VERSION \"" + gl_version_ + "\", below the 3.3 floor");
  }
}

namespace {

// A context made by someone else (GlContext::adopt): its owner's callbacks make it current and release it.
class ForeignBackend final : public detail::ContextBackend {
 public:
  explicit ForeignBackend(ForeignContext f) : f_(std::move(f)) {}
  void makeCurrent() override { f_.make_current(); }
  void releaseCurrent() noexcept override {
    if (f_.release_current) f_.release_current();
  }
  GLADloadfunc loader() const override { return reinterpret_cast<GLADloadfunc>(f_.get_proc_address); }
  std::string backendName() const override { return f_.backend_name; }
  bool deviceIsHardware() const override { return true; }  // decided by the renderer string alone

 private:
  ForeignContext f_;
};

}  // namespace

std::unique_ptr<GlContext> GlContext::adopt(ForeignContext foreign) {
  if (!foreign.make_current || !foreign.get_proc_address) {
    throw Error("GlContext::adopt: " + foreign.backend_name + ": no make-current callback or entry-point loader");
  }
  if (t_current != nullptr) {
    t_current->backend_->releaseCurrent();
    t_current = nullptr;
  }
  const GlContext* entry_points_of = foreign.entry_points_of;
  std::unique_ptr<GlContext> context(new GlContext(std::make_unique<ForeignBackend>(std::move(foreign))));
  context->entry_points_of_ = entry_points_of;
  context->backend_->makeCurrent();
  t_current = context.get();
  if (!context->entryPointsLoaded()) context->loadEntryPoints();
  context->queryStrings();
  context->is_hardware_ = !containsSoftwareRasteriser(context->gl_renderer_);
  checkGlError("adopting a GL context");
  return context;
}

void GlContext::makeCurrent() {
  if (t_current != nullptr && t_current != this) {
    t_current->backend_->releaseCurrent();
    t_current = nullptr;
  }
  backend_->makeCurrent();
  t_current = this;
  if (!entryPointsLoaded()) loadEntryPoints();
}

std::string glErrorName(unsigned int code) {
  switch (code) {
    case GL_NO_ERROR: return "GL_NO_ERROR";
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    case GL_STACK_UNDERFLOW: return "GL_STACK_UNDERFLOW";
    case GL_STACK_OVERFLOW: return "GL_STACK_OVERFLOW";
    default: {
      std::ostringstream os;
      os << "0x" << std::hex << code;
      return os.str();
    }
  }
}

void checkGlError(const char* where) {
  requireCurrentContext(where);
  std::string errors;
  // glGetError returns one recorded flag per call; a bounded loop guards against a lost context that keeps
  // reporting the same error forever.
  for (int i = 0; i < 32; ++i) {
    const GLenum e = glGetError();
    if (e == GL_NO_ERROR) break;
    errors += (errors.empty() ? "" : ", ") + glErrorName(e);
  }
  if (!errors.empty()) throw Error(std::string("GL error after ") + where + ": " + errors);
}

void requireCurrentContext(const char* what) {
  if (t_current == nullptr) {
    throw Error(std::string(what) + ": no current OpenGL context (create a pvrr::gl::GlContext first)");
  }
}

}  // namespace pvrr::gl
