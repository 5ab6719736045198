// View volume of the reflection map: containment of hits and segments, clipping of the mirror, frame and
// matrices (against glm::frustum and the direct projection), asymmetry, up hint, the zooming region and its
// reversed volume.
#include "pvrr/method/view_volume.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "pvrr/base/error.h"

namespace pvrr {
namespace {

// Round-off of products of O(1) doubles through a few matrix operations.
constexpr double kRounding = 1e-12;

Vec3 reflect(const Vec3& i, const Vec3& n) { return i - 2.0 * glm::dot(i, n) * n; }
double hitDistance(int k, double t0, double t1) { return t0 + (t1 - t0) * std::fmod(0.618034 * (k + 1), 1.0); }

// Spherical cap (apex at the origin, axis +z towards the eye side); convex or concave; hits at [t0, t1].
std::vector<ViewpointRay> sphereMirror(const Vec3& eye, double radius_m, bool convex, double half_size_m, int grid,
                                       double t0, double t1) {
  const Vec3 axis(0, 0, 1);
  const Vec3 centre = convex ? -radius_m * axis : radius_m * axis;
  std::vector<ViewpointRay> rays;
  for (int i = 0; i < grid; ++i)
    for (int j = 0; j < grid; ++j) {
      const Vec3 q(half_size_m * (2.0 * i / (grid - 1) - 1), 0.6 * half_size_m * (2.0 * j / (grid - 1) - 1), 0.0);
      const Vec3 radial = glm::normalize(q - centre);
      const Vec3 o = centre + radius_m * radial;
      const Vec3 d = reflect(glm::normalize(o - eye), convex ? radial : -radial);
      rays.push_back({o, d, o + hitDistance(int(rays.size()), t0, t1) * d});
    }
  return rays;
}

double depth(const ViewVolume& vv, const Vec3& p) { return glm::dot(p - vv.eye, vv.forward); }

bool inUnitSquare(const Vec2& st, double tol = kRounding) {
  return st.x >= -tol && st.x <= 1 + tol && st.y >= -tol && st.y <= 1 + tol;
}

void expectOrthonormalFrame(const ViewVolume& vv) {
  EXPECT_NEAR(glm::length(vv.forward), 1.0, kRounding);
  EXPECT_NEAR(glm::length(vv.up), 1.0, kRounding);
  EXPECT_NEAR(glm::length(vv.right), 1.0, kRounding);
  EXPECT_NEAR(glm::dot(vv.up, vv.forward), 0.0, kRounding);
  EXPECT_NEAR(glm::dot(vv.right, vv.forward), 0.0, kRounding);
  EXPECT_NEAR(glm::length(vv.right - glm::cross(vv.forward, vv.up)), 0.0, kRounding);
}

Vec3 meanDirection(const std::vector<ViewpointRay>& rays) {
  Vec3 m(0);
  for (const auto& r : rays) m += r.direction;
  return glm::normalize(m);
}

TEST(ViewVolume, ConvexMirrorVolumeContainsEveryHitAndSegmentAndClipsTheMirror) {
  const Vec3 eye(0.25, 0.1, 1.0);
  const auto rays = sphereMirror(eye, 1.2, true, 0.1, 9, 1.0, 25.0);
  const ViewpointFit fit = fitViewpoint(rays);
  ASSERT_TRUE(fit.accepted);
  ViewVolumeOptions opt;
  const ViewVolume vv = buildViewVolume(fit.eye, rays, opt);
  EXPECT_EQ(vv.note, "");
  EXPECT_FALSE(vv.reversed);
  EXPECT_FALSE(vv.backward);
  EXPECT_TRUE(vv.zooming.empty());
  EXPECT_EQ(vv.hits_covered, int(rays.size()));
  EXPECT_EQ(vv.hits_outside, 0);
  EXPECT_EQ(vv.mirror_vertices_unclipped, 0);
  expectOrthonormalFrame(vv);
  EXPECT_NEAR(glm::length(vv.forward - meanDirection(rays)), 0.0, kRounding);  // paper 3.3
  EXPECT_GT(vv.near_m, 0.0);
  EXPECT_LT(vv.near_m, vv.far_m);

  double s_min = kInf, s_max = -kInf, t_min = kInf, t_max = -kInf;
  for (const auto& r : rays) {
    EXPECT_LT(depth(vv, r.origin), vv.near_m) << "mirror vertex not clipped by the near plane";
    EXPECT_GT(depth(vv, r.hit), vv.near_m);
    EXPECT_LT(depth(vv, r.hit), vv.far_m);
    EXPECT_TRUE(inUnitSquare(projectToTexture(vv, r.hit)));
    // Every point of the reflection segment between near and far is inside the frustum.
    for (int k = 0; k <= 200; ++k) {
      const Vec3 p = r.origin + (k / 200.0) * (r.hit - r.origin);
      const double z = depth(vv, p);
      if (z < vv.near_m || z > vv.far_m) continue;
      const Vec2 st = projectToTexture(vv, p);
      EXPECT_TRUE(inUnitSquare(st)) << st.x << " " << st.y;
      s_min = std::min(s_min, st.x), s_max = std::max(s_max, st.x);
      t_min = std::min(t_min, st.y), t_max = std::max(t_max, st.y);
    }
  }
  // The box is tight up to the margin: the extreme samples sit margin / (1 + 2 margin) from the edges
  // (sampling 200 steps per segment can miss the exact end points only by the clipping; 1e-3 of the map).
  constexpr double kSampling = 1e-3;
  const double edge = opt.margin / (1 + 2 * opt.margin);
  EXPECT_NEAR(s_min, edge, kSampling);
  EXPECT_NEAR(1 - s_max, edge, kSampling);
  EXPECT_NEAR(t_min, edge, kSampling);
  EXPECT_NEAR(1 - t_max, edge, kSampling);
}

TEST(ViewVolume, MatricesReproduceProjectToTextureAndGlmFrustum) {
  const Vec3 eye(0.25, 0.1, 1.0);
  const auto rays = sphereMirror(eye, 0.8, true, 0.1, 7, 1.0, 10.0);
  const ViewVolume vv = buildViewVolume(fitViewpoint(rays).eye, rays);
  const Mat4 ref = glm::frustum(vv.left, vv.right_, vv.bottom, vv.top, vv.near_m, vv.far_m);
  const Mat4 look = glm::lookAt(vv.eye, vv.eye + vv.forward, vv.up);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      EXPECT_NEAR(vv.projection[c][r], ref[c][r], kRounding * std::max(1.0, std::abs(ref[c][r])));
      EXPECT_NEAR(vv.view[c][r], look[c][r], kRounding * std::max(1.0, std::abs(look[c][r])));
    }
  const auto rm = rowMajor16(vv.projection);
  EXPECT_EQ(rm[2], vv.projection[2][0]);   // row 0, column 2: the asymmetry term (r + l) / (r - l)
  EXPECT_EQ(rm[11], vv.projection[3][2]);  // row 2, column 3
  EXPECT_EQ(rm[14], -1.0);                 // row 3, column 2: w = -z_eye

  for (const auto& r : rays) {
    for (const Vec3& p : {r.hit, 0.5 * (r.origin + r.hit)}) {
      const Vec4 clip = vv.projection * vv.view * Vec4(p, 1.0);
      const Vec3 ndc = Vec3(clip) / clip.w;
      const Vec2 st = projectToTexture(vv, p);
      EXPECT_NEAR(st.x, 0.5 * (ndc.x + 1), kRounding);
      EXPECT_NEAR(st.y, 0.5 * (ndc.y + 1), kRounding);
      const Vec4 rel = vv.view_relative * Vec4(p - vv.eye, 1.0);
      const Vec4 abs = vv.view * Vec4(p, 1.0);
      EXPECT_NEAR(glm::length(Vec3(rel) - Vec3(abs)), 0.0, kRounding);
      EXPECT_NEAR(-abs.z, depth(vv, p), kRounding);  // camera looks down -z
      const Vec2 texel = projectToTexel(vv, p, 1024, 512);
      EXPECT_NEAR(texel.x, st.x * 1024, kRounding * 1024);
      EXPECT_NEAR(texel.y, st.y * 512, kRounding * 512);
    }
  }
  // Depth range: the near plane maps to NDC z = -1, the far plane to +1.
  for (const auto& [z, expected] : {std::pair{vv.near_m, -1.0}, std::pair{vv.far_m, 1.0}}) {
    const Vec4 clip = vv.projection * vv.view * Vec4(vv.eye + z * vv.forward, 1.0);
    EXPECT_NEAR(clip.z / clip.w, expected, 1e-9);
  }
  EXPECT_TRUE(std::isnan(projectToTexture(vv, vv.eye - vv.forward).x));  // behind the eye
}

// Rays through the eye at the origin: direction normalize(tan ax, tan ay, 1), origin 0.5 m and hit 5 m out.
std::vector<ViewpointRay> fan(const std::vector<double>& ax_deg, const std::vector<double>& ay_deg) {
  std::vector<ViewpointRay> rays;
  for (double ax : ax_deg)
    for (double ay : ay_deg) {
      const Vec3 d = glm::normalize(Vec3(std::tan(radians(ax)), std::tan(radians(ay)), 1.0));
      rays.push_back({0.5 * d, d, 5.0 * d});
    }
  return rays;
}

TEST(ViewVolume, FrustumIsAsymmetricWhenTheRaysAre) {
  ViewVolumeOptions opt;
  opt.margin = 0;
  // Symmetric fan: the frustum is symmetric.
  const ViewVolume sym = buildViewVolume(Vec3(0), fan({-10, -5, 0, 5, 10}, {-4, 4}), opt);
  EXPECT_NEAR(sym.left, -sym.right_, kRounding);
  EXPECT_NEAR(sym.bottom, -sym.top, kRounding);
  // Eight rays between +1 and +2 deg and two at -20 deg: the mean direction leans to +; the extremes do not.
  const ViewVolume asym = buildViewVolume(Vec3(0), fan({-20, 1, 1.5, 1.75, 2}, {-3, 3}), opt);
  expectOrthonormalFrame(asym);
  EXPECT_GT(std::abs(asym.left + asym.right_), 0.3 * (asym.right_ - asym.left));
  // Rays through the eye, margin 0: the horizontal field is exactly the extreme angles' difference (the
  // fan lies in planes through the y axis, which is up, so the x angle is preserved).
  EXPECT_NEAR(asym.fov_x_rad, radians(22.0), kRounding);
  // The frustum's axis is the mean direction: the two sides sit at the extremes' angles from it.
  const double phi = std::atan2(asym.forward.x, asym.forward.z);  // mean direction's angle about y
  const double a = std::atan(asym.left / asym.near_m), b = std::atan(asym.right_ / asym.near_m);
  // right = forward x up points to -x here, so the +2 deg ray is at the left edge.
  EXPECT_NEAR(a, -(radians(2.0) - phi), kRounding);
  EXPECT_NEAR(b, phi - radians(-20.0), kRounding);
}

// Square texels on the near plane: a symmetric fan of +-30 deg across and +-10 deg up has extents in the ratio
// tan 30 / tan 10 = 3.274; the longer side keeps the requested texels, the shorter one its share, rounded up.
TEST(ViewVolume, MapTexelsAreSquareOnTheNearPlane) {
  ViewVolumeOptions opt;
  opt.margin = 0;
  const ViewVolume wide = buildViewVolume(Vec3(0), fan({-30, 0, 30}, {-10, 10}), opt);
  const double ratio = std::tan(radians(30.0)) / std::tan(radians(10.0));
  ASSERT_NEAR((wide.right_ - wide.left) / (wide.top - wide.bottom), ratio, 1e-9);
  const std::array<int, 2> t = mapTexels(wide, 1024);
  EXPECT_EQ(t[0], 1024);
  EXPECT_EQ(t[1], int(std::ceil(1024 / ratio)));  // 313
  // The texel's size on the near plane is the same across and up (within the rounding of one texel).
  const double across = (wide.right_ - wide.left) / t[0], up = (wide.top - wide.bottom) / t[1];
  EXPECT_LE(up, across);
  EXPECT_GT(up, across * (1.0 - 1.0 / t[1]));
  // Taller than wide: the roles swap.
  const ViewVolume tall = buildViewVolume(Vec3(0), fan({-10, 10}, {-30, 0, 30}), opt);
  const std::array<int, 2> u = mapTexels(tall, 512);
  EXPECT_EQ(u[1], 512);
  EXPECT_EQ(u[0], int(std::ceil(512 / ratio)));
  // A square frustum keeps a square map; a sliver never goes below 16 texels (or the map itself).
  EXPECT_EQ(mapTexels(buildViewVolume(Vec3(0), fan({-5, 5}, {-5, 5}), opt), 256), (std::array<int, 2>{256, 256}));
  const ViewVolume sliver = buildViewVolume(Vec3(0), fan({-40, 40}, {-0.01, 0.01}), opt);
  EXPECT_EQ(mapTexels(sliver, 1024)[1], 16);
  EXPECT_EQ(mapTexels(sliver, 8)[1], 8);
}

// The map side for a patch's pixels: texels_per_pixel * pixels texels at square texels, rounded up to 32,
// within [min(max, 128), max]; 0 texels per pixel: max.
TEST(ViewVolume, MapSideForPixels) {
  ViewVolumeOptions opt;
  opt.margin = 0;
  const ViewVolume square = buildViewVolume(Vec3(0), fan({-5, 5}, {-5, 5}), opt);
  EXPECT_EQ(mapSideForPixels(square, 10000, 4, 1024), 224);  // sqrt(40000) = 200 -> 224
  EXPECT_EQ(mapSideForPixels(square, 1e7, 4, 1024), 1024);
  EXPECT_EQ(mapSideForPixels(square, 10, 4, 1024), 128);
  EXPECT_EQ(mapSideForPixels(square, 10, 4, 100), 100);
  EXPECT_EQ(mapSideForPixels(square, 10000, 0, 1024), 1024);
  // A 3.274 : 1 frustum: the longer side grows by sqrt(3.274) so that the texels stay 4 per pixel.
  const ViewVolume wide = buildViewVolume(Vec3(0), fan({-30, 0, 30}, {-10, 10}), opt);
  const int side = mapSideForPixels(wide, 10000, 4, 1024);
  EXPECT_EQ(side, 32 * int(std::ceil(std::sqrt(40000 * std::tan(radians(30.0)) / std::tan(radians(10.0))) / 32)));
  const std::array<int, 2> t = mapTexels(wide, side);
  EXPECT_GE(double(t[0]) * t[1], 40000);
}

// Map reuse: a widened volume turns each side out by the margin (angles from forward), keeps eye, frame and
// near, pushes far out, and contains the view turned by less than the margin about the eye, not by more.
TEST(ViewVolume, WidenedVolumeContainsTheViewTurnedByLessThanTheMargin) {
  ViewVolumeOptions opt;
  opt.margin = 0;
  const ViewVolume v = buildViewVolume(Vec3(0), fan({-30, 0, 30}, {-10, 10}), opt);
  const ViewVolume w = widenViewVolume(v, radians(2.0));
  EXPECT_NEAR(degrees(std::atan(w.left / w.near_m)), -32.0, 1e-9);
  EXPECT_NEAR(degrees(std::atan(w.right_ / w.near_m)), 32.0, 1e-9);
  EXPECT_NEAR(degrees(std::atan(w.bottom / w.near_m)), -12.0, 1e-9);
  EXPECT_NEAR(degrees(std::atan(w.top / w.near_m)), 12.0, 1e-9);
  EXPECT_NEAR(w.fov_x_rad, radians(64.0), 1e-12);
  EXPECT_EQ(w.near_m, v.near_m);
  EXPECT_NEAR(w.far_m, 1.1 * v.far_m, kRounding);
  EXPECT_EQ(w.eye, v.eye);
  EXPECT_EQ(w.forward, v.forward);
  EXPECT_TRUE(frustumContains(w, v));
  EXPECT_FALSE(frustumContains(v, w));
  // The same view turned about the vertical through the eye: its right side lies at 30 + angle deg.
  auto turned = [&](double deg) {
    std::vector<ViewpointRay> rays = fan({-30, 0, 30}, {-10, 10});
    const Mat4 r = glm::rotate(Mat4(1.0), radians(deg), Vec3(0, 1, 0));
    for (ViewpointRay& ray : rays) {
      ray.origin = Vec3(r * Vec4(ray.origin, 1.0));
      ray.direction = Vec3(r * Vec4(ray.direction, 0.0));
      ray.hit = Vec3(r * Vec4(ray.hit, 1.0));
    }
    return buildViewVolume(Vec3(0), rays, opt);
  };
  EXPECT_TRUE(frustumContains(w, turned(1.9)));
  EXPECT_TRUE(frustumContains(w, turned(-1.9)));
  EXPECT_FALSE(frustumContains(w, turned(2.1)));
  EXPECT_FALSE(frustumContains(w, turned(-2.1)));
  // A side at the field-of-view limit stays there.
  const ViewVolume limited = widenViewVolume(v, radians(2.0), radians(62.0));
  EXPECT_NEAR(degrees(std::atan(limited.right_ / limited.near_m)), 31.0, 1e-9);
  EXPECT_NEAR(degrees(std::atan(limited.top / limited.near_m)), 12.0, 1e-9);
  // A reversed volume is not widened (its far plane clips the mirror).
  ViewVolume backward = v;
  backward.backward = true;
  EXPECT_EQ(widenViewVolume(backward, radians(2.0)).right_, v.right_);
}

// Texel angles: a 90 x 90 deg frustum of 100 x 100 texels has texels of 0.02 in tangent; at its corner
// (tan^2 = 2 from the axis) one spans 0.02 / 3 rad.
TEST(ViewVolume, MinTexelAngleAtTheFrustumCorner) {
  ViewVolumeOptions opt;
  opt.margin = 0;
  const ViewVolume v = buildViewVolume(Vec3(0), fan({-45, 45}, {-45, 45}), opt);
  EXPECT_NEAR(longerExtentTan(v), 2.0, 1e-9);
  EXPECT_NEAR(minTexelAngle(v, 100), 0.02 / 3, 1e-9);
  const ViewVolume wide = buildViewVolume(Vec3(0), fan({-30, 0, 30}, {-10, 10}), opt);
  const double t30 = std::tan(radians(30.0)), t10 = std::tan(radians(10.0));
  EXPECT_NEAR(longerExtentTan(wide), 2 * t30, 1e-9);
  EXPECT_NEAR(minTexelAngle(wide, 1000), 2 * t30 / 1000 / (1 + t30 * t30 + t10 * t10), 1e-12);
}

TEST(ViewVolume, UpHintIsHonoured) {
  const Vec3 eye(0.25, 0.1, 1.0);
  const auto rays = sphereMirror(eye, 1.2, true, 0.1, 7, 1.0, 25.0);
  const Vec3 e = fitViewpoint(rays).eye;
  ViewVolumeOptions opt;
  opt.up_hint = Vec3(1.0, 0.3, 0.2);  // e.g. a principal curvature direction
  const ViewVolume vv = buildViewVolume(e, rays, opt);
  expectOrthonormalFrame(vv);
  const Vec3 h = glm::normalize(*opt.up_hint);
  const Vec3 expected = glm::normalize(h - glm::dot(h, vv.forward) * vv.forward);
  EXPECT_NEAR(glm::length(vv.up - expected), 0.0, kRounding);
  for (const auto& r : rays) EXPECT_TRUE(inUnitSquare(projectToTexture(vv, r.hit)));

  // No hint: world up projected.
  const ViewVolume plain = buildViewVolume(e, rays);
  const Vec3 w = plain.forward;
  const Vec3 world = ViewVolumeOptions{}.world_up;
  EXPECT_NEAR(glm::length(plain.up - glm::normalize(world - glm::dot(world, w) * w)), 0.0, kRounding);

  // A hint along forward is unusable: world up is used and the note says so.
  opt.up_hint = plain.forward;
  const ViewVolume fallback = buildViewVolume(e, rays, opt);
  EXPECT_NEAR(glm::length(fallback.up - plain.up), 0.0, kRounding);
  EXPECT_NE(fallback.note.find("up hint"), std::string::npos);
}

TEST(ViewVolume, HitNearerThanTheMirrorIsKeptAndReported) {
  // A steeply tilted mirror: origins from 1.0 to 1.5 m deep; one hit lands at 1.2 m.
  std::vector<ViewpointRay> rays;
  for (int i = 0; i < 5; ++i) {
    const Vec3 o(0.1 * i - 0.2, 0.0, 1.0 + 0.125 * i);
    const Vec3 d = glm::normalize(o);  // rays from an eye at the origin
    rays.push_back({o, d, o + 4.0 * d});
  }
  rays.push_back({Vec3(0, 0.05, 1.0), glm::normalize(Vec3(0, 0.05, 1.0)), Vec3(0, 0.06, 1.2)});
  const ViewVolume vv = buildViewVolume(Vec3(0), rays);
  EXPECT_NE(vv.note, "");
  EXPECT_GT(vv.mirror_vertices_unclipped, 0);
  EXPECT_LT(vv.near_m, 1.2);
  for (const auto& r : rays) EXPECT_TRUE(inUnitSquare(projectToTexture(vv, r.hit)));
  EXPECT_EQ(vv.hits_outside, 0);
}

TEST(ViewVolume, ConcaveMirrorZoomingRegionGetsAReversedVolume) {
  // Concave R = 1 m, eye 3 m out: the rays cross ~0.6 m in front of the mirror. Every third hit at 0.3 m
  // lies before the crossing, i.e. behind the fitted viewpoint (objects inside the focal region).
  auto rays = sphereMirror(Vec3(0.02, 0.01, 3.0), 1.0, false, 0.05, 9, 2.0, 4.0);
  std::vector<int> expected;
  for (size_t k = 0; k < rays.size(); k += 3) {
    rays[k].hit = rays[k].origin + 0.3 * rays[k].direction;
    expected.push_back(int(k));
  }
  const ViewpointFit fit = fitViewpoint(rays);
  ASSERT_TRUE(fit.accepted) << fit.solver_report;
  ASSERT_GT(fit.eye.z, 0.3);  // in front of the mirror: the "reversed region" of paper Fig. 8b
  const ViewVolume front = buildViewVolume(fit.eye, rays);
  EXPECT_TRUE(front.reversed);
  EXPECT_EQ(front.zooming, expected);
  EXPECT_EQ(front.hits_covered, int(rays.size() - expected.size()));
  EXPECT_NE(front.note.find("behind the eye"), std::string::npos);
  EXPECT_EQ(front.hits_outside, 0);
  for (size_t k = 0; k < rays.size(); ++k) {
    EXPECT_LT(depth(front, rays[k].origin), front.near_m);  // the mirror lies behind the eye: clipped
    if (k % 3) {
      EXPECT_TRUE(inUnitSquare(projectToTexture(front, rays[k].hit)));
    }
  }

  const ViewVolume back = buildReversedViewVolume(fit.eye, rays);
  EXPECT_TRUE(back.backward);
  EXPECT_EQ(back.zooming, expected);
  EXPECT_EQ(back.hits_covered, int(expected.size()));
  EXPECT_EQ(back.hits_outside, 0);
  EXPECT_EQ(back.mirror_vertices_unclipped, 0);
  EXPECT_NE(back.note.find("GL_GREATER"), std::string::npos);
  expectOrthonormalFrame(back);
  Vec3 mean(0);
  for (int k : expected) mean += rays[size_t(k)].direction;
  EXPECT_NEAR(glm::length(back.forward + glm::normalize(mean)), 0.0, kRounding);
  for (const auto& r : rays) EXPECT_GT(depth(back, r.origin), back.far_m) << "mirror must lie beyond far'";
  for (int k : expected) {
    const ViewpointRay& r = rays[size_t(k)];
    EXPECT_GT(depth(back, r.hit), back.near_m);
    EXPECT_LT(depth(back, r.hit), back.far_m);
    EXPECT_TRUE(inUnitSquare(projectToTexture(back, r.hit)));
    // Each zooming ray travels towards the eye in the backward view (depth' decreases along it), so its
    // first hit is the farthest surface point on its line of sight: hence GL_GREATER with clear depth 0.
    EXPECT_LT(glm::dot(r.direction, back.forward), 0.0);
  }
}

TEST(ViewVolume, FieldOfViewIsLimitedAndOverflowReported) {
  ViewVolumeOptions opt;
  opt.max_fov_rad = radians(120);
  const ViewVolume vv = buildViewVolume(Vec3(0), fan({-80, -40, 0, 40, 80}, {-5, 5}), opt);
  EXPECT_LE(vv.fov_x_rad, opt.max_fov_rad + kRounding);
  EXPECT_EQ(vv.hits_outside, 4);  // the four rays at +-80 deg lie beyond +-60 deg
  EXPECT_NE(vv.note.find("max_fov"), std::string::npos);
}

TEST(ViewVolume, FarPlaneReachesTheSceneBounds) {
  ViewVolumeOptions opt;
  opt.scene_center = Vec3(0, 0, 30);
  opt.scene_radius_m = 10;
  const ViewVolume vv = buildViewVolume(Vec3(0), fan({-10, 10}, {-10, 10}), opt);
  EXPECT_GE(vv.far_m, 40.0);
}

TEST(ViewVolume, RejectsUnusableInput) {
  EXPECT_THROW(buildViewVolume(Vec3(0), {}), Error);
  // Opposite directions cancel: no single frustum.
  const std::vector<ViewpointRay> opposite = {{Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 2)},
                                              {Vec3(0, 0, -1), Vec3(0, 0, -1), Vec3(0, 0, -2)}};
  EXPECT_THROW(buildViewVolume(Vec3(0), opposite), Error);
  // No zooming hit: no reversed volume.
  EXPECT_THROW(buildReversedViewVolume(Vec3(0), fan({-10, 10}, {0})), Error);
}

}  // namespace
}  // namespace pvrr
