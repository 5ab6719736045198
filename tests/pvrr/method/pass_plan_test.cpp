// The planning of pvrr mode's first passes without GL (pvrr/method/pass_plan.h): map sizes, the nested passes of the
// mirror pair, map reuse and widening.
#include <gtest/gtest.h>

#include <cmath>

#include "pvrr/method/pass_plan.h"
#include "pvrr/trace/ray_scene.h"
#include "pvrr/method/view_volume.h"
#include "support/scenes.h"

namespace pvrr {
namespace {

// Top-level frames as the renderer's CPU stages make them without a cache: each element traced from the eye
// with its own channels and the tracer's depth budget, fitted to what the observer sees.
struct TopLevel {
  std::vector<ElementFrame> frames;
  std::vector<VertexStageOptions> opts;
};
TopLevel topLevelFrames(const Scene& s, const RayScene& rays) {
  TopLevel t;
  const Observer& ob = s.observer;
  for (size_t e = 0; e < s.elements.size(); ++e) {
    VertexStageOptions o;
    o.channels = dispersionChannels(s, int(e));
    o.tir_trace_depth = elementInterfaces(s.elements[e]) > s.render.max_depth ? 0 : s.render.max_depth;
    o.viewer_clip = ob.visibilityProjection() * ob.view();
    ElementFrame f = prepareElement(s, int(e));
    traceVertexRays(rays, f, ob.eye, o);
    fitPatchViews(s, f, o);
    t.frames.push_back(std::move(f));
    t.opts.push_back(o);
  }
  return t;
}

TEST(PassPlan, PatchMapSizeKeepsFourFullMapsOfTexels) {
  const int map_size = 1024;
  int previous = map_size;
  for (size_t n = 1; n <= 64; ++n) {
    const int s = patchMapSize(map_size, n);
    if (n <= 4) {
      EXPECT_EQ(s, map_size) << n;  // up to four patches each get the full size
    }
    EXPECT_LE(s, previous) << n;              // more patches never get larger maps
    EXPECT_GE(s, 128) << n;
    // All of them together about as many texels as four full maps (never more, but for the 128 floor).
    if (s > 128) {
      EXPECT_LE(double(n) * s * s, 4.0 * map_size * map_size) << n;
    }
    previous = s;
  }
  EXPECT_EQ(patchMapSize(1024, 5), 512);   // shrink ceil(sqrt(5 / 4)) = 2
  EXPECT_EQ(patchMapSize(1024, 16), 512);  // sqrt(16 / 4) = 2 exactly
  EXPECT_EQ(patchMapSize(1024, 17), 341);  // ceil(sqrt(17 / 4)) = 3
  EXPECT_EQ(patchMapSize(1024, 64), 256);
  EXPECT_EQ(patchMapSize(256, 64), 128);   // the floor
  EXPECT_EQ(patchMapSize(128, 64), 128);   // small maps are never shrunk
  EXPECT_EQ(patchMapSize(64, 64), 64);
}

TEST(PassPlan, NestedMapsAreHalfTheParentDownTo128) {
  EXPECT_EQ(nestedMapSize(1024), 512);
  EXPECT_EQ(nestedMapSize(512), 256);
  EXPECT_EQ(nestedMapSize(256), 128);
  EXPECT_EQ(nestedMapSize(200), 128);
  EXPECT_EQ(nestedMapSize(128), 128);
  EXPECT_EQ(nestedMapSize(64), 64);  // a parent at or under the floor keeps its size
}

// The mirror pair (models/mirror-pair.json) at 160 x 120: the observer sees the convex mirror, whose map shows
// the back-wall mirror (behind the observer, not seen directly), whose map shows the convex mirror again, and so
// on: a tunnel of nested maps, each fitted to what its parent's map camera sees of it.
class MirrorPairPlan : public ::testing::Test {
 protected:
  Scene s = test::shippedScene("mirror-pair", {"observer.image_size=[160,120]"});
  RayScene rays{s};
  PassPlanOptions options;
  TopLevel t;

  PassPlan plan(int max_depth) {
    s.render.max_depth = max_depth;
    t = topLevelFrames(s, rays);
    return planPasses(s, rays, t.frames, t.opts, options);
  }
};

// render.max_depth = 4: depth 1 (convex) -> 2 (back wall) -> 3 (convex) -> 4 (back wall), one nested pass per
// mirror and level; the depth-4 map camera no longer sees the convex mirror, so nothing is drawn dark.
TEST_F(MirrorPairPlan, OneNestedPassPerMirrorAndLevel) {
  const PassPlan p = plan(4);
  ASSERT_EQ(s.elements.size(), 2u);
  ASSERT_EQ(p.top, 2u);  // one patch each
  EXPECT_TRUE(p.passes[0].visible);   // the convex mirror
  EXPECT_FALSE(p.passes[1].visible);  // the back-wall mirror is behind the observer: no top-level map
  EXPECT_TRUE(p.passes[1].nested.empty());
  ASSERT_EQ(p.nested(), 3u);
  EXPECT_EQ(p.nested_frames.size(), 3u);
  EXPECT_EQ(p.dark, 0u);
  EXPECT_FALSE(p.budget_hit);
  EXPECT_EQ(p.visiblePasses(), 4u);
  // Each pass that reads a nested map holds exactly one nested draw, of the other mirror, whose pass follows
  // it in the list (parents before children), one level deeper, at half its size (at least 128).
  const MapPass* parent = &p.passes[0];
  for (size_t i = p.top; i < p.passes.size(); ++i) {
    const MapPass& mp = p.passes[i];
    EXPECT_EQ(mp.owner->element, parent->owner->element == 0 ? 1 : 0) << i;
    EXPECT_EQ(mp.depth, parent->depth + 1) << i;
    EXPECT_EQ(mp.slot, i);
    EXPECT_EQ(mp.size, nestedMapSize(parent->size)) << i;
    EXPECT_LE(mp.side, std::min(mp.size, nestedMapSize(parent->side))) << i;
    ASSERT_EQ(parent->nested.size(), 1u) << i;
    EXPECT_EQ(parent->nested[0].element, mp.owner->element);
    EXPECT_EQ(parent->nested[0].frame, mp.owner);
    EXPECT_EQ(parent->nested[0].first_slot, i);
    parent = &mp;
  }
  EXPECT_EQ(parent->depth, 4);
  EXPECT_TRUE(parent->nested.empty());
}

// render.max_depth = 3: the depth-3 map shows the back-wall mirror, whose reflection would be event 4: drawn
// dark there.
TEST_F(MirrorPairPlan, TheDepthLimitDrawsTheInnermostMirrorDark) {
  const PassPlan p = plan(3);
  EXPECT_EQ(p.nested(), 2u);
  EXPECT_EQ(p.dark, 1u);
  EXPECT_FALSE(p.budget_hit);  // the depth limit, not the budget
  const MapPass& deepest = p.passes.back();
  EXPECT_EQ(deepest.depth, 3);
  ASSERT_EQ(deepest.nested.size(), 1u);
  EXPECT_EQ(deepest.nested[0].element, 1);
  EXPECT_EQ(deepest.nested[0].frame, nullptr);
}

TEST_F(MirrorPairPlan, DepthOneDrawsTheOtherMirrorDark) {
  const PassPlan p = plan(1);
  EXPECT_EQ(p.nested(), 0u);
  EXPECT_EQ(p.dark, 1u);
  EXPECT_FALSE(p.budget_hit);
  ASSERT_EQ(p.passes[0].nested.size(), 1u);
  EXPECT_EQ(p.passes[0].nested[0].element, 1);
  EXPECT_EQ(p.passes[0].nested[0].frame, nullptr);
}

// The back-wall mirror split into 4 x 4 patches needs 16 maps when nested: with the convex mirror's own map
// that exceeds the budget of kMaxFirstPasses, so it is drawn dark in the convex mirror's map.
TEST_F(MirrorPairPlan, TheBudgetOfSixteenFirstPassesDrawsTheRestDark) {
  s.elements[1].patches_u = s.elements[1].patches_v = 4;
  const PassPlan p = plan(4);
  ASSERT_EQ(p.top, 17u);
  EXPECT_EQ(p.visiblePasses(), 1u);  // the back-wall mirror's own patches are out of view
  EXPECT_EQ(p.nested(), 0u);
  EXPECT_EQ(p.dark, 1u);
  EXPECT_TRUE(p.budget_hit);
  ASSERT_EQ(p.passes[0].nested.size(), 1u);
  EXPECT_EQ(p.passes[0].nested[0].frame, nullptr);
  // Split 3 x 3, 1 + 9 maps fit: the back-wall mirror is nested with its nine maps, and what follows stays
  // within the budget.
  s.elements[1].patches_u = s.elements[1].patches_v = 3;
  const PassPlan q = plan(4);
  ASSERT_EQ(q.passes[0].nested.size(), 1u);
  EXPECT_NE(q.passes[0].nested[0].frame, nullptr);
  EXPECT_GE(q.nested(), 9u);
  EXPECT_LE(q.visiblePasses(), kMaxFirstPasses);
}

TEST(PassPlan, TopLevelVisibilityAndDepth) {
  Scene s = test::shippedScene("spectacle-lens", {"observer.image_size=[80,60]"});
  RayScene rays(s);
  TopLevel t = topLevelFrames(s, rays);
  ASSERT_EQ(t.frames.size(), 1u);
  EXPECT_EQ(elementInterfaces(s.elements[0]), 2);
  EXPECT_FALSE(beyondDepth(s, t.frames[0]));
  s.render.max_depth = 1;  // a lens's back surface is beyond it: drawn dark, no map
  EXPECT_TRUE(beyondDepth(s, t.frames[0]));
  for (size_t v = 0; v < t.frames[0].views.size(); ++v) EXPECT_FALSE(topLevelVisible(s, t.frames[0], v));
}

// rayOrigins on the plane mirror, whose viewpoint is exact: a point seen through one of its vertices (on the
// line from the viewpoint through it, beyond the mirror) takes that vertex's outgoing-ray origin, the vertex
// itself; a point far outside the map's view takes the viewpoint.
TEST(PassPlan, RayOriginsOfPointsSeenThroughTheMirror) {
  // A vertex's texture coordinates and the point's projection agree to rounding (1e-12 of the map): its
  // barycentric weights are 1 and 0 to about that, over a mirror of ~1 m.
  constexpr double kOriginTol_m = 1e-6;
  Scene s = test::shippedScene("plane-mirror", {"observer.image_size=[160,120]"});
  RayScene rays(s);
  const TopLevel t = topLevelFrames(s, rays);
  ASSERT_EQ(t.frames.size(), 1u);
  const ElementFrame& f = t.frames[0];
  const PatchView& pv = f.views[0];
  const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
  const size_t fc = f.rays.size() / 2;
  std::vector<Vec3> points, expect;
  for (size_t k = 0; k < gp.vertices.size(); k += 7) {
    const uint32_t vi = gp.vertices[k];
    if (!f.in_view.empty() && !f.in_view[vi]) continue;
    if (f.rays[fc][vi].status == VertexStatus::Tir) continue;
    const Vec3 o = f.rays[fc][vi].origin;
    points.push_back(pv.volume.eye + 3.0 * (o - pv.volume.eye));
    expect.push_back(o);
  }
  ASSERT_GT(points.size(), 3u);
  // Far to the side of the map's view: no triangle within half a triangle of it.
  const Vec3 side = glm::normalize(glm::cross(expect[0] - pv.volume.eye, Vec3(0, 1, 0)));
  points.push_back(expect[0] + 1e3 * side);
  const std::vector<Vec3> got = rayOrigins(f, pv, points);
  ASSERT_EQ(got.size(), points.size());
  for (size_t i = 0; i < expect.size(); ++i) EXPECT_LT(glm::length(got[i] - expect[i]), kOriginTol_m) << i;
  EXPECT_EQ(got.back(), pv.volume.eye);
}

// Map reuse on the plane mirror (one element, nothing to nest): the maps are widened once, and a later frame
// draws from them while it stays inside them.
class PlaneMirrorReuse : public ::testing::Test {
 protected:
  Scene s = test::shippedScene("plane-mirror", {"observer.image_size=[160,120]"});
  RayScene rays{s};
  PassPlanOptions options;
  static constexpr uint64_t kSerial = 7;

  // The cache after a first pass of widened maps, as the renderer records it.
  FrameCache widenedCache() {
    TopLevel t = topLevelFrames(s, rays);
    const std::vector<std::array<int, 2>> widened = widenMaps(s, t.frames, options, 16384);
    const PassPlan p = planPasses(s, rays, t.frames, t.opts, options, &widened);
    EXPECT_EQ(p.nested(), 0u);
    EXPECT_EQ(p.dark, 0u);
    FrameCache c;
    c.valid = true;
    for (size_t i = 0; i < widened.size(); ++i) {
      const MapPass& mp = p.passes[i];
      c.maps.push_back({mp.owner->element, mp.view, mp.owner->views[mp.view].volume, mp.side, mp.visible});
    }
    c.maps_serial = kSerial;
    return c;
  }
};

TEST_F(PlaneMirrorReuse, AnUnchangedFrameDrawsFromTheWidenedMaps) {
  const FrameCache c = widenedCache();
  TopLevel t = topLevelFrames(s, rays);
  std::string note;
  ASSERT_TRUE(reuseMaps(s, t.frames, c, options, kSerial, {}, &note)) << note;
  EXPECT_EQ(note.rfind("map reuse: every view lies inside the maps drawn 1 frame(s) ago", 0), 0u) << note;
  // Each seen view now has its map's (widened) volume.
  for (size_t v = 0; v < t.frames[0].views.size(); ++v)
    if (c.maps[v].rendered) {
      EXPECT_EQ(t.frames[0].views[v].volume.eye, c.maps[v].volume.eye);
    }
}

TEST_F(PlaneMirrorReuse, AnotherRenderersMapsAreNotReused) {
  const FrameCache c = widenedCache();
  TopLevel t = topLevelFrames(s, rays);
  std::string note;
  EXPECT_FALSE(reuseMaps(s, t.frames, c, options, kSerial + 1, {}, &note));
  EXPECT_EQ(note, "this renderer drew other maps since");
  EXPECT_FALSE(reuseMaps(s, t.frames, FrameCache{}, options, kSerial, {}, &note));
  EXPECT_EQ(note.rfind("no reusable maps", 0), 0u) << note;
}

TEST_F(PlaneMirrorReuse, PlanesMapsAreNotReusedForRgbaChannels) {
  const FrameCache c = widenedCache();
  TopLevel t = topLevelFrames(s, rays);
  std::string note;
  EXPECT_FALSE(reuseMaps(s, t.frames, c, options, kSerial, std::vector<bool>(c.maps.size(), true), &note));
  EXPECT_EQ(note, "the colour channels changed");
}

TEST_F(PlaneMirrorReuse, AMoveBeyondTheMarginOrParallaxRendersAgain) {
  const FrameCache c = widenedCache();
  // A step of 5 cm sideways: its view stays inside the 2 deg margin, but the viewpoint moves by far more than a
  // quarter texel of parallax (4.3 texels at 160 x 120).
  const Vec3 step = 0.05 * glm::normalize(glm::cross(s.observer.target - s.observer.eye, s.observer.up));
  s.observer.eye += step;
  s.observer.target += step;
  TopLevel t = topLevelFrames(s, rays);
  std::string note;
  EXPECT_FALSE(reuseMaps(s, t.frames, c, options, kSerial, {}, &note));
  EXPECT_EQ(note.rfind("the viewpoint moved too far (parallax", 0), 0u) << note;
}

// A step of 1 mm (about a tenth of a texel of parallax) stays inside maps widened by 2 deg, not inside maps
// widened by 1e-4 deg.
TEST_F(PlaneMirrorReuse, ASmallStepLeavesANarrowMargin) {
  const Vec3 step = 1e-3 * glm::normalize(glm::cross(s.observer.target - s.observer.eye, s.observer.up));
  const FrameCache wide = widenedCache();
  options.map_reuse_margin_deg = 1e-4;
  const FrameCache narrow = widenedCache();
  s.observer.eye += step;
  s.observer.target += step;
  TopLevel t = topLevelFrames(s, rays);
  std::string note;
  EXPECT_FALSE(reuseMaps(s, t.frames, narrow, options, kSerial, {}, &note));
  EXPECT_EQ(note, "a view left its map's margin");
  options.map_reuse_margin_deg = 2;
  t = topLevelFrames(s, rays);
  EXPECT_TRUE(reuseMaps(s, t.frames, wide, options, kSerial, {}, &note)) << note;
}

TEST_F(PlaneMirrorReuse, AStepWellUnderAQuarterTexelOfParallaxIsReused) {
  const FrameCache c = widenedCache();
  const Vec3 step = 2e-5 * glm::normalize(glm::cross(s.observer.target - s.observer.eye, s.observer.up));  // 0.02 mm
  s.observer.eye += step;
  s.observer.target += step;
  TopLevel t = topLevelFrames(s, rays);
  std::string note;
  ASSERT_TRUE(reuseMaps(s, t.frames, c, options, kSerial, {}, &note)) << note;
  EXPECT_NE(note.find("viewpoints moved <= 0.0"), std::string::npos) << note;  // mm, the virtual eye's step
}

TEST_F(PlaneMirrorReuse, WideningGrowsTheExtentByAtMostTwentyPercent) {
  for (const double margin_deg : {0.5, 2.0, 10.0, 30.0}) {
    options.map_reuse_margin_deg = margin_deg;
    TopLevel t = topLevelFrames(s, rays);
    const std::vector<ElementFrame> narrow = t.frames;
    const std::vector<std::array<int, 2>> widened = widenMaps(s, t.frames, options, 16384);
    ASSERT_EQ(widened.size(), t.frames[0].views.size());
    for (size_t v = 0; v < widened.size(); ++v) {
      const ViewVolume &W = t.frames[0].views[v].volume, &N = narrow[0].views[v].volume;
      ASSERT_FALSE(N.backward);
      const double grow = longerExtentTan(W) / longerExtentTan(N);
      EXPECT_GT(grow, 1.0) << margin_deg;
      EXPECT_LE(grow, kMaxWidening + 1e-9) << margin_deg;
      EXPECT_TRUE(frustumContains(W, N)) << margin_deg;
      const int base = patchMapSize(options.map_size, patchesInView(narrow[0]));
      EXPECT_EQ(widened[v][0], 32 * int(std::ceil(1.25 * base / 32.0)));  // 25 % larger, in steps of 32
      EXPECT_LE(widened[v][1], widened[v][0]);
      EXPECT_GE(widened[v][1], topLevelMapSide(s, narrow[0], narrow[0].views[v], options));
    }
  }
  // A GL that cannot hold the larger texture keeps the unwidened size.
  TopLevel t = topLevelFrames(s, rays);
  const std::vector<std::array<int, 2>> small = widenMaps(s, t.frames, options, 0);
  for (const auto& ss : small) EXPECT_EQ(ss[0], patchMapSize(options.map_size, patchesInView(t.frames[0])));
}

}  // namespace
}  // namespace pvrr
