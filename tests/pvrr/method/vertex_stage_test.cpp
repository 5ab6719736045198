// The CPU stages of PVRR: per-vertex rays, viewpoint, view volume and texture coordinates.
#include <gtest/gtest.h>

#include <algorithm>

#include "pvrr/optics/optics.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/method/vertex_stage.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// The plane-mirror viewpoint is exact: 1e-9 relative is the bound (the fit itself reaches ~1e-15).
constexpr double kViewpointRelTol = 1e-9;
// Per-vertex laws of reflection and refraction hold to double precision.
constexpr double kVertexLawTol = 1e-12;

TEST(VertexStage, PlaneMirrorViewpointIsTheMirrorImageOfTheEye) {
  Scene s = test::roomScene(Vec3(0.4, 0.3, 1.8), Vec3(0, 0, 0));
  const cad::Outline outline = cad::Outline::rectangle(0.6, 0.4, 0.05);
  // A mirror tilted about y, so the image is not trivially (x, y, -z).
  const Vec3 normal = glm::normalize(Vec3(0.2, 0.0, 1.0)), centre(0.1, -0.05, 0.0);
  test::addMirror(s, cad::makePlane(outline), outline, test::pose(centre, normal), 9);
  s.updateBounds();
  RayScene rays(s);
  ElementFrame f = prepareElement(s, 0);
  VertexStageOptions opt;
  traceVertexRays(rays, f, s.observer.eye, opt);
  fitPatchViews(s, f, opt);
  ASSERT_EQ(f.views.size(), 1u);
  const Vec3 e = s.observer.eye;
  const Vec3 image = e - 2.0 * glm::dot(e - centre, normal) * normal;
  EXPECT_LT(glm::length(f.views[0].fit.eye - image), kViewpointRelTol * glm::length(image));
  EXPECT_TRUE(f.views[0].fit.fallback.empty()) << f.views[0].fit.fallback;
  EXPECT_TRUE(std::isfinite(f.views[0].fit.condition_number));
  for (const Vec2& st : f.views[0].st[0]) {
    EXPECT_GE(st.x, 0.0);
    EXPECT_LE(st.x, 1.0);
    EXPECT_GE(st.y, 0.0);
    EXPECT_LE(st.y, 1.0);
  }
}

// ElementGridCache keeps an element's tessellation while its surface, grid size and outline stay the same
// (a rigid element moved, or the observer turned: the same grid, posed anew), and tessellates again when any
// of them changes. A frame prepared from the kept grid equals a fresh one exactly.
TEST(ElementGridCache, KeepsTheTessellationWhileTheElementKeepsItsShape) {
  Scene s = test::roomScene(Vec3(0.4, 0.3, 1.8), Vec3(0, 0, 0));
  const cad::Outline outline = cad::Outline::rectangle(0.6, 0.4, 0.05);
  test::addMirror(s, cad::makeSphere(1.5, outline), outline, test::pose(Vec3(0.1, -0.05, 0), Vec3(0.2, 0, 1)), 9);
  ElementGridCache cache;
  auto samePositions = [](const cad::Tessellation& a, const cad::Tessellation& b) {
    return a.positions == b.positions && a.normals == b.normals && a.triangles.size() == b.triangles.size();
  };
  const cad::Tessellation& first = cache.get(s, 0);
  EXPECT_TRUE(samePositions(first, prepareElement(s, 0).grid));
  const Vec3* kept = first.positions.data();
  // Moved: the same grid (not tessellated again), and the frame from it equals a fresh one.
  s.elements[0].local_to_world = test::pose(Vec3(-0.3, 0.2, 0.1), Vec3(-0.1, 0.3, 1));
  s.elements[0].world_to_local = glm::inverse(s.elements[0].local_to_world);
  EXPECT_EQ(cache.get(s, 0).positions.data(), kept);
  const ElementFrame fresh = prepareElement(s, 0), from_cache = prepareElement(s, 0, &cache.get(s, 0));
  EXPECT_EQ(fresh.world_pos, from_cache.world_pos);
  EXPECT_EQ(fresh.world_normal, from_cache.world_normal);
  // A finer grid, another outline, another surface: tessellated again, as prepareElement does.
  s.elements[0].tess_u = 13;
  EXPECT_EQ(cache.get(s, 0).vertexCount(), size_t(13 * 9));
  EXPECT_TRUE(samePositions(cache.get(s, 0), prepareElement(s, 0).grid));
  s.elements[0].outline = cad::Outline::ellipse(0.6, 0.4);
  EXPECT_TRUE(samePositions(cache.get(s, 0), prepareElement(s, 0).grid));
  s.elements[0].surface = cad::makeSphere(0.8, s.elements[0].outline);
  EXPECT_TRUE(samePositions(cache.get(s, 0), prepareElement(s, 0).grid));
  const Vec3* now = cache.get(s, 0).positions.data();
  EXPECT_EQ(cache.get(s, 0).positions.data(), now);  // and kept again
}

// A plane rectangle facing the eye head-on projects to a rectangle: (w / (2 d tan(fov_y / 2) * aspect)) *
// width by (h / (2 d tan(fov_y / 2))) * height pixels. Half of it out of the image counts half. Behind the
// eye: nothing.
TEST(VertexStage, PatchScreenPixelsOfAHeadOnRectangle) {
  Scene s = test::roomScene(Vec3(0, 0, 2), Vec3(0, 0, 0), 400, 300);
  const double w = 0.6, h = 0.4;
  const cad::Outline outline = cad::Outline::rectangle(w, h);
  test::addMirror(s, cad::makePlane(outline), outline, test::pose(Vec3(0), Vec3(0, 0, 1)), 9);
  s.updateBounds();
  RayScene rays(s);
  ElementFrame f = prepareElement(s, 0);
  traceVertexRays(rays, f, s.observer.eye, VertexStageOptions{});
  fitPatchViews(s, f, VertexStageOptions{});
  ASSERT_EQ(f.views.size(), 1u);
  const PatchView& pv = f.views[0];
  const double half_h = 2.0 * std::tan(s.observer.fov_y_rad / 2), half_w = half_h * 400.0 / 300.0;  // at d = 2
  const double expected = (w / (2 * half_w) * 400) * (h / (2 * half_h) * 300);
  const Mat4 clip = s.observer.visibilityProjection() * s.observer.view();
  EXPECT_NEAR(patchScreenPixels(f, pv, clip, 400, 300), expected, 1e-6 * expected);
  // Looking so that the image's left edge runs through the mirror's centre: the half inside counts.
  const double yaw = std::atan(half_w / 2.0);  // the left edge of the view is yaw from the axis
  s.observer.target = s.observer.eye + Vec3(std::sin(yaw), 0, -std::cos(yaw));
  const double off = patchScreenPixels(f, pv, s.observer.visibilityProjection() * s.observer.view(), 400, 300);
  EXPECT_GT(off, 0.3 * expected);
  EXPECT_LT(off, 0.7 * expected);
  // Looking away: the mirror is behind the eye plane.
  s.observer.target = s.observer.eye + Vec3(0, 0, 1);
  EXPECT_EQ(patchScreenPixels(f, pv, s.observer.visibilityProjection() * s.observer.view(), 400, 300), 0.0);
  // Looking along the mirror's plane from its middle: part of it lies behind the eye plane, so the whole image.
  s.observer.eye = Vec3(0, 0, 0.01);
  s.observer.target = Vec3(1, 0, 0.01);
  EXPECT_EQ(patchScreenPixels(f, pv, s.observer.visibilityProjection() * s.observer.view(), 400, 300), 400.0 * 300.0);
}

TEST(VertexStage, MirrorRaysObeyTheLawOfReflection) {
  Scene s = test::roomScene(Vec3(0.2, 0.1, 1.5), Vec3(0, 0, 0));
  const cad::Outline outline = cad::Outline::rectangle(0.3, 0.2, 0.03);
  test::addMirror(s, cad::makeSphere(1.2, outline), outline, test::pose(Vec3(0), Vec3(0, 0, 1)), 7);
  s.updateBounds();
  RayScene rays(s);
  ElementFrame f = prepareElement(s, 0);
  traceVertexRays(rays, f, s.observer.eye, VertexStageOptions{});
  ASSERT_EQ(f.world_pos.size(), 49u);
  for (size_t i = 0; i < f.world_pos.size(); ++i) {
    const Vec3 d = glm::normalize(f.world_pos[i] - s.observer.eye), n = f.world_normal[i];
    const VertexRay& r = f.rays[0][i];
    EXPECT_NEAR(-glm::dot(d, n), glm::dot(r.dir, n), kVertexLawTol);             // equal angles
    EXPECT_NEAR(glm::dot(glm::cross(d, n), r.dir), 0.0, kVertexLawTol);            // coplanar
    EXPECT_EQ(r.status, VertexStatus::Hit);                                         // a closed room
    EXPECT_NEAR(glm::length(glm::cross(r.hit - r.origin, r.dir)), 0.0, 1e-9);       // hit on the ray
  }
}

TEST(VertexStage, LensRaysObeySnellAtBothSurfaces) {
  Scene s = test::roomScene(Vec3(0.0, 0.0, 0.3), Vec3(0, 0, -1));
  const cad::Outline outline = cad::Outline::circle(0.03);
  Element e;
  e.name = "lens";
  e.type = ElementType::Lens;
  e.lens = cad::makeLens(cad::makeSphere(-0.12, outline), cad::makeSphere(0.09, outline), outline, 0.002, 0.0, "t");
  e.outline = outline;
  e.local_to_world = test::pose(Vec3(0, 0, 0.288), Vec3(0, 0, 1));
  e.world_to_local = glm::inverse(e.local_to_world);
  e.dispersion = Dispersion::fromAbbe(1.498, 58);
  e.tess_u = e.tess_v = 9;
  s.elements.push_back(e);
  s.updateBounds();
  RayScene rays(s);
  ElementFrame f = prepareElement(s, 0);
  VertexStageOptions opt;
  opt.channels = {ChannelSpec{656.2725}, ChannelSpec{587.5618}, ChannelSpec{486.1327}};
  traceVertexRays(rays, f, s.observer.eye, opt);
  for (size_t c = 0; c < 3; ++c) {
    const double n = e.dispersion.index(opt.channels[c].wavelength_nm);
    size_t flagged = 0;
    for (size_t i = 0; i < f.world_pos.size(); ++i) {
      const VertexRay& r = f.rays[c][i];
      // Steep rays at the rim leave through the edge band: flagged, not refracted at the back. Only the
      // outermost ring may be flagged.
      const int gi = int(i) / f.grid.grid_v, gj = int(i) % f.grid.grid_v;
      const bool rim = gi == 0 || gj == 0 || gi == f.grid.grid_u - 1 || gj == f.grid.grid_v - 1;
      if (r.status == VertexStatus::Tir) {
        EXPECT_TRUE(rim) << "vertex " << i;
        ++flagged;
        continue;
      }
      const Vec3 d = glm::normalize(f.world_pos[i] - s.observer.eye), n1 = f.world_normal[i];
      EXPECT_NEAR(glm::length(glm::cross(d, n1)), n * glm::length(glm::cross(r.internal_dir, n1)), kVertexLawTol);
      EXPECT_NEAR(n * glm::length(glm::cross(r.internal_dir, r.back_normal)), glm::length(glm::cross(r.dir, r.back_normal)),
                  kVertexLawTol);
      EXPECT_NEAR(glm::dot(glm::cross(d, n1), r.internal_dir), 0.0, kVertexLawTol);
    }
    EXPECT_LE(flagged, size_t(4 * (9 - 1)));
  }
  // Blue bends more than red: at an off-axis vertex the channels' exit directions differ, blue most deviated.
  const size_t corner = 4 * 9 + 1;  // off-axis, well inside the rim
  const Vec3 d0 = glm::normalize(f.world_pos[corner] - s.observer.eye);
  const double dev_r = angleBetween(f.rays[0][corner].dir, d0), dev_b = angleBetween(f.rays[2][corner].dir, d0);
  EXPECT_GT(dev_b, dev_r);
}

// A spectacle lens 12 mm from the eye spans ~150 deg; a 50 deg view sees a small part of it. With the
// observer as the viewer, the view volume holds only what it sees: the rays of the vertices inside its view
// and, where its edge cuts a triangle, the rays interpolated there (not the far corners of those triangles:
// at 24 x 24 a triangle spans ~10 deg). So: a much narrower frustum (more texels where they are looked at),
// close to the view itself plus the lens's prism; every seen point's texture coordinate inside the map; and
// the same fitted viewpoint (fitted to all the rays either way).
TEST(VertexStage, ViewVolumeHoldsWhatTheViewerSees) {
  Scene s = buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/spectacle-lens.json", {"observer.image_size=[320,240]"}));
  // One patch for the whole lens, whose rays span more than the default split's 90 deg: this compares that one
  // volume with the part the viewer sees.
  s.elements[0].max_patch_fov_rad = 0;
  RayScene rays(s);
  ElementFrame all = prepareElement(s, 0);
  VertexStageOptions opt;
  traceVertexRays(rays, all, s.observer.eye, opt);
  ElementFrame seen = all;
  fitPatchViews(s, all, opt);
  opt.viewer_clip = s.observer.projection(1e-3, 1e6) * s.observer.view();
  fitPatchViews(s, seen, opt);
  ASSERT_EQ(all.views.size(), 1u);
  ASSERT_EQ(seen.views.size(), 1u);
  EXPECT_TRUE(all.in_view.empty());
  ASSERT_EQ(seen.in_view.size(), seen.world_pos.size());
  const size_t inside = size_t(std::count(seen.in_view.begin(), seen.in_view.end(), 2));
  const size_t corners = size_t(std::count(seen.in_view.begin(), seen.in_view.end(), 1));
  EXPECT_GT(inside, 20u);
  EXPECT_GT(corners, 20u);
  EXPECT_LT(inside + corners, seen.world_pos.size() / 2);  // most of the lens is outside a 50 deg view
  const PatchView& pv = seen.views[0];
  EXPECT_EQ(pv.rays_out_of_view, int(seen.world_pos.size() - inside));
  EXPECT_GT(pv.view_edge.size(), corners);  // each cut triangle adds two or more points
  EXPECT_EQ(pv.fit.eye, all.views[0].fit.eye);
  EXPECT_GT(all.views[0].volume.fov_y_rad, radians(120.0));
  // The view's 50 deg, the -3 D lens's prism at its edge (~2 deg a side) and the 2 % margins; with the whole
  // edge triangles it was 79 deg at 1280 x 720.
  EXPECT_LT(pv.volume.fov_y_rad, radians(62.0));
  EXPECT_GT(pv.volume.fov_y_rad, radians(50.0));
  const double view_x = 2 * std::atan(std::tan(radians(25.0)) * 320.0 / 240.0);  // 63.6 deg
  EXPECT_LT(pv.volume.fov_x_rad, view_x + radians(12.0));
  EXPECT_GT(pv.volume.fov_x_rad, view_x);
  std::printf("seen frustum %.1f x %.1f deg (all rays: %.1f x %.1f)\n", pv.volume.fov_x_rad * 180 / kPi,
              pv.volume.fov_y_rad * 180 / kPi, all.views[0].volume.fov_x_rad * 180 / kPi, all.views[0].volume.fov_y_rad * 180 / kPi);
  // Every cut point lies on the edge of the viewer's view: on one of its clip planes.
  for (const PatchView::ViewEdgeSample& e : pv.view_edge) {
    Vec3 p(0.0);
    for (int j = 0; j < 3; ++j) p += e.weights[j] * seen.world_pos[seen.grid_patches[0].vertices[e.corners[j]]];
    const Vec4 c = *opt.viewer_clip * Vec4(p, 1.0);
    const double on = std::min({std::abs(c.w - std::abs(c.x)), std::abs(c.w - std::abs(c.y)), std::abs(c.w - std::abs(c.z))});
    EXPECT_LT(on, 1e-9 * std::abs(c.w)) << c.x << " " << c.y << " " << c.z << " " << c.w;
  }
  const cad::GridPatch& gp = seen.grid_patches[0];
  for (size_t k = 0; k < gp.vertices.size(); ++k) {
    if (seen.in_view[gp.vertices[k]] != 2) continue;
    const Vec2 st = pv.st[0][k];
    EXPECT_TRUE(st.x >= -1e-9 && st.x <= 1 + 1e-9 && st.y >= -1e-9 && st.y <= 1 + 1e-9) << "vertex " << gp.vertices[k];
  }
  // What the rasteriser shows where the view's edge cuts a triangle: (s q, t q, q) interpolated linearly over
  // the triangle. Inside the map, within the interpolation's curvature (1 % of the map).
  for (const PatchView::ViewEdgeSample& e : pv.view_edge) {
    Vec3 stq(0.0);
    for (int j = 0; j < 3; ++j) {
      const size_t k = e.corners[j];
      stq += e.weights[j] * pv.q[k] * Vec3(pv.st[0][k], 1.0);
    }
    const Vec2 st = Vec2(stq) / stq.z;
    EXPECT_TRUE(st.x >= -0.01 && st.x <= 1.01 && st.y >= -0.01 && st.y <= 1.01) << st.x << ", " << st.y;
  }
}

}  // namespace
}  // namespace pvrr
