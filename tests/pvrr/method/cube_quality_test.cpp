// Envmap and impostor modes check their frames too (pvrr/method/cube_quality.h): the cube's near plane from
// the nearest surface, the depth buffer's resolution in closed form, envmap mode's parallax and interpolated
// normals, a lens seen from behind, and impostor searches that end off the maps.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "pvrr/method/cube_quality.h"
#include "pvrr/method/vertex_stage.h"
#include "pvrr/trace/ray_scene.h"
#include "support/scenes.h"

namespace pvrr {
namespace {

Scene stressScene(const std::string& name, const std::vector<std::string>& sets = {}) {
  return buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/tests/data/stress/" + name + ".json", sets));
}

// Element e's cube as CubePass draws it: near plane from what the cube draws (the environment, in envmap
// mode only that), far plane from the scene.
CubeQuality assess(const Scene& s, const RayScene& rays, int e, RenderMode mode, ElementFrame* out = nullptr,
                   double near_m = 0) {
  ElementFrame f = prepareElement(s, e);
  const Vec3 centre = Vec3(s.elements[size_t(e)].local_to_world[3]);
  if (near_m <= 0) near_m = cubeNearPlane(nearestSurface(s, centre, {}));
  const CubeQuality q = assessCubeQuality(rays, f, mode, s.observer.eye, near_m, cubeFarPlane(s, centre),
                                          std::vector<char>(s.elements.size(), 0));
  if (out) *out = std::move(f);
  return q;
}

TEST(CubeQuality, DepthResolutionIsTheClosedForm) {
  // 2^-24 d (f - n) / (f n): at n = 1 mm, f = 1e5 m, d = 10 km, 0.6 of the distance (nothing ordered).
  EXPECT_NEAR(relativeDepthResolution(1e-3, 1e5, 1e4), std::ldexp(1.0, -24) * 1e4 * (1e5 - 1e-3) / (1e5 * 1e-3),
              1e-15);
  EXPECT_GT(relativeDepthResolution(1e-3, 1e5, 1e4), 0.5);
  // At the far mirror's near plane now (25 m): 2.4e-5, well inside the 1e-3 limit.
  EXPECT_NEAR(relativeDepthResolution(25.0, 1e5, 1e4), 2.38359e-5, 1e-10);
}

TEST(CubeQuality, NearPlaneIsHalfTheNearestSurface) {
  // The plane mirror hangs 10 mm in front of the far wall (z = -1.99 and -2), its centre over the wall.
  const Scene s = test::shippedScene("plane-mirror");
  const Vec3 centre = Vec3(s.elements[0].local_to_world[3]);
  const double d = nearestSurface(s, centre, {});
  EXPECT_NEAR(d, 0.01, 1e-6);
  EXPECT_NEAR(cubeNearPlane(d), 0.005, 1e-6);
  EXPECT_EQ(cubeNearPlane(1e-4), kMinCubeNear_m);  // never below the old fixed plane
  EXPECT_EQ(cubeNearPlane(std::numeric_limits<double>::infinity()), kMinCubeNear_m);
  // The far mirror's nearest surface is the ground 50 m below its centre.
  const Scene far = stressScene("far-mirror");
  EXPECT_NEAR(nearestSurface(far, Vec3(far.elements[0].local_to_world[3]), {}), 50.0, 1e-3);
}

TEST(CubeQuality, ElementsTheCubeDrawsCountForItsNearPlane) {
  // The mirror pair: the back-wall mirror (a plane at z = 1.99 facing the convex mirror) lies 1.79 m from
  // the convex mirror's centre; its grid triangles lie in the plane, so the distance is exact.
  const Scene s = test::shippedScene("mirror-pair");
  const ElementFrame wall = prepareElement(s, 1);
  const Vec3 centre = Vec3(s.elements[0].local_to_world[3]);
  const double with = nearestSurface(s, centre, {&wall}), without = nearestSurface(s, centre, {});
  EXPECT_LE(with, without);
  EXPECT_NEAR(nearestSurface(Scene{}, centre, {&wall}), 1.99 - centre.z, 1e-6);  // the wall mirror's plane z = 1.99
}

TEST(CubeQuality, FarMirrorDepthIsFlaggedOnlyWithTheFixedNearPlane) {
  const Scene s = stressScene("far-mirror");
  const RayScene rays(s);
  ElementFrame f;
  const CubeQuality fixed = assess(s, rays, 0, RenderMode::Impostor, &f, kMinCubeNear_m);
  EXPECT_GT(fixed.max_hit_distance_m, 9000.0);  // the towers and the ground near the observer
  EXPECT_GT(fixed.depth_relative, 1e-3);
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kDegraded);
  EXPECT_NE(f.quality.action.find("the cube's depth buffer resolves the hits"), std::string::npos) << f.quality.action;
  const CubeQuality now = assess(s, rays, 0, RenderMode::Impostor, &f);
  EXPECT_LT(now.depth_relative, 1e-4);
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kGood) << f.quality.action;
}

TEST(CubeQuality, EnvmapParallaxFlagsThePlaneMirrorNotTheSpectacleLens) {
  // Measured in pixels against the reference (docs/accuracy.md): plane mirror 256' median, spectacle lens 7.4'.
  {
    const Scene s = test::shippedScene("plane-mirror");
    const RayScene rays(s);
    ElementFrame f;
    const CubeQuality q = assess(s, rays, 0, RenderMode::Envmap, &f);
    EXPECT_GT(q.parallax_median_arcmin, 100.0);
    EXPECT_EQ(q.max_normal_spread_deg, 0.0);  // a plane
    EXPECT_EQ(f.quality.verdict, QualityVerdict::kDegraded);
    EXPECT_NE(f.quality.action.find("envmap mode looks every ray up from the cube's centre"), std::string::npos);
    // Impostor mode searches along each ray: no parallax measured, nothing flagged.
    const CubeQuality qi = assess(s, rays, 0, RenderMode::Impostor, &f);
    EXPECT_EQ(qi.parallax_median_arcmin, 0.0);
    EXPECT_EQ(f.quality.verdict, QualityVerdict::kGood) << f.quality.action;
  }
  {
    const Scene s = test::shippedScene("spectacle-lens");
    const RayScene rays(s);
    ElementFrame f;
    const CubeQuality q = assess(s, rays, 0, RenderMode::Envmap, &f);
    EXPECT_GT(q.parallax_median_arcmin, 1.0);
    EXPECT_LT(q.parallax_median_arcmin, 30.0);
    EXPECT_EQ(f.quality.verdict, QualityVerdict::kGood) << f.quality.action;
  }
}

TEST(CubeQuality, EnvmapParallaxVanishesWhenEverythingIsFar) {
  // A mirror with nothing but a sphere about 3 km away: every ray meets it (or escapes) in nearly the
  // direction the cube's centre sees it, at most 0.54 m from the vertices (half the mirror's diagonal):
  // under 0.54 m / 3 km = 0.62' apart.
  const Scene s = test::shippedScene(
      "plane-mirror", {R"(environment=[{"type":"sphere","name":"far","centre":[0,1.4,5000],"radius":2000}])"});
  const RayScene rays(s);
  ElementFrame f;
  const CubeQuality q = assess(s, rays, 0, RenderMode::Envmap, &f);
  EXPECT_GT(q.seen, 0);
  EXPECT_LT(q.parallax_max_arcmin, 0.62);
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kGood) << f.quality.action;
}

TEST(CubeQuality, EnvmapFlagsInterpolatedNormalsOfTheSteepAsphere) {
  const Scene s = stressScene("steep-asphere");
  const RayScene rays(s);
  ElementFrame f;
  const CubeQuality q = assess(s, rays, 0, RenderMode::Envmap, &f);
  EXPECT_GT(q.max_normal_spread_deg, 6.0);
  EXPECT_NE(f.quality.action.find("envmap mode interpolates the normals"), std::string::npos) << f.quality.action;
}

TEST(CubeQuality, EnvmapFlagsALensSeenFromBehind) {
  const Scene s =
      test::shippedScene("reading-lens", {"observer.eye=[0,0.85,0.06]", "observer.target=[0,1.25,0.3]"});
  const RayScene rays(s);
  ElementFrame f;
  const CubeQuality q = assess(s, rays, 0, RenderMode::Envmap, &f);
  EXPECT_EQ(q.lens_back_vertices, q.seen);
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kDegraded);
  EXPECT_NE(f.quality.action.find("the eye is behind the lens's front surface"), std::string::npos);
  EXPECT_NE(f.quality.note.find("the eye is behind lens 'reading-lens'"), std::string::npos) << f.quality.note;
}

// Impostor mode's search escapes to the sky where it finds no surface behind every layer of the maps: a surface
// hidden behind two occluders from the cube's centre. The wall mirror with two cards stacked 2 and 6 cm in front
// of its centre (tests/data/stress/hunt-impostor-behind-two-cards.json): from the centre most of the room its rays
// reach lies behind both cards, with the default two layers; with four layers nothing is beyond them. The
// shipped plane mirror sees nothing behind two surfaces.
TEST(CubeQuality, ImpostorFlagsSurfacesBehindEveryLayer) {
  {
    const Scene s = stressScene("hunt-impostor-behind-two-cards");
    const RayScene rays(s);
    ElementFrame f;
    const CubeQuality q = assess(s, rays, 0, RenderMode::Impostor, &f);
    EXPECT_GT(q.hit_vertices, 20);
    EXPECT_GT(double(q.behind_layers_vertices), 0.05 * q.hit_vertices);
    std::printf("[ measured ] two cards, 2 layers: %d of %d seen vertex rays hit behind every layer\n",
                q.behind_layers_vertices, q.hit_vertices);
    EXPECT_EQ(f.quality.verdict, QualityVerdict::kDegraded);
    EXPECT_NE(f.quality.action.find("surfaces as seen from the cube's centre"), std::string::npos) << f.quality.action;
    // Envmap mode has no layers: not this flag (its parallax flag is its own).
    ElementFrame fe;
    assess(s, rays, 0, RenderMode::Envmap, &fe);
    EXPECT_EQ(fe.quality.action.find("surfaces as seen from the cube's centre"), std::string::npos);
  }
  {
    // The far card shrunk to 1 mm: one card in front, which the second layer holds.
    const Scene s = stressScene("hunt-impostor-behind-two-cards", {"environment[11].size=[0.001, 0.001]"});
    const RayScene rays(s);
    ElementFrame f2;
    const CubeQuality q2 = assess(s, rays, 0, RenderMode::Impostor, &f2);
    EXPECT_LE(q2.behind_layers_vertices, 1);  // 1 of 49 measured: under the 5 % line
    EXPECT_EQ(f2.quality.verdict, QualityVerdict::kGood) << f2.quality.action;
    // With one layer the near card alone hides them.
    const Scene s1 = stressScene("hunt-impostor-behind-two-cards",
                                 {"environment[11].size=[0.001, 0.001]", "render.impostor_layers=1"});
    const RayScene rays1(s1);
    EXPECT_GT(assess(s1, rays1, 0, RenderMode::Impostor).behind_layers_vertices, 20);
  }
  const Scene s = test::shippedScene("plane-mirror");
  const RayScene rays(s);
  ElementFrame f;
  const CubeQuality q = assess(s, rays, 0, RenderMode::Impostor, &f);
  EXPECT_GT(q.hit_vertices, 20);
  EXPECT_EQ(q.behind_layers_vertices, 0);
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kGood) << f.quality.action;
}

// A lens at render.max_depth 1: the reference ends its paths at the back surface (black); envmap mode's cube lookup
// draws the room through it (pvrr compare, 96 x 72: 6902 of the spectacle lens's 6912 such pixels lit), so it is
// flagged; at the scene's own depth it is not.
TEST(CubeQuality, EnvmapFlagsALensBeyondTheDepthLimit) {
  const Scene s = test::shippedScene("spectacle-lens", {"render.max_depth=1"});
  const RayScene rays(s);
  ElementFrame f;
  assess(s, rays, 0, RenderMode::Envmap, &f);
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kDegraded);
  EXPECT_NE(f.quality.action.find("render.max_depth 1: the reference ends every path through the lens"),
            std::string::npos)
      << f.quality.action;
  const Scene s4 = test::shippedScene("spectacle-lens");
  const RayScene rays4(s4);
  ElementFrame f4;
  assess(s4, rays4, 0, RenderMode::Envmap, &f4);
  EXPECT_EQ(f4.quality.action.find("render.max_depth"), std::string::npos) << f4.quality.action;
}

TEST(CubeQuality, UnresolvedSearchesAboveOnePercentAreFlagged) {
  ElementFrame f;
  f.quality.action = "none";
  noteUnresolvedSearches(f, 10, 1000);  // 1 %: at the limit, not over it
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kGood);
  noteUnresolvedSearches(f, 11, 1000);
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kDegraded);
  EXPECT_NE(f.quality.action.find("11 of 1000 pixels (1.1 %) ended their impostor search off every layer"),
            std::string::npos)
      << f.quality.action;
}

}  // namespace
}  // namespace pvrr
