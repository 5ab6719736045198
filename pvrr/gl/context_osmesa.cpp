// OSMesa contexts (Mesa's off-screen interface, llvmpipe). The context is made current on a small internal RGBA8
// buffer that is never read: all drawing goes to framebuffer objects.
#include "pvrr/gl/gl.h"  // glad first: it defines GLAPI and the GL/gl.h guard that GL/osmesa.h relies on

#include <GL/osmesa.h>

#include <vector>

#include "pvrr/base/error.h"

namespace pvrr::gl::detail {
namespace {

// Side of the internal buffer in pixels. Its size does not limit FBO sizes.
constexpr int kBufferSide = 4;

class OsMesaBackend final : public ContextBackend {
 public:
  OsMesaBackend(int major, int minor) : buffer_(kBufferSide * kBufferSide * 4) {
    // Depth bits 0: the internal buffer is never drawn to; FBOs carry their own depth attachments.
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           0,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           major,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           minor,
                           0};
    context_ = OSMesaCreateContextAttribs(attribs, nullptr);
    if (context_ == nullptr) {
      throw Error("OSMesaCreateContextAttribs(GL " + std::to_string(major) + "." + std::to_string(minor) +
                  " core) returned NULL");
    }
  }
  ~OsMesaBackend() override {
    releaseCurrent();
    if (context_ != nullptr) OSMesaDestroyContext(context_);
  }

  void makeCurrent() override {
    if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, kBufferSide, kBufferSide)) {
      throw Error("OSMesaMakeCurrent failed");
    }
  }
  void releaseCurrent() noexcept override {
    if (context_ != nullptr && OSMesaGetCurrentContext() == context_) {
      OSMesaMakeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0);
    }
  }
  GLADloadfunc loader() const override { return reinterpret_cast<GLADloadfunc>(OSMesaGetProcAddress); }
  std::string backendName() const override { return "osmesa"; }
  bool deviceIsHardware() const override { return false; }

 private:
  OSMesaContext context_ = nullptr;
  std::vector<unsigned char> buffer_;
};

}  // namespace

std::unique_ptr<ContextBackend> createOsMesaContext(int major, int minor) {
  auto backend = std::make_unique<OsMesaBackend>(major, minor);
  backend->makeCurrent();  // outside the constructor, so a failure still destroys the context
  return backend;
}

}  // namespace pvrr::gl::detail
