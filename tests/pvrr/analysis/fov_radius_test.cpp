// pvrr/analysis/fov_radius: R46 Annex 7's three-point mean radius on the exact surface, against spheres (every
// reading R exactly), a plane (infinite) and a torus (its section radii in closed form).
#include "pvrr/analysis/fov_radius.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr {
namespace {

// Three exact surface points and a circumradius: rounding of coordinates of 0.1 m over a sag of 1e-4 m leaves
// about 1e-12 relative; this is well above that and far below any figure the regulation cares for.
constexpr double kExactRel = 1e-9;

Scene sceneWith(const std::string& surface,
                const std::string& outline = R"({"shape": "rectangle", "width": 0.2, "height": 0.15})") {
  const std::string json = R"({"version": 1, "observer": {"eye": [0, 0, 1], "target": [0, 0, 0]},
    "elements": [{"name": "m", "type": "mirror", "pose": {"position": [0, 0, 0], "normal": [0, 0, 1], "up": [0, 1, 0]},
      "surface": )" + surface +
                           R"(, "outline": )" + outline + "}]}";
  return buildScene(parseScene(json, "test.json", "."));
}

TEST(FovRadius, SphereReadsItsRadiusEverywhere) {
  for (const double R : {1.4, 1.2, -2.0, 30.0}) {
    const Scene s = sceneWith(R"({"type": "sphere", "radius": )" + std::to_string(R) + "}");
    const Annex7Radius a = annex7Radius(s.elements[0]);
    EXPECT_TRUE(a.arc_along_u);  // the 0.2 m width is the longer arc
    EXPECT_DOUBLE_EQ(a.half_span_m, 0.02);
    for (const Annex7Radius::Point& p : a.points) {
      EXPECT_NEAR(p.r_along_m, R, kExactRel * std::abs(R));
      EXPECT_NEAR(p.r_across_m, R, kExactRel * std::abs(R));
    }
    EXPECT_NEAR(a.r_m, R, kExactRel * std::abs(R));
    EXPECT_LT(a.max_principal_deviation, kExactRel);
    EXPECT_LT(a.max_point_deviation, kExactRel);
    // The measuring points at 1/3, 1/2, 2/3 of the central arc: symmetric about the centre, the middle one on it.
    EXPECT_NEAR(a.points[1].square.x, 0, 1e-9);
    EXPECT_NEAR(a.points[0].square.x, -a.points[2].square.x, 1e-9);
    EXPECT_NEAR(a.points[0].square.x, -1.0 / 3, 1e-2);  // arc length nearly proportional to x on a shallow sphere
  }
}

TEST(FovRadius, PlaneIsInfinite) {
  const Scene s = sceneWith(R"({"type": "plane"})");
  const Annex7Radius a = annex7Radius(s.elements[0]);
  EXPECT_TRUE(std::isinf(a.r_m));
  EXPECT_EQ(a.max_point_deviation, 0);
}

// The longer arc chooses the direction: a taller outline measures along its height.
TEST(FovRadius, LongerArcIsMeasured) {
  const Scene s =
      sceneWith(R"({"type": "sphere", "radius": 1.4})", R"({"shape": "rectangle", "width": 0.1, "height": 0.16})");
  const Annex7Radius a = annex7Radius(s.elements[0]);
  EXPECT_FALSE(a.arc_along_u);
  EXPECT_NEAR(a.arc_length_m, 2 * 1.4 * std::asin(0.08 / 1.4), 1e-6);  // the sphere's great-circle arc
}

// A torus (cad/sag.h makeToric: the b-circle swept along the a-circle). Along its a-circle (axis 0 deg, the
// measuring arc along x) every section is a circle: r_i = Ra, r'_i = Rb, r = (Ra + Rb) / 2 exactly.
TEST(FovRadius, TorusAlongItsSweepCircle) {
  constexpr double kRa = 1.5, kRb = 0.9;
  const Scene s = sceneWith(R"({"type": "toric", "radius_a": 1.5, "radius_b": 0.9, "axis_deg": 0})");
  const Annex7Radius a = annex7Radius(s.elements[0]);
  ASSERT_TRUE(a.arc_along_u);
  for (const Annex7Radius::Point& p : a.points) {
    EXPECT_NEAR(p.r_along_m, kRa, kExactRel * kRa);
    EXPECT_NEAR(p.r_across_m, kRb, kExactRel * kRa);
  }
  EXPECT_NEAR(a.r_m, 0.5 * (kRa + kRb), kExactRel * kRa);
  EXPECT_NEAR(a.max_principal_deviation, (kRa - kRb) / (kRa + kRb), 1e-9);
}

// Turned by 90 deg, the arc runs along the b-circle: r_i = Rb exactly; across it the reading approaches the
// normal-curvature radius of the parallel, Rb + (Ra - Rb) / cos(phi) (Meusnier), phi the angle along the
// b-circle; exactly Ra at the middle point (phi = 0).
TEST(FovRadius, TorusAcrossItsSweepCircle) {
  constexpr double kRa = 1.5, kRb = 0.9;
  // Off the circle of symmetry the section is no circle: the spherometer's chord reads the normal curvature
  // to O((span / R)^2) at most; with a 5 mm half span it reads it to 2.6e-9 relative (measured), far inside this.
  constexpr double kSpan_m = 0.005, kChordRel = 1e-7;
  const Scene s = sceneWith(R"({"type": "toric", "radius_a": 1.5, "radius_b": 0.9, "axis_deg": 90})");
  const Annex7Radius a = annex7Radius(s.elements[0], kSpan_m);
  ASSERT_TRUE(a.arc_along_u);
  double worst = 0;
  for (const Annex7Radius::Point& p : a.points) {
    EXPECT_NEAR(p.r_along_m, kRb, kExactRel * kRa);
    // The point's place on the b-circle (the arc runs along local x, the b-circle's plane at axis 90 deg).
    const double phi = std::asin(p.p.x / kRb);
    const double expected = kRb + (kRa - kRb) / std::cos(phi);
    worst = std::max(worst, std::abs(p.r_across_m - expected) / expected);
    EXPECT_NEAR(p.r_across_m, expected, kChordRel * expected) << "phi " << phi;
  }
  EXPECT_NEAR(a.points[1].r_across_m, kRa, kExactRel * kRa);
  std::printf("torus across its sweep circle: worst relative difference from Meusnier %.3g (span %.3g m)\n", worst,
              kSpan_m);
}

}  // namespace
}  // namespace pvrr
