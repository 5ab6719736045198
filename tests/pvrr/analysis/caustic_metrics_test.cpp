// The caustic metrics on analytic irradiance maps: a sampled Gaussian spot of known centre, width and power.
#include "pvrr/analysis/caustic_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pvrr/base/error.h"

namespace pvrr {
namespace {

// 40 x 30 cells of 0.25 mm on a tilted receiver (its axes need not be the world's).
ReceiverRect receiver() {
  ReceiverRect r;
  r.centre = Vec3(0.1, 0.75, -0.2);
  r.u_axis = glm::normalize(Vec3(1, 0, 1));
  r.v_axis = Vec3(0, 1, 0);
  r.width_m = 0.01;
  r.height_m = 0.0075;
  r.cells_u = 40;
  r.cells_v = 30;
  return r;
}

// A Gaussian spot of `power` W and standard deviation sigma (m) about `centre` (receiver coordinates), its
// irradiance sampled at the cell centres, the same in each channel.
IrradianceGrid gaussian(Vec2 centre, double sigma, double power) {
  IrradianceGrid g = IrradianceGrid::zeros(receiver());
  for (int j = 0; j < g.rect.cells_v; ++j)
    for (int i = 0; i < g.rect.cells_u; ++i) {
      const Vec2 d = g.rect.cellCentre(i, j) - centre;
      const double e = power / (2 * kPi * sigma * sigma) * std::exp(-glm::dot(d, d) / (2 * sigma * sigma));
      g.irradiance[g.index(i, j)] = Vec3(e);
    }
  return g;
}

const Vec2 kCentre(0.0013, -0.0007);  // off the cell centres on both axes
constexpr double kSigma = 0.0008, kPower = 2.0;
// The log-parabola is exact for a sampled Gaussian: only rounding remains (metres).
constexpr double kExactPeakTol = 1e-12;
// The midpoint sum of a Gaussian 3.2 cells wide is exact to far below this; the grid's edges cut its tail at
// 3.8 sigma (7e-5 of the power).
constexpr double kPowerTol = 1e-3;

TEST(CausticMetrics, FindsAGaussianSpotsPeakPowerAndSpot) {
  const IrradianceGrid g = gaussian(kCentre, kSigma, kPower);
  const SpotMetrics s = spotMetrics(g);
  ASSERT_TRUE(s.found);
  EXPECT_NEAR(s.peak_uv_m.x, kCentre.x, kExactPeakTol);
  EXPECT_NEAR(s.peak_uv_m.y, kCentre.y, kExactPeakTol);
  EXPECT_LT(glm::length(s.peak_world - g.rect.toWorld(kCentre)), kExactPeakTol);
  EXPECT_NEAR(s.total_power / kPower, 1.0, kPowerTol);
  // Above half the peak lies 1 - 1/2 of a Gaussian's power, within a disc of area 2 pi sigma^2 ln 2; on cells
  // of a third of sigma the staircase boundary is off by a few per cent.
  constexpr double kSpotTol = 0.05;
  EXPECT_NEAR(s.spot_power / (0.5 * kPower), 1.0, kSpotTol);
  EXPECT_NEAR(s.spot_area_m2 / (2 * kPi * kSigma * kSigma * std::log(2.0)), 1.0, 2 * kSpotTol);
  // The spot's centroid: the staircase breaks its symmetry by a fraction of a cell.
  EXPECT_LT(glm::length(s.centroid_uv_m - kCentre), 0.25 * g.rect.cellWidth());
}

TEST(CausticMetrics, ComparesTwoMaps) {
  const IrradianceGrid ref = gaussian(kCentre, kSigma, kPower);
  // 10 % brighter everywhere: relative L1 0.1 in the spot, power ratio 1.1, the same peak.
  IrradianceGrid brighter = ref;
  for (Vec3& e : brighter.irradiance) e *= 1.1;
  IrradianceComparison c = compareIrradiance(brighter, ref);
  EXPECT_NEAR(c.relative_l1_in_spot, 0.1, 1e-12);
  EXPECT_NEAR(c.power_ratio, 1.1, 1e-12);
  EXPECT_NEAR(c.peak_distance_m, 0, kExactPeakTol);
  // Moved by 0.5 mm along u: the peaks 0.5 mm apart; the error grows with the shift.
  const IrradianceGrid moved = gaussian(kCentre + Vec2(0.0005, 0), kSigma, kPower);
  c = compareIrradiance(moved, ref);
  EXPECT_NEAR(c.peak_distance_m, 0.0005, kExactPeakTol);
  EXPECT_NEAR(c.power_ratio, 1.0, kPowerTol);
  const double l1_half_mm = c.relative_l1_in_spot;
  const double l1_quarter_mm =
      compareIrradiance(gaussian(kCentre + Vec2(0.00025, 0), kSigma, kPower), ref).relative_l1_in_spot;
  EXPECT_GT(l1_quarter_mm, 0.05);
  EXPECT_GT(l1_half_mm, 1.5 * l1_quarter_mm);
  // Only the reference's spot counts: light far outside it does not change the spot's error.
  IrradianceGrid stray = ref;
  stray.irradiance[stray.index(0, 0)] += Vec3(1.0);
  EXPECT_NEAR(compareIrradiance(stray, ref).relative_l1_in_spot, 0, 1e-15);
}

TEST(CausticMetrics, EmptyAndMismatchedMaps) {
  const IrradianceGrid empty = IrradianceGrid::zeros(receiver());
  EXPECT_FALSE(spotMetrics(empty).found);
  const IrradianceGrid ref = gaussian(kCentre, kSigma, kPower);
  EXPECT_THROW(compareIrradiance(ref, empty), Error);
  const IrradianceComparison c = compareIrradiance(empty, ref);
  EXPECT_NEAR(c.relative_l1_in_spot, 1.0, 1e-15);
  EXPECT_FALSE(std::isfinite(c.peak_distance_m));
  IrradianceGrid other = ref;
  other.rect.cells_u = 20;
  EXPECT_THROW(compareIrradiance(other, ref), Error);
  IrradianceGrid shifted = ref;
  shifted.rect.centre.x += 1e-3;
  EXPECT_THROW(compareIrradiance(shifted, ref), Error);
  EXPECT_THROW(spotMetrics(ref, 0.0), Error);
}

}  // namespace
}  // namespace pvrr
