// Ambient occlusion from displacement fields (pvrr/method/ao_field.h) against closed forms and against the
// reference's hemisphere sampling (pvrr/trace/ambient_occlusion.h), issue 24's "done when": the fields'
// visibility on the ground around a car agrees with the reference's within 0.05 mean absolute difference.
//
// Closed forms: a sphere of radius r whose centre lies at distance D from a point, wholly above the point's
// horizon, at angle beta from its normal, hides the cosine-weighted fraction (r / D)^2 cos(beta) of the
// hemisphere (the form factor of a differential area to a sphere): A = 1 - (r/D)^2 cos(beta).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "pvrr/method/ao_field.h"
#include "pvrr/trace/ambient_occlusion.h"
#include "pvrr/trace/ray_scene.h"
#include "support/ao_scenes.h"

namespace pvrr {
namespace {

// The sampling maps invert to rounding.
constexpr double kMapTol = 1e-12;
// The reference with 1024 stratified rays against a closed form: the stratified estimate's error of a smooth
// cap boundary is well under 1 %.
constexpr double kReferenceTol = 0.01;
// A field against a closed form: positional (64^2) and directional (16^2) quantisation move the silhouette
// by a fraction of a texel; 16 cone samples.
constexpr double kFieldTol = 0.03;
// Issue 24: fields against the reference on the ground around a car, mean absolute difference.
constexpr double kGroundMad = 0.05;

// Adds a mesh as object `object`; `occluder`: its EnvMesh::occluder (-1: it does not occlude).
TEST(AoFieldTest, SamplingMapsInvert) {
  for (double a = -0.95; a <= 0.95; a += 0.1)
    for (double b = -0.95; b <= 0.95; b += 0.1) {
      const Vec2 back = concentricSquare(concentricDisk(Vec2(a, b)));
      EXPECT_NEAR(back.x, a, kMapTol);
      EXPECT_NEAR(back.y, b, kMapTol);
      const Vec2 uv((a + 1) / 2, (b + 1) / 2);
      const Vec2 uv_back = octEncode(octDecode(uv));
      EXPECT_NEAR(uv_back.x, uv.x, kMapTol);
      EXPECT_NEAR(uv_back.y, uv.y, kMapTol);
    }
  Vec3 t, b;
  for (const Vec3 n : {Vec3(0, 0, 1), Vec3(0, 0, -1), glm::normalize(Vec3(1, -2, 0.3))}) {
    basisAround(n, t, b);
    EXPECT_NEAR(glm::dot(t, n), 0, kMapTol);
    EXPECT_NEAR(glm::dot(b, n), 0, kMapTol);
    EXPECT_NEAR(glm::dot(t, b), 0, kMapTol);
    EXPECT_NEAR(glm::length(t), 1, kMapTol);
  }
}

TEST(AoFieldTest, SphereMatchesTheFormFactor) {
  Scene s = test::aoBaseScene();
  const double r = 0.5;
  test::addAoObject(s, makeSphereMesh(Vec3(0), r, 192, 96), 0, 0);
  s.updateBounds();
  const RayScene rays(s);
  const AoField f = buildAoField(s, 0, 64, 16);
  ASSERT_EQ(f.bytes(), size_t(64 * 16) * size_t(64 * 16));
  // The tessellated sphere is a little smaller than r: its silhouette at distance D differs by O(r / 96^2).
  for (const double dist : {1.25, 2.0, 4.0})
    for (const double beta_deg : {0.0, 30.0, 50.0}) {
      const double beta = beta_deg * kPi / 180;
      const Vec3 x(0, 0, dist);
      const Vec3 n(std::sin(beta), 0, -std::cos(beta));  // beta from the direction to the centre
      const double exact = 1 - (r / dist) * (r / dist) * std::cos(beta);
      EXPECT_NEAR(referenceAmbientVisibility(rays, x, n, -1, 1024), exact, kReferenceTol) << dist << " " << beta_deg;
      EXPECT_NEAR(fieldVisibility({f}, s, x, n, -1, 16), exact, kFieldTol) << dist << " " << beta_deg;
    }
  // The receiver's own occluder does not occlude it.
  EXPECT_EQ(fieldVisibility({f}, s, Vec3(0, 0, 1), Vec3(0, 0, -1), 0, 16), 1.0);
}

TEST(AoFieldTest, PointUnderASquareMatchesTheFormFactor) {
  // A 2 m square slab 1 m above the point, parallel, centred: four rectangles a = b = h with the point under
  // a corner, each F = (1 / 2 pi) (2 X / sqrt(1 + X^2) atan(X / sqrt(1 + X^2))), X = a / h (the form factor of
  // a differential area to a parallel rectangle). A = 1 - 4 F.
  Scene s = test::aoBaseScene();
  const double h = 1.0, half = 1.0, thick = 0.01;
  test::addAoObject(s, makeBoxMesh(Vec3(0, h + thick / 2, 0), Vec3(2 * half, thick, 2 * half), Mat3(1.0)), 0, 0);
  s.updateBounds();
  const RayScene rays(s);
  const AoField f = buildAoField(s, 0, 64, 16);
  const double x = half / h, q = x / std::sqrt(1 + x * x);
  const double exact = 1 - 4 * (1 / (2 * kPi)) * 2 * q * std::atan(q);
  EXPECT_NEAR(referenceAmbientVisibility(rays, Vec3(0), Vec3(0, 1, 0), -1, 1024), exact, kReferenceTol);
  EXPECT_NEAR(fieldVisibility({f}, s, Vec3(0), Vec3(0, 1, 0), -1, 64), exact, kFieldTol);
  // Above the slab, facing up: nothing occludes.
  EXPECT_NEAR(fieldVisibility({f}, s, Vec3(0, h + 0.5, 0), Vec3(0, 1, 0), -1, 64), 1.0, kFieldTol);
  EXPECT_EQ(referenceAmbientVisibility(rays, Vec3(0, h + 0.5, 0), Vec3(0, 1, 0), -1, 256), 1.0);
}

// Mean |A_field - A_reference| over ground points within 7 m of the car's centre (a 0.5 m grid, points under
// the body included, points inside a wheel's footprint left out), and the largest; likewise for the occlusion
// volume (volume_mad) and the ground map at the ground's height (ground_mad, what the raster modes shade).
void groundDifference(const Mat4& motion, double& mad, double& worst, double& darkest, double& volume_mad,
                      double& ground_mad) {
  const Scene s = test::boxCarScene(motion);
  const RayScene rays(s);
  const std::vector<AoField> fields = buildAoFields(s);
  ASSERT_EQ(fields.size(), 1u);
  const std::vector<uint8_t> ground = groundMap(fields[0], 0.0);
  double sum = 0, volume_sum = 0, ground_sum = 0;
  int count = 0;
  worst = 0;
  darkest = 1;
  for (double gx = -7; gx <= 7; gx += 0.5)
    for (double gz = -7; gz <= 7; gz += 0.5) {
      if (gx * gx + gz * gz > 49) continue;
      const Vec3 local(gx + 0.13, 0, gz + 0.07);  // off the wheel edges' symmetric grid
      bool in_wheel = false;
      for (const double wx : {-1.4, 1.4})
        for (const double wz : {-0.8, 0.8}) in_wheel |= std::abs(local.x - wx) < 0.35 && std::abs(local.z - wz) < 0.14;
      if (in_wheel) continue;
      const Vec3 x(motion * Vec4(local, 1.0));
      const Vec3 n(0, 1, 0);
      const double a_ref = referenceAmbientVisibility(rays, x, n, -1, 256);
      const double a_field = fieldVisibility(fields, s, x, n, -1, 16);
      volume_sum += std::abs(volumeVisibility(fields, s, x, n, -1) - a_ref);
      ground_sum += std::abs(std::max(0.0, 1 - groundMapOcclusion(fields[0], ground, motion, x)) - a_ref);
      sum += std::abs(a_field - a_ref);
      worst = std::max(worst, std::abs(a_field - a_ref));
      darkest = std::min(darkest, a_ref);
      ++count;
    }
  mad = sum / count;
  volume_mad = volume_sum / count;
  ground_mad = ground_sum / count;
}

TEST(AoFieldTest, GroundAroundACarAgreesWithTheReference) {
  double mad = 0, worst = 0, darkest = 1, volume_mad = 0, ground_mad = 0;
  groundDifference(Mat4(1.0), mad, worst, darkest, volume_mad, ground_mad);
  EXPECT_LT(darkest, 0.3);  // the test means something: under the car the ground is dark
  EXPECT_LT(mad, kGroundMad) << "worst " << worst;
  EXPECT_LT(volume_mad, kGroundMad);
  EXPECT_LT(ground_mad, kGroundMad);
  std::printf("ground around a car: mean |A_field - A_ref| %.4f (worst %.4f), |A_volume - A_ref| %.4f, "
              "|A_ground_map - A_ref| %.4f\n", mad, worst, volume_mad, ground_mad);
}

TEST(AoFieldTest, TheFieldMovesWithItsObject) {
  // Turned 35 degrees about y and moved 12 m: the field, built in the placed pose, follows.
  const Mat4 motion = glm::rotate(glm::translate(Mat4(1.0), Vec3(12, 0, -5)), radians(35), Vec3(0, 1, 0));
  double mad = 0, worst = 0, darkest = 1, volume_mad = 0, ground_mad = 0;
  groundDifference(motion, mad, worst, darkest, volume_mad, ground_mad);
  EXPECT_LT(darkest, 0.3);
  EXPECT_LT(mad, kGroundMad) << "worst " << worst;
  EXPECT_LT(volume_mad, kGroundMad);
  EXPECT_LT(ground_mad, kGroundMad);
  std::printf("moved car: mean |A_field - A_ref| %.4f, |A_volume - A_ref| %.4f, |A_ground_map - A_ref| %.4f\n", mad,
              volume_mad, ground_mad);
}

}  // namespace
}  // namespace pvrr
