// Back-face culling of closed convex environment meshes (EnvMesh::closed_convex) rests on three facts, each
// tested here against closed forms: the builders' meshes are closed, convex and wound counter-clockwise seen
// from outside; nearClipCannotOpen tells when near clipping can cut such a solid open; and
// facingTrianglesWindCounterClockwise tells which window-space winding a triangle facing the camera has.
// depthSortedDrawOrder, the renderer's environment draw order, is checked on boxes at known distances.
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "pvrr/scene/scene.h"
#include "pvrr/method/view_volume.h"

namespace pvrr {
namespace {

// Closed: the area vectors of a closed surface sum to zero. Outward: its signed volume is positive. Convex
// and outward: every vertex lies on or behind the plane of every triangle (its counter-clockwise normal).
void expectClosedConvexOutward(const EnvMesh& m, double volume_m3, const std::string& what) {
  ASSERT_TRUE(m.closed_convex) << what;
  Vec3 area_sum(0);
  double volume = 0, scale = 0;
  for (const glm::vec3& p : m.positions) scale = std::max(scale, double(glm::length(p)));
  size_t behind_violations = 0;
  for (const auto& t : m.triangles) {
    const Vec3 a(m.positions[t.x]), b(m.positions[t.y]), c(m.positions[t.z]);
    const Vec3 n = glm::cross(b - a, c - a);
    area_sum += 0.5 * n;
    volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    const double len = glm::length(n);
    if (len < 1e-12) continue;  // none in these meshes; no plane to test against
    for (const glm::vec3& p : m.positions) behind_violations += glm::dot(Vec3(p) - a, n / len) > 1e-5 * scale;
  }
  EXPECT_LT(glm::length(area_sum), 1e-5 * scale * scale) << what << ": not closed";
  EXPECT_NEAR(volume, volume_m3, 2e-3 * volume_m3) << what << ": not wound outward";
  EXPECT_EQ(behind_violations, 0u) << what << ": not convex, or a triangle wound inward";
}

TEST(ClosedConvexMesh, BoxesAndSpheresAreClosedConvexAndWoundOutward) {
  expectClosedConvexOutward(makeBoxMesh(Vec3(1, 2, 3), Vec3(0.5, 2, 4), Mat3(1.0)), 0.5 * 2 * 4, "box");
  const Mat3 turned = Mat3(glm::rotate(Mat4(1.0), 0.7, glm::normalize(Vec3(1, 2, -1))));
  expectClosedConvexOutward(makeBoxMesh(Vec3(-4, 0, 9), Vec3(3, 1, 0.2), turned, 0.5), 3 * 1 * 0.2, "turned box");
  // A sphere mesh of 48 x 24 facets is inscribed: its volume is below 4/3 pi r^3 by ~1.1 %.
  const EnvMesh sphere = makeSphereMesh(Vec3(2, 0, 0), 0.75);
  double volume = 0;
  for (const auto& t : sphere.triangles) {
    const Vec3 a(sphere.positions[t.x]), b(sphere.positions[t.y]), c(sphere.positions[t.z]);
    volume += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  EXPECT_GT(volume, 0.985 * 4.0 / 3.0 * kPi * std::pow(0.75, 3));
  expectClosedConvexOutward(sphere, volume, "sphere");
  // Not solids to cull: inside out (a negative size), sheared axes, too few facets.
  EXPECT_FALSE(makeBoxMesh(Vec3(0), Vec3(1, -1, 1), Mat3(1.0)).closed_convex);
  EXPECT_FALSE(makeBoxMesh(Vec3(0), Vec3(1), Mat3(Vec3(1, 0, 0), Vec3(0.3, 1, 0), Vec3(0, 0, 1))).closed_convex);
  EXPECT_TRUE(makeBoxMesh(Vec3(0), Vec3(1), Mat3(Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1))).closed_convex);
  expectClosedConvexOutward(makeBoxMesh(Vec3(0), Vec3(1, 2, 3), Mat3(Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1))), 6,
                            "mirrored axes");
  EXPECT_FALSE(makeSphereMesh(Vec3(0), 1.0, 2, 24).closed_convex);
  // A quad (a ground, a sign) is two-sided: never culled.
  EXPECT_FALSE(makeQuadMesh(Vec3(0), Vec3(0, 1, 0), Vec3(0, 0, 1), 2, 2).closed_convex);
}

// A camera at the origin looking down -z, near 0.1 m, 90 deg: the near plane's rectangle reaches
// 0.1 * sqrt(1 + 1 + 1) = 0.1732 m from the camera (its corners at (+-0.1, +-0.1, -0.1)).
Mat4 cameraAtOrigin(const Vec3& eye = Vec3(0)) {
  return glm::perspective(kPi / 2, 1.0, 0.1, 100.0) * glm::lookAt(eye, eye + Vec3(0, 0, -1), Vec3(0, 1, 0));
}

TEST(NearClip, CannotOpenBoxesWhollyBeyondTheNearPlaneOrBeyondTheNearRectanglesReach) {
  const NearClip clip(cameraAtOrigin());
  // Wholly beyond the near plane (z < -0.1), even far off to the side.
  EXPECT_TRUE(clip.cannotOpen(Vec3(-1, -1, -3), Vec3(1, 1, -0.11)));
  EXPECT_TRUE(clip.cannotOpen(Vec3(50, -1, -3), Vec3(51, 1, -0.2)));
  // Beyond it by less than the margin (1e-6 of the box's size and place): not counted as beyond, and within
  // the rectangle's reach.
  EXPECT_FALSE(clip.cannotOpen(Vec3(-1, -1, -3), Vec3(1, 1, -0.1 - 1e-9)));
  // Reaching in front of the near plane, but farther from the camera than the rectangle's corners (0.1732).
  EXPECT_TRUE(clip.cannotOpen(Vec3(0.18, -1, -1), Vec3(2, 1, 1)));
  EXPECT_TRUE(clip.cannotOpen(Vec3(-5, -5, 0.2), Vec3(5, 5, 1)));  // wholly behind the camera
  // Within reach of the rectangle, while crossing the near plane: it may be cut open.
  EXPECT_FALSE(clip.cannotOpen(Vec3(0.15, -1, -1), Vec3(2, 1, 1)));
  EXPECT_FALSE(clip.cannotOpen(Vec3(0.05, 0.05, -0.5), Vec3(0.5, 0.5, -0.05)));
  EXPECT_FALSE(clip.cannotOpen(Vec3(0.17, -1, -1), Vec3(2, 1, 1)));  // just inside the reach
  // The camera inside the box (a room): never.
  EXPECT_FALSE(clip.cannotOpen(Vec3(-3, -3, -3), Vec3(3, 3, 3)));
  // An asymmetric frustum looking along another axis, from another place: the reach is that of its own
  // near rectangle (corners at near 0.05 and the frustum's extents).
  const Vec3 eye(1, 2, 3);
  const Mat4 view = glm::lookAt(eye, Vec3(-4, 1, 0), Vec3(0, 1, 0));
  const NearClip oblique(glm::frustum(-0.02, 0.3, 0.1, 0.25, 0.05, 80.0) * view);
  const double reach = glm::length(Vec3(0.3, 0.25, 0.05));
  const Vec3 back = Vec3(glm::inverse(view) * Vec4(0, 0, 1, 0));  // behind the camera
  auto boxAlong = [&](double from, double to) {  // the box around the segment eye + [from, to] back
    const Vec3 a = eye + from * back, b = eye + to * back;
    return std::array<Vec3, 2>{glm::min(a, b) - Vec3(0.005), glm::max(a, b) + Vec3(0.005)};
  };
  const auto out_of_reach = boxAlong(reach + 0.02, reach + 0.5), within = boxAlong(reach - 0.01, reach + 0.5);
  EXPECT_TRUE(oblique.cannotOpen(out_of_reach[0], out_of_reach[1]));
  EXPECT_FALSE(oblique.cannotOpen(within[0], within[1]));
}

TEST(FacingTriangles, WindCounterClockwiseUnlessTheProjectionMirrors) {
  EXPECT_TRUE(facingTrianglesWindCounterClockwise(cameraAtOrigin()));
  EXPECT_TRUE(facingTrianglesWindCounterClockwise(cameraAtOrigin(Vec3(3, -4, 1e5))));
  // An asymmetric frustum looking along another axis.
  const Mat4 oblique = glm::frustum(-0.02, 0.3, 0.1, 0.25, 0.05, 80.0) *
                       glm::lookAt(Vec3(1, 2, 3), Vec3(-4, 1, 0), glm::normalize(Vec3(0.2, 1, 0.1)));
  EXPECT_TRUE(facingTrianglesWindCounterClockwise(oblique));
  // Mirrored images (left and right swapped, or up and down): facing triangles appear clockwise.
  EXPECT_FALSE(facingTrianglesWindCounterClockwise(glm::scale(Mat4(1.0), Vec3(-1, 1, 1)) * cameraAtOrigin()));
  EXPECT_FALSE(facingTrianglesWindCounterClockwise(glm::frustum(0.3, -0.02, 0.1, 0.25, 0.05, 80.0)));
  EXPECT_FALSE(facingTrianglesWindCounterClockwise(glm::frustum(-0.02, 0.3, 0.25, 0.1, 0.05, 80.0)));
  // Both flipped: a half turn, no mirror.
  EXPECT_TRUE(facingTrianglesWindCounterClockwise(glm::frustum(0.3, -0.02, 0.25, 0.1, 0.05, 80.0)));
  // Checked directly: a triangle facing the camera, projected, and its signed area in NDC.
  for (const Mat4& vp : {cameraAtOrigin(), oblique, Mat4(glm::scale(Mat4(1.0), Vec3(-1, 1, 1)) * cameraAtOrigin())}) {
    const Mat4 inv = glm::inverse(vp);
    const Vec4 eye_h = inv * Vec4(0, 0, -1, 1), far_h = inv * Vec4(0, 0, 1, 1);
    const Vec3 on = Vec3(eye_h) / eye_h.w, beyond = Vec3(far_h) / far_h.w;
    const Vec3 dir = glm::normalize(beyond - on), centre = on + 2.0 * dir;
    const Vec3 u = glm::normalize(glm::cross(dir, Vec3(0.3, 1, 0.2))), v = glm::cross(u, dir);
    // Counter-clockwise about -dir (towards the camera): a, a + u, a + v with (u x v) = -dir.
    const Vec3 a = centre, b = centre + 0.1 * u, c = centre + 0.1 * v;
    ASSERT_LT(glm::dot(glm::cross(b - a, c - a), dir), 0);
    auto ndc = [&](const Vec3& p) {
      const Vec4 h = vp * Vec4(p, 1.0);
      return glm::dvec2(h) / h.w;
    };
    const glm::dvec2 pa = ndc(a), pb = ndc(b), pc = ndc(c);
    const double area = (pb.x - pa.x) * (pc.y - pa.y) - (pc.x - pa.x) * (pb.y - pa.y);
    EXPECT_EQ(area > 0, facingTrianglesWindCounterClockwise(vp));
  }
}

// Boxes relative to the centre of projection, at known distances: nearest points 4 (a car), 0.5 (a road
// plane under the eye, flat in y), 1 (a door beside the eye) and |(20, 0, 20)| (a building); a room around
// the eye, whose nearest face is 2 away.
TEST(DepthSortedDrawOrder, NearestFirstOrFarthestFirstWithReversedDepth) {
  const std::vector<std::array<Vec3, 2>> boxes = {
      {Vec3(-1, -1, 4), Vec3(1, 1, 6)},         // 0: car, nearest 4 (z), farthest |(1,1,6)|
      {Vec3(-100, -0.5, -100), Vec3(100, -0.5, 100)},  // 1: road, nearest 0.5, farthest |(100,0.5,100)|
      {Vec3(1, -1, -1), Vec3(1.1, 1, 1)},       // 2: door, nearest 1, farthest |(1.1,1,1)|
      {Vec3(-2, -2, -2), Vec3(2, 3, 2)},        // 3: a room around the eye, nearest face 2
      {Vec3(20, 0, 20), Vec3(30, 10, 40)},      // 4: building, nearest |(20,0,20)|
  };
  EXPECT_EQ(depthSortedDrawOrder(boxes, false), (std::vector<size_t>{1, 2, 3, 0, 4}));
  // Farthest corners: road 141.4, building 50.99, car 6.16, room 4.12, door 1.79.
  EXPECT_EQ(depthSortedDrawOrder(boxes, true), (std::vector<size_t>{1, 4, 0, 3, 2}));
  // Equal keys keep the given order; no boxes, no order.
  const std::vector<std::array<Vec3, 2>> twins = {{Vec3(0, 0, 3), Vec3(1, 1, 4)}, {Vec3(0, 0, 3), Vec3(1, 1, 4)},
                                                   {Vec3(0, 0, 1), Vec3(1, 1, 2)}};
  EXPECT_EQ(depthSortedDrawOrder(twins, false), (std::vector<size_t>{2, 0, 1}));
  EXPECT_EQ(depthSortedDrawOrder(twins, true), (std::vector<size_t>{0, 1, 2}));
  EXPECT_TRUE(depthSortedDrawOrder({}, false).empty());
}

}  // namespace
}  // namespace pvrr
