// GlContext::adopt (a context made elsewhere, as `pvrr view`'s window makes one) and Renderer::colorTexture: the
// renderer draws in an adopted context as in its own, and its colour texture holds the frame it read back.
#include "pvrr/gl/gl.h"  // glad before GL/osmesa.h (pvrr/gl/gl.h says why)

#include <GL/osmesa.h>
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "support/test_scenes.h"

namespace pvrr::gl {
namespace {

// An OSMesa context made by the test itself, not by GlContext: the "foreign" one.
struct TestOsMesa {
  OSMesaContext context = nullptr;
  std::vector<unsigned char> buffer = std::vector<unsigned char>(4 * 4 * 4);
  TestOsMesa() {
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
    context = OSMesaCreateContextAttribs(attribs, nullptr);
  }
  ~TestOsMesa() {
    if (context) OSMesaDestroyContext(context);
  }
  void makeCurrent() { OSMesaMakeCurrent(context, buffer.data(), GL_UNSIGNED_BYTE, 4, 4); }
};

ForeignContext foreign(TestOsMesa& m) {
  ForeignContext f;
  f.backend_name = "test-osmesa";
  f.make_current = [&m] { m.makeCurrent(); };
  f.release_current = [] { OSMesaMakeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0); };
  f.get_proc_address = reinterpret_cast<ForeignContext::Proc (*)(const char*)>(OSMesaGetProcAddress);
  return f;
}

TEST(AdoptedContext, RendererDrawsInItAndItsColourTextureHoldsTheFrame) {
  TestOsMesa mesa;
  ASSERT_NE(mesa.context, nullptr) << "OSMesa cannot make a 3.3 core context here";
  mesa.makeCurrent();
  std::unique_ptr<GlContext> ctx = GlContext::adopt(foreign(mesa));
  EXPECT_EQ(ctx->backendName(), "test-osmesa");
  EXPECT_EQ(GlContext::current(), ctx.get());
  EXPECT_GE(ctx->glMajor() * 10 + ctx->glMinor(), kGlFloorMajor * 10 + kGlFloorMinor);
  EXPECT_FALSE(ctx->glRenderer().empty());

  Scene s = test::roomScene(Vec3(0.3, 0.2, 2.0), Vec3(0, -0.2, 0));
  RayScene rays(s);
  RendererOptions opt;
  opt.seen_points = false;  // the window's settings: colour only, a 16-bit target
  Renderer r(s, rays, opt);
  EXPECT_EQ(r.colorTexture(), 0u);
  const RasterFrame f = r.render(RenderMode::Raster);
  ASSERT_NE(r.colorTexture(), 0u);

  // The texture's texels (GL's bottom-up rows) are the frame's colours (top-down rows).
  std::vector<float> texels(size_t(f.width) * size_t(f.height) * 4);
  glBindTexture(GL_TEXTURE_2D, r.colorTexture());
  glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, texels.data());
  checkGlError("reading the colour texture");
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const Vec3& c = f.color[size_t(y) * size_t(f.width) + size_t(x)];
      const float* t = &texels[4 * (size_t(f.height - 1 - y) * size_t(f.width) + size_t(x))];
      for (int k = 0; k < 3; ++k) ASSERT_EQ(float(c[k]), t[k]) << x << "," << y;
    }

  // Another pvrr context in between: making the adopted one current again reloads its entry points.
  {
    auto other = GlContext::create(GlBackend::OsMesa);
    EXPECT_EQ(GlContext::current(), other.get());
    ctx->makeCurrent();
    EXPECT_EQ(GlContext::current(), ctx.get());
    EXPECT_EQ(r.render(RenderMode::Raster).color, f.color);
    other->makeCurrent();
  }
  ctx->makeCurrent();
}

}  // namespace
}  // namespace pvrr::gl
