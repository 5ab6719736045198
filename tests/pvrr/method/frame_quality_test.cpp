// Every frame checks itself (pvrr/method/frame_quality.h): the verdicts on real elements (a plane mirror, the
// strongly curved toric mirror of issue 26), the adaptive grid size in closed form, the traced fallback against
// the exact hits, and the viewpoint solver as a scene choice.
#include <gtest/gtest.h>

#include <algorithm>

#include "pvrr/base/error.h"
#include "pvrr/method/frame_quality.h"
#include "pvrr/method/vertex_stage.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "support/scenes.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// A traced seen point of a ray that meets a diffuse surface first is that hit: both come from the same Embree
// intersection of the same ray, started an epsilon apart (RayScene::epsilon, ~1e-6 of the scene's size).
constexpr double kSeenTol_m = 1e-4;

// The car-mirror scene with the issue's toric mirror: radius 0.05 m across an 80 mm circle against -50 m.
std::vector<std::string> toricSets(std::vector<std::string> more = {}) {
  std::vector<std::string> s = {R"(elements[0].surface={"type":"toric","radius_a":0.05,"radius_b":-50})",
                                R"(elements[0].outline={"shape":"circle","diameter":0.08})",
                                "elements[0].tessellation=15", "observer.image_size=[160,120]"};
  s.insert(s.end(), more.begin(), more.end());
  return s;
}

ElementFrame fitted(const Scene& s, const RayScene& rays, const VertexStageOptions& opt = {}) {
  ElementFrame f = prepareElement(s, 0);
  VertexStageOptions o = opt;
  o.viewer_clip = s.observer.visibilityProjection() * s.observer.view();
  traceVertexRays(rays, f, s.observer.eye, o);
  fitPatchViews(s, f, o);
  return f;
}

TEST(FrameQuality, PlaneMirrorIsGood) {
  Scene s = test::roomScene(Vec3(0.4, 0.3, 1.8), Vec3(0, 0, 0));
  const cad::Outline outline = cad::Outline::rectangle(0.6, 0.4, 0.05);
  test::addMirror(s, cad::makePlane(outline), outline, test::pose(Vec3(0.1, -0.05, 0), glm::normalize(Vec3(0.2, 0, 1))),
                  9);
  s.updateBounds();
  RayScene rays(s);
  const ElementFrame f = fitted(s, rays);
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kGood) << f.quality.action;
  for (const PatchView& pv : f.views) {
    EXPECT_EQ(pv.quality.verdict, QualityVerdict::kGood) << pv.quality.reasons;
    EXPECT_TRUE(pv.quality.reasons.empty());
    EXPECT_EQ(pv.quality.max_normal_spread_deg, 0.0);  // a plane: every normal the same
    EXPECT_EQ(pv.quality.st_outside_share, 0.0);
    EXPECT_EQ(pv.quality.hits_behind, 0);
  }
  EXPECT_EQ(refinedGridSize(f, 4096), (std::array<int, 2>{f.grid.grid_u, f.grid.grid_v}));
}

// One map for the whole toric mirror (no split): its rays spread over more than 180 deg, some of its hits lie
// behind the viewpoint. No split can make one map hold that: fallback, with both reasons, and every traced
// seen point where the vertex's exact ray meets the scene.
TEST(FrameQuality, UnsplitToricMirrorFallsBackToTracedVertices) {
  const Scene s = test::shippedScene("car-mirror", toricSets({"elements[0].max_patch_fov_deg=179"}));
  RayScene rays(s);
  ElementFrame f = fitted(s, rays);
  ASSERT_EQ(f.views.size(), 1u);
  const PatchQuality& q = f.views[0].quality;
  EXPECT_EQ(q.verdict, QualityVerdict::kFallback) << q.reasons;
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kFallback);
  EXPECT_TRUE(q.fov_limited);
  EXPECT_GT(q.hits_behind, 0);
  EXPECT_GT(q.st_outside_share, 0.0);
  EXPECT_NE(q.reasons.find("behind the viewpoint"), std::string::npos) << q.reasons;

  EXPECT_EQ(applyTracedFallback(rays, f, 0), 0);  // no budget left: flagged, drawn from the map
  EXPECT_FALSE(f.views[0].draw_traced);
  ASSERT_EQ(applyTracedFallback(rays, f, 3), 1);
  EXPECT_TRUE(f.views[0].draw_traced);
  EXPECT_EQ(f.views[0].quality.action, "drawn from traced vertex colours");
  int checked = 0;
  for (const VertexRay& r : f.rays[0]) {
    EXPECT_TRUE(r.traced);
    if (r.status != VertexStatus::Hit) continue;
    // The hit is on the environment (the car mirror's scene has no other element): the tracer's diffuse end.
    EXPECT_LT(glm::length(r.traced_seen - r.hit), kSeenTol_m);
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

// By default the toric mirror is split (90 deg) and, its triangles spanning ~12 deg of normals, asks for a finer
// grid within the budget; the split patches are not fallbacks.
TEST(FrameQuality, DefaultSplitsTheToricMirrorAndAsksForAFinerGrid) {
  const Scene s = test::shippedScene("car-mirror", toricSets());
  EXPECT_DOUBLE_EQ(s.elements[0].max_patch_fov_rad, radians(kDefaultMaxPatchFovDeg));
  RayScene rays(s);
  const ElementFrame f = fitted(s, rays);
  EXPECT_GT(f.views.size(), 1u) << f.split_note;
  double spread = 0;
  for (const PatchView& pv : f.views) {
    EXPECT_NE(pv.quality.verdict, QualityVerdict::kFallback) << pv.quality.reasons;
    spread = std::max(spread, pv.quality.max_normal_spread_deg);
  }
  EXPECT_GT(spread, FrameQualityLimits{}.max_normal_spread_deg);
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kDegraded);
  const std::array<int, 2> size = refinedGridSize(f, 4096);
  EXPECT_GT(size[0], 15);
  EXPECT_LE(size[0] * size[1], 4096);
  // The refined grid brings every seen triangle within the limit.
  ElementGridCache cache;
  cache.refine(s, 0, size[0], size[1]);
  EXPECT_EQ(cache.refined(0), size);
  ElementFrame g = prepareElement(s, 0, &cache.get(s, 0));
  VertexStageOptions o;
  o.viewer_clip = s.observer.visibilityProjection() * s.observer.view();
  traceVertexRays(rays, g, s.observer.eye, o);
  fitPatchViews(s, g, o);
  for (const PatchView& pv : g.views) {
    EXPECT_LE(pv.quality.max_normal_spread_deg, FrameQualityLimits{}.max_normal_spread_deg);
    EXPECT_NE(pv.quality.verdict, QualityVerdict::kFallback) << pv.quality.reasons;
  }
}

// refinedGridSize in closed form: the spread falls in proportion to the spacing, aimed at 90 % of the limit.
TEST(FrameQuality, RefinedGridSizeScalesWithTheSpreadWithinTheBudget) {
  ElementFrame f;
  f.grid.grid_u = 15;
  f.grid.grid_v = 15;
  f.views.resize(1);
  f.views[0].quality.max_normal_spread_deg = 12.0;
  // 12 / (0.9 * 6) = 2.22: 1 + ceil(14 * 2.22) = 33.
  EXPECT_EQ(refinedGridSize(f, 4096), (std::array<int, 2>{33, 33}));
  // A budget of 500: (1 + 14 k)^2 <= 500 gives k <= 1.526, 1 + ceil(21.4) = 23 (529 > 500): rounded down, 22.
  EXPECT_EQ(refinedGridSize(f, 500), (std::array<int, 2>{22, 22}));
  f.views[0].quality.max_normal_spread_deg = 5.9;  // within the limit: as it is
  EXPECT_EQ(refinedGridSize(f, 4096), (std::array<int, 2>{15, 15}));
  f.views[0].quality.max_normal_spread_deg = 12.0;
  f.views[0].in_view = false;  // unseen patches ask for nothing
  EXPECT_EQ(refinedGridSize(f, 4096), (std::array<int, 2>{15, 15}));
  // A lens's TIR region: its traced directions spread 4 deg across a triangle against the 2 deg limit, the same
  // ratio as 12 deg of normals against 6: 33 x 33 (the thick TIR lens: 64' median at 24 x 24 -> 3.8' at 64 x 64,
  // docs/robustness.md).
  f.views[0].in_view = true;
  f.views[0].quality.max_normal_spread_deg = 1.0;
  f.views[0].quality.max_traced_spread_deg = 4.0;
  EXPECT_EQ(refinedGridSize(f, 4096), (std::array<int, 2>{33, 33}));
  f.views[0].quality.max_traced_spread_deg = 1.9;  // within its limit
  EXPECT_EQ(refinedGridSize(f, 4096), (std::array<int, 2>{15, 15}));
}

// render.viewpoint_solver: parsed, refused when unknown, and each solver fits the stiff toric patches with an
// accepted, checked result.
TEST(FrameQuality, ViewpointSolverIsASceneChoice) {
  for (const char* name : {"auto", "gauss-newton", "ceres", "closed-form"})
    EXPECT_STREQ(nameOf(*parseName<ViewpointSolver>(name)), name);
  EXPECT_FALSE(parseName<ViewpointSolver>("newton"));
  EXPECT_THROW(test::shippedScene("car-mirror", {R"(render.viewpoint_solver="newton")"}), Error);
  const std::pair<const char*, const char*> solvers[] = {
      {"gauss-newton", "gauss-newton"}, {"ceres", "ceres"}, {"closed-form", "closed form only"}};
  for (const auto& [name, report] : solvers) {
    const Scene s =
        test::shippedScene("car-mirror", toricSets({std::string("render.viewpoint_solver=\"") + name + "\""}));
    EXPECT_STREQ(nameOf(s.render.viewpoint_solver), name);
    RayScene rays(s);
    VertexStageOptions o;
    o.viewpoint.solver = s.render.viewpoint_solver;
    const ElementFrame f = fitted(s, rays, o);
    for (const PatchView& pv : f.views) {
      EXPECT_TRUE(pv.fit.accepted) << name << ": " << pv.fit.solver_report << " " << pv.fit.fallback;
      EXPECT_EQ(pv.fit.solver_report.rfind(report, 0), 0u) << name << ": " << pv.fit.solver_report;
    }
  }
}

}  // namespace
}  // namespace pvrr
