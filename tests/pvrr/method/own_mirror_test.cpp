// Vertex rays traced beside their own mirror (VertexStageOptions::beside_own_mirror, RayScene::intersectBeside):
// RayScene::tangentClearance against the closed form of spherical caps and a plane, and every vertex ray the
// same, bit for bit, as when traced through the whole scene: shipped mirror scenes, a mirror seen from behind,
// nested-pass origins, grazing views, and a deep concave bowl whose rays meet the bowl again.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "pvrr/trace/ray_scene.h"
#include "pvrr/method/vertex_stage.h"
#include "support/scenes.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// A spherical cap of radius `radius` (> 0 convex, < 0 concave seen from +z) and outline diameter `diameter`,
// facing the eye from the origin, in the test room.
Scene capScene(double radius, double diameter, const Vec3& eye = Vec3(0.3, 0.2, 1.5), int tess = 9) {
  Scene s = test::roomScene(eye, Vec3(0, 0, 0));
  const cad::Outline outline = cad::Outline::circle(diameter);
  test::addMirror(s, std::isfinite(radius) ? cad::makeSphere(radius, outline) : cad::makePlane(outline), outline,
                  test::pose(Vec3(0), Vec3(0, 0, 1)), tess);
  s.updateBounds();
  return s;
}

// For a sphere of radius R, a cap of half-angle alpha (sin alpha = D / 2|R|) and a point at polar angle theta
// from the cap's axis (seen from the centre): a candidate at angle gamma from the point lies at R (cos gamma - 1)
// along the point's normal (the normal points away from the centre for R > 0, towards it for R < 0: then
// |R| (1 - cos gamma)). The farthest candidate is on the rim across the axis: gamma = theta + alpha. Radii of
// 200 m keep it within the cap of 1e-3 of the size (exact values); at 0.5 m it lies beyond (infinite).
TEST(TangentClearance, SphericalCapsAndAPlaneAgainstTheClosedForm) {
  const double diameter = 0.3;
  for (const double radius : {0.5, -0.5, 200.0, -200.0, kInf}) {
    const Scene s = capScene(radius, diameter);
    RayScene rays(s);
    const ElementFrame f = prepareElement(s, 0);
    const auto c = rays.tangentClearance(0, f.grid.positions, f.grid.normals);
    ASSERT_EQ(c->ahead.size(), f.grid.positions.size());
    const double cap = RayScene::kClearanceCap * std::sqrt(2.0) * diameter;  // 1e-3 of the candidates' box diagonal
    for (size_t i = 0; i < f.grid.positions.size(); ++i) {
      const Vec3 p = f.grid.positions[i];
      const std::string where = "R " + std::to_string(radius) + ", vertex " + std::to_string(i);
      if (!std::isfinite(radius)) {  // a plane: every candidate on every tangent plane
        EXPECT_NEAR(c->ahead[i], 0.0, 1e-15) << where;
        EXPECT_NEAR(c->behind[i], 0.0, 1e-15) << where;
        continue;
      }
      const double R = std::abs(radius), alpha = std::asin(0.5 * diameter / R);
      const double rho = std::hypot(p.x, p.y), theta = std::asin(std::min(rho / R, 1.0));
      const double far = R * (1.0 - std::cos(theta + alpha));  // the farthest candidate's distance
      // The candidates nearest the point lie within two of the 96 x 96 grid's spacings.
      const double near = R * (1.0 - std::cos(2.0 * diameter / 95.0 / R));
      // Convex: all candidates behind the tangent plane, the rim across the farthest; concave: ahead.
      const double toward = radius > 0 ? c->ahead[i] : -c->behind[i], away = radius > 0 ? -c->behind[i] : c->ahead[i];
      EXPECT_LE(toward, 1e-12) << where;
      EXPECT_GE(toward, -near) << where;
      if (far > 1.01 * cap) {
        EXPECT_EQ(away, kInf) << where << ": beyond the cap";
      } else if (far < 0.99 * cap) {
        EXPECT_NEAR(away, far, 0.02 * far) << where;
      }
    }
    // The same points again: the kept answer.
    EXPECT_EQ(rays.tangentClearance(0, f.grid.positions, f.grid.normals), c);
  }
  // A point or normal that is not finite is never clear.
  const Scene s = capScene(0.5, diameter);
  RayScene rays(s);
  const auto c = rays.tangentClearance(0, {Vec3(0), Vec3(0, 0, std::nan("")), Vec3(0)},
                                       {Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, std::nan(""), 1)});
  EXPECT_LE(c->ahead[0], c->tolerance);
  for (size_t i : {1, 2}) {
    EXPECT_EQ(c->ahead[i], kInf) << i;
    EXPECT_EQ(c->behind[i], -kInf) << i;
  }
}

// Every vertex ray of element `element` traced beside its mirror equals the whole scene's; returns how many
// were traced beside it.
int expectSameRays(const Scene& s, const RayScene& rays, int element, const Vec3& eye,
                   const std::vector<Vec3>* origins, const std::string& what) {
  ElementFrame whole = prepareElement(s, element), beside = prepareElement(s, element);
  VertexStageOptions off, on;
  off.beside_own_mirror = false;
  if (origins) {
    traceVertexRays(rays, whole, eye, *origins, off);
    traceVertexRays(rays, beside, eye, *origins, on);
  } else {
    traceVertexRays(rays, whole, eye, off);
    traceVertexRays(rays, beside, eye, on);
  }
  EXPECT_EQ(whole.rays_beside, 0) << what;
  size_t differ = 0;
  for (size_t c = 0; c < whole.rays.size(); ++c)
    for (size_t i = 0; i < whole.rays[c].size(); ++i) {
      const VertexRay &a = whole.rays[c][i], &b = beside.rays[c][i];
      differ += a.status != b.status || a.hit != b.hit || a.dir != b.dir || a.origin != b.origin;
    }
  EXPECT_EQ(differ, 0u) << what;
  return beside.rays_beside;
}

TEST(BesideOwnMirror, ShippedMirrorScenesTraceTheSameRays) {
  // Rays traced beside the mirror: every ray of the convex car mirror and of the plane mirror; none of the
  // concave and saddle mirrors, whose candidates lie ahead of their tangent planes.
  const std::pair<const char*, bool> scenes[] = {{"car-mirror", true},   {"plane-mirror", true},
                                                 {"concave-mirror", false}, {"saddle-mirror", false},
                                                 {"mirror-pair", true}};
  for (const auto& [name, all] : scenes) {
    const Scene s = test::shippedScene(name);
    RayScene rays(s);
    for (size_t e = 0; e < s.elements.size(); ++e) {
      const int n = expectSameRays(s, rays, int(e), s.observer.eye, nullptr, std::string(name) + " element " + std::to_string(e));
      const int vertices = s.elements[e].tess_u * s.elements[e].tess_v;
      std::printf("%s element %zu: %d of %d vertex rays traced beside it\n", name, e, n, vertices);
      if (all) EXPECT_GE(n, vertices * 9 / 10) << name;  // the outline may trim the grid
      else EXPECT_EQ(n, 0) << name;
    }
  }
}

TEST(BesideOwnMirror, BacksGrazingViewsAndNestedOriginsTraceTheSameRays) {
  // Seen from behind, a convex mirror is concave: no ray beside it. A concave one is convex there, and a
  // plane is a plane: every ray beside it.
  for (const double radius : {0.5, -0.5, kInf}) {
    const Scene s = capScene(radius, 0.3, Vec3(0.2, 0.1, -1.2));
    RayScene rays(s);
    const int n = expectSameRays(s, rays, 0, s.observer.eye, nullptr, "from behind, R " + std::to_string(radius));
    if (std::isfinite(radius) && radius > 0) EXPECT_EQ(n, 0);
    else EXPECT_EQ(n, s.elements[0].tess_u * s.elements[0].tess_v) << radius;
  }
  // Grazing: the eye almost in the mirror's plane, and every vertex ray from its own origin (a nested pass's
  // viewpoints), some from in front and some from behind. Rays leaving closer than kMinLeave to the tangent
  // plane go through the whole scene: on the plane, exactly those with |d . n| below it.
  for (const double radius : {0.5, 2.0, kInf}) {
    const Scene s = capScene(radius, 0.3, Vec3(0.5, 0.02, 0.004), 21);
    RayScene rays(s);
    const int grazing = expectSameRays(s, rays, 0, s.observer.eye, nullptr, "grazing, R " + std::to_string(radius));
    ElementFrame f = prepareElement(s, 0);
    traceVertexRays(rays, f, s.observer.eye, VertexStageOptions{});
    int leaving = 0;
    for (size_t i = 0; i < f.rays[0].size(); ++i)
      leaving += std::abs(glm::dot(f.rays[0][i].dir, f.world_normal[i])) >= RayScene::kMinLeave;
    EXPECT_GT(leaving, 0) << radius;
    EXPECT_LT(leaving, int(f.rays[0].size())) << radius;
    if (!std::isfinite(radius)) EXPECT_EQ(grazing, leaving);
    else EXPECT_LE(grazing, leaving) << radius;
    std::vector<Vec3> origins(f.world_pos.size());
    for (size_t i = 0; i < origins.size(); ++i)
      origins[i] = Vec3(0.4 * std::sin(double(i)), 0.3 * std::cos(3.0 * double(i)), (i % 3 == 0 ? -1.0 : 1.0));
    expectSameRays(s, rays, 0, s.observer.eye, &origins, "nested origins, R " + std::to_string(radius));
  }
}

// A mirror that moves with the observer (a two-level dynamic scene, RaySceneOptions::moving_elements): after
// updateElementPoses the scene beside it has moved with it, and its rays are the whole scene's.
TEST(BesideOwnMirror, AMovedMirrorTracesTheSameRays) {
  Scene s = capScene(0.5, 0.3);
  s.elements[0].attached_to_observer = true;
  RaySceneOptions options;
  options.moving_elements = true;
  RayScene rays(s, options);
  EXPECT_EQ(expectSameRays(s, rays, 0, s.observer.eye, nullptr, "before the move"), 81);
  s.elements[0].local_to_world = test::pose(Vec3(0.2, -0.1, 0.3), glm::normalize(Vec3(0.3, 0.1, 1)));
  s.elements[0].world_to_local = glm::inverse(s.elements[0].local_to_world);
  rays.updateElementPoses();
  EXPECT_EQ(expectSameRays(s, rays, 0, s.observer.eye, nullptr, "after the move"), 81);
}

// A deep concave bowl (radius 0.2 m, 0.36 m across: 64 deg half-angle) seen from its axis: rays from one side
// cross the axis and meet the bowl again. None is traced beside it, and those hits are the bowl's.
TEST(BesideOwnMirror, RaysThatMeetTheirOwnMirrorAreTracedThroughTheWholeScene) {
  const Scene s = capScene(-0.2, 0.36, Vec3(0.0, 0.01, 0.5), 15);
  RayScene rays(s);
  EXPECT_EQ(expectSameRays(s, rays, 0, s.observer.eye, nullptr, "bowl"), 0);
  ElementFrame f = prepareElement(s, 0);
  traceVertexRays(rays, f, s.observer.eye, VertexStageOptions{});
  const Vec3 centre(0, 0, 0.2);  // the centre of curvature (z_vertex - R)
  int on_bowl = 0;
  for (const VertexRay& r : f.rays[0]) on_bowl += r.status == VertexStatus::Hit && std::abs(glm::length(r.hit - centre) - 0.2) < 1e-9;
  EXPECT_GT(on_bowl, 0);
}

}  // namespace
}  // namespace pvrr
