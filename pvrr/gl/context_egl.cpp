// EGL contexts without a window system: EGL_EXT_platform_device (a GPU, or Mesa's software device) and
// EGL_MESA_platform_surfaceless. The context has no default framebuffer that pvrr draws to (see platform notes e).
#include "pvrr/gl/gl.h"  // glad first

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <map>
#include <mutex>
#include <sstream>
#include <vector>

#include "pvrr/base/error.h"

namespace pvrr::gl::detail {

std::string eglErrorName(int code) {
  switch (code) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
    case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
    case EGL_BAD_DEVICE_EXT: return "EGL_BAD_DEVICE_EXT";
    default: {
      std::ostringstream os;
      os << "0x" << std::hex << code;
      return os.str();
    }
  }
}

namespace {

// Throws "<step>: <EGL error name>" with the error eglGetError reports for the call that just failed.
[[noreturn]] void throwEgl(const std::string& step) { throw Error(step + ": " + eglErrorName(eglGetError())); }

// Whole-word search in a space-separated EGL extension string (nullptr counts as empty).
bool hasExtension(const char* extensions, const char* name) {
  if (extensions == nullptr) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = extensions; (p = std::strstr(p, name)) != nullptr; p += n) {
    const bool starts = p == extensions || p[-1] == ' ';
    const bool ends = p[n] == '\0' || p[n] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

template <class Fn>
Fn eglProc(const char* name) {
  return reinterpret_cast<Fn>(eglGetProcAddress(name));
}

// An EGLDisplay is a per-(platform, native display) singleton and eglTerminate destroys every context on it, so
// each display is terminated only when the last pvrr context on it goes.
class DisplayRefs {
 public:
  static void acquire(EGLDisplay d) {
    std::lock_guard<std::mutex> lock(mutex());
    ++counts()[d];
  }
  static void release(EGLDisplay d) {
    std::lock_guard<std::mutex> lock(mutex());
    auto it = counts().find(d);
    if (it == counts().end()) return;
    if (--it->second == 0) {
      counts().erase(it);
      eglTerminate(d);
    }
  }

 private:
  // Never destroyed, so a context destroyed during static destruction still finds them.
  static std::mutex& mutex() {
    static auto* m = new std::mutex;
    return *m;
  }
  static std::map<EGLDisplay, int>& counts() {
    static auto* c = new std::map<EGLDisplay, int>;
    return *c;
  }
};

class EglBackend final : public ContextBackend {
 public:
  EglBackend(std::string name, bool hardware) : name_(std::move(name)), hardware_(hardware) {}
  ~EglBackend() override {
    releaseCurrent();
    if (display_ != EGL_NO_DISPLAY) {
      if (surface_ != EGL_NO_SURFACE) eglDestroySurface(display_, surface_);
      if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
      if (initialized_) DisplayRefs::release(display_);
    }
  }

  // Initialises `display` and creates a core context of major.minor on it, current on this thread.
  void init(EGLDisplay display, int major, int minor) {
    display_ = display;
    EGLint egl_major = 0, egl_minor = 0;
    if (!eglInitialize(display_, &egl_major, &egl_minor)) throwEgl("eglInitialize");
    initialized_ = true;
    DisplayRefs::acquire(display_);
    if (!eglBindAPI(EGL_OPENGL_API)) throwEgl("eglBindAPI(EGL_OPENGL_API)");

    const char* extensions = eglQueryString(display_, EGL_EXTENSIONS);
    const bool no_config = hasExtension(extensions, "EGL_KHR_no_config_context");
    const bool surfaceless = hasExtension(extensions, "EGL_KHR_surfaceless_context");
    // Without EGL_KHR_surfaceless_context the context needs a (1x1 pbuffer) surface, hence a config.
    EGLConfig config = nullptr;  // EGL_NO_CONFIG_KHR
    if (!no_config || !surfaceless) {
      const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                       EGL_NONE};
      EGLint count = 0;
      if (!eglChooseConfig(display_, config_attribs, &config, 1, &count)) throwEgl("eglChooseConfig");
      if (count < 1) throw Error("eglChooseConfig: no config with EGL_OPENGL_BIT and EGL_PBUFFER_BIT");
    }
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,       major,
                                      EGL_CONTEXT_MINOR_VERSION,       minor,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_NONE};
    context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, context_attribs);
    if (context_ == EGL_NO_CONTEXT) {
      throwEgl("eglCreateContext(GL " + std::to_string(major) + "." + std::to_string(minor) + " core)");
    }
    if (!surfaceless) {
      const EGLint pbuffer_attribs[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
      surface_ = eglCreatePbufferSurface(display_, config, pbuffer_attribs);
      if (surface_ == EGL_NO_SURFACE) throwEgl("eglCreatePbufferSurface(1x1)");
    }
    makeCurrent();
  }

  void makeCurrent() override {
    if (!eglMakeCurrent(display_, surface_, surface_, context_)) throwEgl("eglMakeCurrent");
  }
  void releaseCurrent() noexcept override {
    if (context_ != EGL_NO_CONTEXT && eglGetCurrentContext() == context_) {
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
  }
  GLADloadfunc loader() const override { return reinterpret_cast<GLADloadfunc>(eglGetProcAddress); }
  std::string backendName() const override { return name_; }
  bool deviceIsHardware() const override { return hardware_; }

 private:
  std::string name_;
  bool hardware_ = false;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  bool initialized_ = false;
  EGLContext context_ = EGL_NO_CONTEXT;
  EGLSurface surface_ = EGL_NO_SURFACE;
};

std::unique_ptr<ContextBackend> createOnDevices(bool hardware, int major, int minor,
                                                PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(client, "EGL_EXT_platform_device")) {
    throw Error("EGL client extension EGL_EXT_platform_device is not available");
  }
  auto query_devices = eglProc<PFNEGLQUERYDEVICESEXTPROC>("eglQueryDevicesEXT");
  auto query_device_string = eglProc<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
  if (query_devices == nullptr || query_device_string == nullptr) {
    throw Error("eglGetProcAddress: eglQueryDevicesEXT/eglQueryDeviceStringEXT not available");
  }
  EGLint count = 0;
  if (!query_devices(0, nullptr, &count)) throwEgl("eglQueryDevicesEXT (count)");
  std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
  if (count > 0 && !query_devices(count, devices.data(), &count)) throwEgl("eglQueryDevicesEXT");
  devices.resize(static_cast<std::size_t>(count));

  std::ostringstream failures;
  int candidates = 0;
  for (std::size_t i = 0; i < devices.size(); ++i) {
    const char* device_extensions = query_device_string(devices[i], EGL_EXTENSIONS);
    const bool software = hasExtension(device_extensions, "EGL_MESA_device_software");
    if (software == hardware) continue;
    ++candidates;
    std::string label = "EGL device " + std::to_string(i);
    if (hasExtension(device_extensions, "EGL_EXT_device_drm")) {
      if (const char* file = query_device_string(devices[i], EGL_DRM_DEVICE_FILE_EXT)) label += std::string(" ") + file;
    }
    try {
      EGLDisplay display = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
      if (display == EGL_NO_DISPLAY) throwEgl("eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT)");
      auto backend = std::make_unique<EglBackend>(hardware ? "egl-device" : "egl-device-software", hardware);
      backend->init(display, major, minor);
      return backend;
    } catch (const Error& e) {
      failures << (candidates > 1 ? "; " : "") << label << ": " << e.what();
    }
  }
  if (candidates == 0) {
    throw Error("none of the " + std::to_string(devices.size()) + " EGL devices is " +
                (hardware ? "a hardware device (all have EGL_MESA_device_software)" : "Mesa's software device"));
  }
  throw Error(failures.str());
}

}  // namespace

std::unique_ptr<ContextBackend> createEglContext(EglPath path, int major, int minor) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (client == nullptr) throwEgl("eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS) (no EGL client extensions)");
  auto get_platform_display = eglProc<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
  if (!hasExtension(client, "EGL_EXT_platform_base") || get_platform_display == nullptr) {
    throw Error("EGL client extension EGL_EXT_platform_base (eglGetPlatformDisplayEXT) is not available");
  }
  switch (path) {
    case EglPath::DeviceHardware: return createOnDevices(true, major, minor, get_platform_display);
    case EglPath::DeviceSoftware: return createOnDevices(false, major, minor, get_platform_display);
    case EglPath::Surfaceless: {
      if (!hasExtension(client, "EGL_MESA_platform_surfaceless")) {
        throw Error("EGL client extension EGL_MESA_platform_surfaceless is not available");
      }
      EGLDisplay display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      if (display == EGL_NO_DISPLAY) throwEgl("eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA)");
      auto backend = std::make_unique<EglBackend>("egl-surfaceless", false);
      backend->init(display, major, minor);
      return backend;
    }
  }
  throw Error("unknown EGL path");
}

}  // namespace pvrr::gl::detail
