// Which side of an element the eye sees (pvrr/method/eye_side.h): the notes in the user's terms, and a lens
// seen from behind made a fallback patch drawn from the tracer along the eye's rays.
#include <gtest/gtest.h>

#include "cad/nurbs.h"
#include "pvrr/method/eye_side.h"
#include "pvrr/method/frame_quality.h"
#include "pvrr/method/pass_plan.h"
#include "pvrr/method/vertex_stage.h"
#include "pvrr/trace/ray_scene.h"
#include "pvrr/trace/tracer.h"
#include "support/scenes.h"

namespace pvrr {
namespace {

// Element 0 traced from the observer's eye and fitted, as the renderer's CPU stages do.
ElementFrame frameFromEye(const Scene& s, const RayScene& rays) {
  VertexStageOptions o;
  o.channels = dispersionChannels(s, 0);
  o.tir_trace_depth = s.render.max_depth;
  o.viewer_clip = s.observer.visibilityProjection() * s.observer.view();
  ElementFrame f = prepareElement(s, 0);
  traceVertexRays(rays, f, s.observer.eye, o);
  fitPatchViews(s, f, o);
  return f;
}

TEST(EyeSide, PlaneMirrorFromTheFrontHasNoNote) {
  const Scene s = test::shippedScene("plane-mirror");
  const RayScene rays(s);
  const ElementFrame f = frameFromEye(s, rays);
  const EyeSide side = eyeSide(f);
  EXPECT_GT(side.seen, 0);
  EXPECT_EQ(side.back, 0);
  EXPECT_EQ(f.quality.note, "");
}

TEST(EyeSide, EyeBehindAPlaneMirrorIsExplained) {
  // The mirror hangs at z = -1.99 facing +z; the eye 1 m behind it, looking at its back.
  const Scene s =
      test::shippedScene("plane-mirror", {"observer.eye=[0.2, 1.5, -3]", "observer.target=[0, 1.4, -1.99]"});
  const RayScene rays(s);
  const ElementFrame f = frameFromEye(s, rays);
  const EyeSide side = eyeSide(f);
  EXPECT_GT(side.seen, 0);
  EXPECT_EQ(side.back, side.seen);
  EXPECT_EQ(f.quality.note.rfind("the eye is behind mirror '", 0), 0u) << f.quality.note;
  EXPECT_NE(f.quality.note.find("(its back side faces the eye): nothing is reflected toward it"), std::string::npos);
  // The picture is the mirror's dark back in every mode, as traced: nothing to flag.
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kGood);
}

TEST(EyeSide, EyeInTheMirrorsPlaneSeesPartOfItsBack) {
  // A convex mirror curves away from its plane: an eye beside it, a little in front of the plane, sees the front
  // of the near part and the back of the far part.
  const Scene s = test::shippedScene("car-mirror");
  ASSERT_EQ(s.elements[0].type, ElementType::Mirror);
  ElementFrame f = prepareElement(s, 0);
  const Vec3 centre = Vec3(s.elements[0].local_to_world[3]),
             n = glm::normalize(f.world_normal[f.world_normal.size() / 2]);
  // Just in front of the mirror's centre tangent plane, far to one side: the rim curving back is seen from behind.
  Vec3 side = glm::normalize(glm::cross(n, Vec3(0, 1, 0)));
  f.eye = centre + 1e-3 * n + 0.5 * side;
  const EyeSide e = eyeSide(f);
  EXPECT_GT(e.back, 0);
  EXPECT_LT(e.back, e.seen);
  const std::string note = eyeSideNote(s, f);
  EXPECT_NE(note.find("the eye sees the back side of mirror '"), std::string::npos) << note;
  EXPECT_NE(note.find(std::to_string(e.back) + " of " + std::to_string(e.seen) + " seen vertices"), std::string::npos)
      << note;
}

TEST(EyeSide, LensFromBehindFallsBackToTheTracerAlongTheEyesRays) {
  const Scene s = test::shippedScene(
      "reading-lens", {"observer.eye=[0, 0.85, 0.06]", "observer.target=[0, 1.25, 0.3]", "render.dispersion=\"off\""});
  const RayScene rays(s);
  ElementFrame f = frameFromEye(s, rays);
  EXPECT_EQ(f.quality.verdict, QualityVerdict::kFallback);
  EXPECT_NE(f.quality.note.find("the eye is behind lens 'reading-lens' (its back surface faces the eye)"),
            std::string::npos)
      << f.quality.note;
  ASSERT_GT(applyTracedFallback(rays, f, s.render.max_depth - 2), 0);
  // Each traced vertex colour is the reference's along the eye's ray through the vertex.
  TraceOptions to;
  to.max_depth = s.render.max_depth;
  const Tracer tracer(rays, to);
  int checked = 0;
  for (size_t i = 0; i < f.world_pos.size(); i += 37) {
    if (!f.in_view.empty() && f.in_view[i] != 2) continue;
    const VertexRay& r = f.rays[0][i];
    ASSERT_TRUE(r.traced) << i;
    const TraceResult t = tracer.trace(s.observer.eye, glm::normalize(f.world_pos[i] - s.observer.eye), kLineD_nm);
    EXPECT_LT(glm::length(r.traced_color - t.color), 1e-12) << i;
    EXPECT_EQ(t.first_element, 0) << i;  // the eye's ray meets the lens (its back) first
    ++checked;
  }
  EXPECT_GT(checked, 5);
}

// A non-rational biquadratic patch z = k (x^2 + y^2) over [-hx, hx] x [-hy, hy], x(u) = u and y(v) = v exactly
// (quadratic Bezier control values of x^2 over [a, b]: a^2, a b, b^2): a paraboloid of vertex radius 1 / (2 k),
// concave towards +z for k > 0 (the mirror's front), flat for k = 0. du x dv points to +z.
cad::SurfacePtr paraboloidNurbs(double hx, double hy, double k) {
  cad::NurbsDefinition d;
  d.degree_u = d.degree_v = 2;
  d.count_u = d.count_v = 3;
  d.knots_u = {-hx, -hx, -hx, hx, hx, hx};
  d.knots_v = {-hy, -hy, -hy, hy, hy, hy};
  const double xs[3] = {-hx, 0, hx}, ys[3] = {-hy, 0, hy};
  const double px[3] = {hx * hx, -hx * hx, hx * hx}, py[3] = {hy * hy, -hy * hy, hy * hy};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) d.points.push_back(Vec3(xs[i], ys[j], k * (px[i] + py[j])));
  return std::make_shared<cad::NurbsSurface>(d, "test paraboloid");
}

// The nested-parallax flag (docs/robustness.md, the hunt: a concave mirror facing a plane mirror) on any
// surface: the mirror pair's convex mirror made a concave NURBS paraboloid (vertex radius 1 m, as the hunt's
// sphere R -1 m) and its wall mirror a flat NURBS patch. Before, only sag surfaces were recognised as the element
// a vertex ray lands on, so nothing was flagged here.
TEST(EyeSide, NestedParallaxIsFlaggedOnNurbsMirrors) {
  auto patches = [](const ElementFrame& f) {
    int n = 0;
    for (const PatchView& pv : f.views)
      n += pv.quality.reasons.find("other elements seen in its map from") != std::string::npos;
    return n;
  };
  // The shipped pair (sag surfaces): not flagged (3.4' against the 10' limit).
  {
    const Scene s = test::shippedScene("mirror-pair", {"observer.image_size=[96, 72]"});
    const RayScene rays(s);
    const ElementFrame f = frameFromEye(s, rays);
    EXPECT_EQ(patches(f), 0);
    EXPECT_EQ(f.quality.verdict, QualityVerdict::kGood) << f.quality.action;
  }
  for (const bool concave_nurbs : {false, true}) {
    Scene s = test::shippedScene(
        "mirror-pair", {"observer.image_size=[96, 72]", R"(elements[0].surface={"type":"sphere","radius":-1.0})"});
    // The wall mirror, 1.2 x 0.9 m: a flat NURBS patch a little larger than its outline.
    s.elements[1].surface = paraboloidNurbs(0.61, 0.46, 0.0);
    if (concave_nurbs) s.elements[0].surface = paraboloidNurbs(0.16, 0.12, 0.5);
    const RayScene rays(s);
    const ElementFrame f = frameFromEye(s, rays);
    EXPECT_GT(patches(f), 0) << "concave mirror " << (concave_nurbs ? "NURBS" : "sphere");
    EXPECT_EQ(f.quality.verdict, QualityVerdict::kDegraded) << f.quality.action;
    EXPECT_NE(f.quality.action.find("patch(es) flagged: the mirrors or lenses its maps show"), std::string::npos)
        << f.quality.action;
    for (const PatchView& pv : f.views)
      if (!pv.quality.reasons.empty())
        std::printf("[ measured ] %s patch %d: %s\n", concave_nurbs ? "NURBS" : "sphere", pv.patch,
                    pv.quality.reasons.c_str());
  }
}

// A mirror patch whose near plane could not be placed at the mirror holds what lies behind the mirror: two cards 2
// and 6 cm before the wall mirror (tests/data/stress/hunt-impostor-behind-two-cards.json) moved its near plane 47 mm
// towards the viewpoint and the wall 1 cm behind the mirror covered a triangle of the picture in pvrr mode (p95
// 10800', passed as good). The map's environment pass now clips what lies behind the mirror's plane
// (ViewVolume::clip_plane; the picture: tests/gl/pvrr/behind_mirror_clip_test.cpp), so the check, which counts only
// the part of each segment the plane keeps, no longer flags it; a patch where the plane keeps what lies behind the
// mirror in the map is still flagged. No element of the shipped scenes is flagged, nor keeps a clip plane.
TEST(EyeSide, WhatLiesBehindAMirrorInsideItsMapIsClippedOrFlagged) {
  const Scene s = buildScene(
      loadScene(std::string(PVRR_SOURCE_DIR) + "/tests/data/stress/hunt-impostor-behind-two-cards.json", {}));
  const RayScene rays(s);
  const ElementFrame f = frameFromEye(s, rays);
  EXPECT_EQ(f.quality.action.find("behind the mirror"), std::string::npos) << f.quality.action;
  ASSERT_FALSE(f.views.empty());
  EXPECT_GT(f.views[0].volume.mirror_vertices_unclipped, 0);
  ASSERT_TRUE(f.views[0].volume.clip_plane.has_value()) << f.views[0].volume.note;
  // The plane is the mirror's: the wall mirror's vertices lie on it (within 1e-6 of the mirror's size).
  const Vec4 plane = *f.views[0].volume.clip_plane;
  for (uint32_t vi : f.grid_patches[size_t(f.views[0].patch)].vertices)
    EXPECT_NEAR(glm::dot(Vec3(plane), f.world_pos[vi]) + plane.w, 0.0, 1e-5);
  std::printf("[ measured ] two cards: '%s'; %s\n", f.quality.action.c_str(), f.views[0].volume.note.c_str());
  for (const char* name : {"plane-mirror", "concave-mirror", "car-mirror", "mirror-pair", "saddle-mirror",
                           "shaving-mirror-sun", "overtaking-car"}) {
    const Scene sh = test::shippedScene(name);
    const RayScene r(sh);
    for (size_t e = 0; e < sh.elements.size(); ++e) {
      if (sh.elements[e].type != ElementType::Mirror) continue;
      VertexStageOptions o;
      o.channels = dispersionChannels(sh, int(e));
      o.viewer_clip = sh.observer.visibilityProjection() * sh.observer.view();
      ElementFrame fe = prepareElement(sh, int(e));
      traceVertexRays(r, fe, sh.observer.eye, o);
      fitPatchViews(sh, fe, o);
      EXPECT_EQ(fe.quality.action.find("behind the mirror"), std::string::npos)
          << name << " " << e << ": " << fe.quality.action;
      for (const PatchView& pv : fe.views)
        EXPECT_FALSE(pv.in_view && pv.volume.clip_plane.has_value()) << name << " " << e << " patch " << pv.patch;
    }
  }
}

}  // namespace
}  // namespace pvrr
