// pvrr/analysis/lensmap: as-worn power, astigmatism and prism of spectacle lenses (issue 27), against the
// prescriptions the lenses were built for and against an independent as-worn calculation (worn_reference.h).
#include "pvrr/analysis/lensmap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "pvrr/optics/material.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "support/scenes.h"
#include "tests/pvrr/analysis/worn_reference.h"

namespace pvrr {
namespace {

// The issue's acceptance tolerances ("Done when"): what a focimeter reading is quoted to (0.01 D steps,
// lenses are ordered in 0.25 D steps and ISO 8980-1 allows +-0.12 D at these powers), so the centre of a
// built lens must read its prescription within 0.02 D (sphere) / 0.03 D (toric) and 1 deg of axis.
constexpr double kCentreSphere_d = 0.02;
constexpr double kCentreCylinder_d = 0.02;
constexpr double kToric_d = 0.03;
constexpr double kToricAxis_deg = 1.0;
// Against the independent calculation: two exact calculations of the same quantity, which differ only by
// their numerical differentiation (~1e-6 D measured); the issue asks for 0.01 D and 0.01 prism dioptres.
constexpr double kAgreement_d = 0.01;
constexpr double kAgreementPrism = 0.01;

// A lens attached to the observer like the shipped spectacle lens, with the given "prescription" or surfaces.
Scene wornScene(const std::string& lens_keys) {
  const std::string json = R"({"version": 1, "units": "m",
    "observer": {"eye": [0, 1.6, 4.0], "target": [0, 1.6, 0], "up": [0, 1, 0], "fov_y_deg": 50, "image_size": [64, 48]},
    "environment": [{"type": "quad", "name": "wall", "centre": [0, 1.35, 0], "normal": [0, 0, 1], "up": [0, 1, 0],
                     "size": [5, 2.7], "material": {"color": [0.8, 0.8, 0.8]}}],
    "lights": [{"type": "ambient", "color": [1, 1, 1]}],
    "elements": [{"name": "lens", "type": "lens", "attached_to_observer": true,
      "pose": {"position": [0, 0, -0.012], "normal": [0, 0, 1], "up": [0, 1, 0]},
      "outline": {"shape": "ellipse", "width": 0.05, "height": 0.04},
      "material": {"name": "cr39"}, )" + lens_keys + R"(}]})";
  return buildScene(parseScene(json, "test.json", "."));
}

// -2.00 / -1.50 x 30 (TABO): the scene's axis_deg is counter-clockwise from the wearer's right, 180 - 30.
Scene toricScene() {
  return wornScene(R"("prescription": {"sphere_d": -2, "cylinder_d": -1.5, "axis_deg": 150, "base_curve_d": 4},
                      "centre_thickness": 0.002)");
}
Scene plusScene() {
  return wornScene(R"("prescription": {"sphere_d": 2, "base_curve_d": 6}, "centre_thickness": 0.004)");
}

TEST(Lensmap, SphCylAxisRoundTripsTabo) {
  // Build the matrix of S / C x theta (TABO) from the meridians: TABO theta is the direction at 180 - theta
  // counter-clockwise from the wearer's right, as the wearer sees it; the sphere acts along it.
  for (double theta : {0.0, 30.0, 45.0, 90.0, 135.0, 170.0}) {
    const double phi = radians(180 - theta), s = -2, c = -1.5;
    const Vec2 a(std::cos(phi), std::sin(phi)), b(-a.y, a.x);
    const double vxx = s * a.x * a.x + (s + c) * b.x * b.x, vxy = s * a.x * a.y + (s + c) * b.x * b.y,
                 vyy = s * a.y * a.y + (s + c) * b.y * b.y;
    const SphCylAxis r = sphCylAxis(vxx, vxy, vyy);
    EXPECT_NEAR(r.sphere_d, s, 1e-12);
    EXPECT_NEAR(r.cylinder_d, c, 1e-12);
    EXPECT_NEAR(std::fmod(r.axis_deg - theta + 540.0, 180.0), 0.0, 1e-9) << theta;
  }
}

TEST(Lensmap, SpectacleLensCentreReadsMinus3) {
  const Scene scene = test::shippedScene("spectacle-lens");
  RayScene rays(scene);
  const Lensmap map(rays, 0, {});
  const LensmapPoint c = map.evaluate(0, 0);
  ASSERT_TRUE(c.valid) << c.reason;
  EXPECT_NEAR(c.sphere_d, -3.0, kCentreSphere_d);
  EXPECT_LT(std::abs(c.cylinder_d), kCentreCylinder_d);
  EXPECT_NEAR(c.prism_h, 0.0, 1e-9);
  EXPECT_NEAR(c.prism_v, 0.0, 1e-9);
  // The bundle's fitted matrix is symmetric to rounding: a check of the central differences.
  EXPECT_LT(c.asymmetry_d, 1e-6);
  const LensmapResult::Focimeter f = map.focimeter();
  ASSERT_TRUE(f.found) << f.reason;
  EXPECT_NEAR(f.sphere_d, -3.0, kCentreSphere_d);
  EXPECT_LT(std::abs(f.cylinder_d), kCentreCylinder_d);
  EXPECT_NEAR(f.lens_x_mm, 0.0, 1e-6);
  EXPECT_NEAR(f.lens_y_mm, 0.0, 1e-6);
}

TEST(Lensmap, ToricReadsItsPrescription) {
  const Scene scene = toricScene();
  RayScene rays(scene);
  const LensmapPoint c = Lensmap(rays, 0, {}).evaluate(0, 0);
  ASSERT_TRUE(c.valid) << c.reason;
  EXPECT_NEAR(c.sphere_d, -2.0, kToric_d);
  EXPECT_NEAR(c.cylinder_d, -1.5, kToric_d);
  EXPECT_NEAR(c.axis_deg, 30.0, kToricAxis_deg);
  const LensmapResult::Focimeter f = Lensmap(rays, 0, {}).focimeter();
  ASSERT_TRUE(f.found) << f.reason;
  EXPECT_NEAR(f.sphere_d, -2.0, kToric_d);
  EXPECT_NEAR(f.cylinder_d, -1.5, kToric_d);
  EXPECT_NEAR(f.axis_deg, 30.0, kToricAxis_deg);
}

// Along the horizontal and vertical meridians up to 30 deg: the product against the independent reference.
void expectAgreesAlongMeridians(const Scene& scene, const char* what) {
  RayScene rays(scene);
  const LensmapOptions options;
  const Lensmap map(rays, 0, options);
  const Element& el = scene.elements[0];
  const test::WornReference ref(el.lens, el.dispersion.index(kLineD_nm), options.rotation_centre_m);
  double worst_d = 0, worst_prism = 0;
  for (int axis = 0; axis < 2; ++axis)
    for (double a = -30; a <= 30; a += 2.5) {
      const double gx = axis == 0 ? a : 0, gy = axis == 0 ? 0 : a;
      const LensmapPoint p = map.evaluate(gx, gy);
      const std::optional<test::WornReading> w = ref.at(gx, gy);
      ASSERT_TRUE(p.valid) << what << " " << gx << "," << gy << ": " << p.reason;
      ASSERT_TRUE(w.has_value()) << what << " " << gx << "," << gy;
      const double s = p.sphere_d + 0.0, c = p.cylinder_d, m = p.mean_power_d;
      EXPECT_NEAR(s, w->sphere(), kAgreement_d) << what << " gaze " << gx << "," << gy;
      EXPECT_NEAR(c, w->cylinder(), kAgreement_d) << what << " gaze " << gx << "," << gy;
      EXPECT_NEAR(m, w->mean(), kAgreement_d) << what << " gaze " << gx << "," << gy;
      EXPECT_NEAR(p.prism_h, w->prism_h, kAgreementPrism) << what << " gaze " << gx << "," << gy;
      EXPECT_NEAR(p.prism_v, w->prism_v, kAgreementPrism) << what << " gaze " << gx << "," << gy;
      worst_d = std::max({worst_d, std::abs(s - w->sphere()), std::abs(c - w->cylinder()), std::abs(m - w->mean())});
      worst_prism = std::max({worst_prism, std::abs(p.prism_h - w->prism_h), std::abs(p.prism_v - w->prism_v)});
    }
  std::printf("%s: max disagreement with the independent reference along the meridians: %.2e D, %.2e prism D\n",
              what, worst_d, worst_prism);
}

TEST(Lensmap, AgreesWithIndependentReferenceSpectacleLens) {
  expectAgreesAlongMeridians(test::shippedScene("spectacle-lens"), "-3 D spectacle lens");
}
TEST(Lensmap, AgreesWithIndependentReferencePlusLens) { expectAgreesAlongMeridians(plusScene(), "+2 D lens"); }
TEST(Lensmap, AgreesWithIndependentReferenceToric) { expectAgreesAlongMeridians(toricScene(), "toric"); }

TEST(Lensmap, PlusLensCentre) {
  const Scene scene = plusScene();
  RayScene rays(scene);
  const LensmapPoint c = Lensmap(rays, 0, {}).evaluate(0, 0);
  ASSERT_TRUE(c.valid);
  EXPECT_NEAR(c.sphere_d, 2.0, kCentreSphere_d);
  EXPECT_LT(std::abs(c.cylinder_d), kCentreCylinder_d);
}

}  // namespace
}  // namespace pvrr
