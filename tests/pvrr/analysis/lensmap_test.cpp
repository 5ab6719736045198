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
      "material": {"name": "cr39"}, )" +
                           lens_keys + R"(}]})";
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
  std::printf("%s: max disagreement with the independent reference along the meridians: %.2e D, %.2e prism D\n", what,
              worst_d, worst_prism);
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

// Prentice's rule against the traced prism for the shipped -3 D lens (2 mm thick meniscus, +4 D base): the
// rule overstates the prism by 7.7 % at 2.5 mm and 6.4 % at 4.9 mm of decentration (measured; the issue
// expected "about 6-7 %"): the lens form and thickness, which the rule ignores. The band below pins that known
// size and sign, wide enough for the decentrations the gazes land on.
constexpr double kPrenticeExcessMin = 0.05, kPrenticeExcessMax = 0.09;

TEST(Lensmap, PrenticeOverstatesTheTracedPrism) {
  const Scene scene = test::shippedScene("spectacle-lens");
  RayScene rays(scene);
  const Lensmap map(rays, 0, {});
  const LensmapPoint c = map.evaluate(0, 0);
  for (double gx : {5.6, 11.0}) {  // lens x 2.5 and 4.9 mm on the eye-side surface
    const LensmapPoint p = map.evaluate(gx, 0, &c);
    ASSERT_TRUE(p.valid);
    EXPECT_GT(p.prism_h, 0) << "a minus lens seen through right of its centre is base right";
    const double excess = p.prentice_h / p.prism_h - 1;
    EXPECT_GT(excess, kPrenticeExcessMin) << gx;
    EXPECT_LT(excess, kPrenticeExcessMax) << gx;
    EXPECT_NEAR(p.prism_v, 0, 1e-12);
  }
}

// Lateral colour against the thin-prism estimate P / V_d (the chromatic difference of a prism P of Abbe
// number V): the exact trace exceeds it by 1.6-2.1 % up to 30 deg (obliquity); 4 % allows for that.
constexpr double kLateralColourRelative = 0.04;

TEST(Lensmap, LateralColourFollowsPrismOverAbbe) {
  const Scene scene = test::shippedScene("spectacle-lens");
  RayScene rays(scene);
  const Lensmap map(rays, 0, {});
  const double v_d = scene.elements[0].dispersion.abbe();
  for (double gx : {5.0, 10.0, 20.0, 30.0}) {
    const LensmapPoint p = map.evaluate(gx, 0);
    ASSERT_TRUE(p.valid);
    const double estimate = arcminutes(std::atan(std::hypot(p.prism_h, p.prism_v) / 100) / v_d);
    EXPECT_NEAR(p.lateral_colour_arcmin / estimate, 1.0, kLateralColourRelative) << gx;
  }
}

TEST(Lensmap, DistortionIsBarrelForMinusPincushionForPlus) {
  const Scene minus = test::shippedScene("spectacle-lens"), plus = plusScene();
  RayScene rm(minus), rp(plus);
  const Lensmap mm(rm, 0, {}), mp(rp, 0, {});
  for (double g : {10.0, 20.0, 30.0}) {
    EXPECT_LT(mm.evaluate(g, 0).distortion_pct, 0) << g;
    EXPECT_LT(mm.evaluate(0, -g).distortion_pct, 0) << g;
    EXPECT_GT(mp.evaluate(g, 0).distortion_pct, 0) << g;
  }
  EXPECT_EQ(mm.evaluate(0, 0).distortion_pct, 0);
}

TEST(Lensmap, GazeForObjectInvertsTheMapping) {
  const Scene scene = toricScene();
  RayScene rays(scene);
  const Lensmap map(rays, 0, {});
  for (const Vec2 tg : {Vec2(0.2, -0.15), Vec2(-0.4, 0.3), Vec2(0.01, 0.5)}) {
    Vec2 to;
    ASSERT_TRUE(map.objectTangents(tg, to));
    const std::optional<Vec2> back = map.gazeForObject(to);
    ASSERT_TRUE(back.has_value());
    EXPECT_NEAR(back->x, tg.x, 1e-9);
    EXPECT_NEAR(back->y, tg.y, 1e-9);
  }
}

TEST(Lensmap, GazesOutsideTheLensAreEmptyAndCounted) {
  const Scene scene = test::shippedScene("spectacle-lens");
  RayScene rays(scene);
  LensmapOptions o;
  o.grid = 21;
  const LensmapResult r = Lensmap(rays, 0, o).run();
  ASSERT_EQ(r.points.size(), 21u * 21u);
  EXPECT_FALSE(r.points.front().valid);  // (-40, -40): beyond the 50 x 40 mm ellipse
  EXPECT_EQ(r.points.front().reason, "miss");
  EXPECT_TRUE(r.points[10 * 21 + 10].valid);  // straight ahead
  int invalid = 0;
  for (const LensmapPoint& p : r.points) invalid += p.valid ? 0 : 1;
  EXPECT_GT(invalid, 0);
  EXPECT_EQ(r.empty, invalid);
  EXPECT_EQ(r.empty_miss + r.empty_tir, invalid);
  EXPECT_FALSE(r.progressive.detected);
}

TEST(Lensmap, DistantObjectMatchesInfinity) {
  const Scene scene = test::shippedScene("spectacle-lens");
  RayScene rays(scene);
  LensmapOptions far;
  far.object_distance_m = 1e4;
  const Lensmap inf(rays, 0, {}), finite(rays, 0, far);
  for (double g : {0.0, 15.0, 30.0}) {
    const LensmapPoint a = inf.evaluate(g, g / 2), b = finite.evaluate(g, g / 2);
    // An object 10 km away has a vergence of 1e-4 D: the readings agree to about that.
    EXPECT_NEAR(a.sphere_d, b.sphere_d, 1e-3) << g;
    EXPECT_NEAR(a.cylinder_d, b.cylinder_d, 1e-3) << g;
    EXPECT_NEAR(a.prism_h, b.prism_h, 1e-9) << g;
  }
}

// The shipped progressive lens: plano distance, +2.00 D add on its object-side surface. As worn the add
// along the meridian reads 2.09 D (measured: the oblique view through the near zone adds power), so the test
// allows 0.15 D; the corridor must lie between the far point and the near zone the design puts 12 mm down.
TEST(Lensmap, ProgressiveLensShowsAddAndCorridor) {
  const Scene scene = test::shippedScene("progressive-lens");
  RayScene rays(scene);
  LensmapOptions o;
  o.grid = 9;
  const LensmapResult r = Lensmap(rays, 0, o).run();
  EXPECT_NEAR(r.centre.mean_power_d, 0.0, kCentreSphere_d);
  ASSERT_TRUE(r.progressive.detected);
  EXPECT_NEAR(r.progressive.add_d, 2.0, 0.15);
  EXPECT_LT(r.progressive.near_lens_y_mm, -5);
  EXPECT_GT(r.progressive.corridor_length_mm, 4);
  EXPECT_LT(r.progressive.corridor_length_mm, 12);
  EXPECT_GT(r.progressive.corridor_width_mm, 0);
}

// A near object straight ahead: the paraxial vergence through the lens (surface powers, the reduced thickness)
// gives the exact axial limit of the bundle, so the two agree to the bundle's truncation (~1e-5 D); the
// tolerance is the issue's 0.01 D of agreement.
TEST(Lensmap, NearObjectCentreMatchesParaxialVergence) {
  const Scene scene = test::shippedScene("spectacle-lens");
  RayScene rays(scene);
  LensmapOptions o;
  o.object_distance_m = 0.4;
  const LensmapPoint c = Lensmap(rays, 0, o).evaluate(0, 0);
  ASSERT_TRUE(c.valid);
  const double n = scene.elements[0].dispersion.index(kLineD_nm), t = 0.002, r = o.rotation_centre_m;
  const double f1 = (n - 1) / 0.1245, f2 = (n - 1) / -0.070925;   // object side (+4 D), eye side (-7.02 D)
  const double l1 = -1 / (o.object_distance_m - r - t) + f1;      // after the object-side surface
  const double l2 = l1 / (1 - (t / n) * l1) + f2;                 // at the eye-side vertex (on the vertex sphere)
  const double expected = l2 - (-1 / (o.object_distance_m - r));  // minus the object's own vergence there
  EXPECT_NEAR(c.sphere_d, expected, kAgreement_d);
  EXPECT_NEAR(c.cylinder_d, 0, kCentreCylinder_d);
  std::printf("near object 0.4 m: %.6f D traced, %.6f D paraxial\n", c.sphere_d, expected);
}

// Signs: the lens frame's +x is the wearer's right (the observer's +x for a lens attached like the shipped
// one), and prism bases lie towards the thick part: outwards for a minus lens, inwards for a plus lens.
TEST(Lensmap, GazeAndPrismSigns) {
  const Scene minus = test::shippedScene("spectacle-lens"), plus = plusScene();
  RayScene rm(minus), rp(plus);
  const Lensmap mm(rm, 0, {}), mp(rp, 0, {});
  const LensmapPoint right = mm.evaluate(15, 0), up = mm.evaluate(0, 15);
  EXPECT_GT(right.lens_x_mm, 0);
  EXPECT_NEAR(right.lens_y_mm, 0, 1e-9);
  EXPECT_GT(up.lens_y_mm, 0);
  EXPECT_GT(right.prism_h, 0);        // base right
  EXPECT_GT(up.prism_v, 0);           // base up
  EXPECT_GT(right.object_x_deg, 15);  // a minus lens shows the object nearer the centre than it is
  EXPECT_LT(mp.evaluate(15, 0).prism_h, 0);
  EXPECT_LT(mp.evaluate(0, 15).prism_v, 0);
  // The world: the observer looks along -z with +x to the right; the lens frame's +x follows it.
  const Element& el = minus.elements[0];
  const Vec3 world_x = el.toWorldDir(Vec3(1, 0, 0));
  const Vec3 view = glm::normalize(minus.observer.target - minus.observer.eye);
  EXPECT_GT(glm::dot(world_x, glm::cross(view, minus.observer.up)), 0.99);
}

}  // namespace
}  // namespace pvrr
