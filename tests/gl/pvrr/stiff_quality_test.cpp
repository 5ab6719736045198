// Stiff cases of issue 26 in pvrr mode against the reference tracer: each picture is right (median under 60')
// or flagged in the element's quality, never wrong and "good"; the strongly curved toric mirror is right by
// default (automatic split and adaptive refinement). Scenes: the shipped ones with overrides, 160 x 120.
// OSMesa and EGL.
#include <gtest/gtest.h>

#include <iostream>
#include <string>
#include <vector>

#include "pvrr/gl/renderer.h"
#include "pvrr/trace/tracer.h"
#include "support/accuracy.h"
#include "support/gl_backends.h"
#include "support/scenes.h"

namespace pvrr {
namespace {

// The issue's line between a right picture and a wrong one.
constexpr double kRightArcmin = 60.0;
// The toric mirror by default: 3.0' measured at 160 x 120 (30.7' before the default split and refinement,
// 13.9' with the split alone); 10' leaves room for the GL's rasterisation differences, not for either.
constexpr double kToricArcmin = 10.0;

struct StiffCase {
  const char* name;
  const char* scene;
  std::vector<std::string> sets;
};

std::vector<StiffCase> stiffCases() {
  return {
      // The issue's toric mirror: radius 0.05 m across an 80 mm circle against -50 m.
      {"toric mirror",
       "car-mirror",
       {R"(elements[0].surface={"type":"toric","radius_a":0.05,"radius_b":-50})",
        R"(elements[0].outline={"shape":"circle","diameter":0.08})", "elements[0].tessellation=15"}},
      // A convex sphere of radius 60 mm across 80 mm: rays spread over ~180 deg, some behind the viewpoint.
      {"sphere mirror",
       "car-mirror",
       {R"(elements[0].surface={"type":"sphere","radius":0.06})",
        R"(elements[0].outline={"shape":"circle","diameter":0.08})", "elements[0].tessellation=15"}},
      // A 35 mm thick biconvex lens of radii 45 mm: total internal reflection over much of it.
      {"thick lens with TIR",
       "reading-lens",
       {R"(elements[0].front={"type":"sphere","radius":0.045})",
        R"(elements[0].back={"type":"sphere","radius":-0.045})", "elements[0].centre_thickness=0.035",
        R"(elements[0].outline={"shape":"circle","diameter":0.07})"}},
      // A strong toric lens (front radii 30 and 60 mm) 12 mm before the eye.
      {"strong toric lens",
       "spectacle-lens",
       {R"(elements[0].front={"type":"toric","radius_a":-0.03,"radius_b":-0.06})",
        R"(elements[0].back={"type":"sphere","radius":0.2})", "elements[0].centre_thickness=0.012",
        R"(elements[0].outline={"shape":"circle","diameter":0.03})"}},
  };
}

class StiffQualityTest : public ::testing::TestWithParam<gl::GlBackend> {};

TEST_P(StiffQualityTest, RightOrFlaggedNeverWrongAndGood) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  for (const StiffCase& c : stiffCases()) {
    std::vector<std::string> sets = c.sets;
    sets.push_back("observer.image_size=[160,120]");
    const Scene s = test::shippedScene(c.scene, sets);
    RayScene rays(s);
    const Frame ref = test::referenceFrame(rays);
    gl::Renderer r(s, rays, gl::RendererOptions{});
    const gl::RasterFrame f = r.render(RenderMode::Pvrr);
    size_t pixels = 0;
    const double median = test::medianArcmin(ref, f, &pixels);
    ASSERT_GT(pixels, 100u) << c.name;
    ASSERT_EQ(f.elements.size(), 1u);
    const ElementQuality& q = f.elements[0].quality;
    std::cout << "[ measured ] " << c.name << ": median " << median << "' over " << pixels << " px, quality "
              << toString(q.verdict) << " (" << q.action << ")\n";
    EXPECT_TRUE(median < kRightArcmin || q.verdict != QualityVerdict::kGood)
        << c.name << ": median " << median << "' yet quality good";
    if (std::string(c.name) == "toric mirror") {
      EXPECT_LT(median, kToricArcmin) << q.action;
    }
  }
}

PVRR_GL_BACKENDS(StiffQualityTest);

}  // namespace
}  // namespace pvrr
