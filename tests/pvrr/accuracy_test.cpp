// pvrr/accuracy.h against closed forms: quantiles of known lists (odd and even counts, empty), the angular
// error of seen points placed at known angles, its summaries by region, and the colour RMSE / PSNR of known
// sRGB differences.
#include "pvrr/accuracy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace pvrr {
namespace {

// Sums and interpolations of a few doubles: a few ulps.
constexpr double kExact = 1e-12;
// Angles through atan2 of |a x b| and a . b on unit-scale vectors: about 1e-15 rad, i.e. 1e-11 arcmin.
constexpr double kAngleTol_arcmin = 1e-9;

TEST(Quantile, MedianOfAnOddCountIsTheMiddleValue) {
  EXPECT_EQ(median({3, 1, 2}), 2);
  EXPECT_EQ(median({5, 9, 1, 7, 3}), 5);
  EXPECT_EQ(median({42}), 42);
}

TEST(Quantile, MedianOfAnEvenCountIsTheMeanOfTheTwoMiddleValues) {
  EXPECT_EQ(median({4, 1, 3, 2}), 2.5);  // not 3, the upper middle value
  EXPECT_EQ(median({10, 0}), 5);
  EXPECT_EQ(median({1, 1, 2, 100}), 1.5);
}

TEST(Quantile, EmptyIsZero) {
  EXPECT_EQ(median({}), 0);
  EXPECT_EQ(quantile({}, 0.95), 0);
}

TEST(Quantile, InterpolatesBetweenOrderStatistics) {
  std::vector<double> v;
  for (int i = 100; i >= 0; --i) v.push_back(i);  // 0..100, reversed: position q * 100
  EXPECT_NEAR(quantile(v, 0.95), 95, kExact);
  EXPECT_NEAR(quantile(v, 0.333), 33.3, kExact);
  EXPECT_EQ(quantile(v, 0), 0);
  EXPECT_EQ(quantile(v, 1), 100);
  EXPECT_NEAR(quantile({0, 1}, 0.95), 0.95, kExact);
  // An exact position takes that order statistic alone: an infinite neighbour does not leak in.
  EXPECT_EQ(quantile({1, 2, kInf}, 0.5), 2);
}

// A 2 x 2 reference frame whose element pixels see (1, 0, 0) from their element point at the origin; the frame
// under test sees it rotated about z by the given angles (arcmin).
struct Pair {
  Frame ref, frame;
};
Pair rotatedSeenPoints(const std::vector<int>& element, const std::vector<double>& angles_arcmin) {
  Pair p;
  p.ref.width = p.frame.width = 2;
  p.ref.height = p.frame.height = 2;
  p.ref.element = element;
  for (size_t i = 0; i < element.size(); ++i) {
    const double a = radians(angles_arcmin[i] / 60.0);
    const Vec3 origin(0.0);
    p.ref.element_point.push_back(origin);
    p.ref.seen.push_back(Vec3(1, 0, 0));
    p.frame.seen.push_back(Vec3(std::cos(a), std::sin(a), 0) * 3.0);  // the distance does not matter
    p.ref.color.push_back(Vec3(0.5));
    p.frame.color.push_back(Vec3(0.5));
  }
  return p;
}

TEST(AngularErrors, AreTheAnglesAtTheReferencesElementPoint) {
  const Pair p = rotatedSeenPoints({0, -1, 1, 0}, {1.5, 7, 2.25, 0.5});
  const std::vector<double> e = angularErrors(p.ref, p.ref.seen, p.frame.seen);
  ASSERT_EQ(e.size(), 4u);
  EXPECT_NEAR(e[0], 1.5, kAngleTol_arcmin);
  EXPECT_TRUE(std::isnan(e[1])) << "no element under the pixel";
  EXPECT_NEAR(e[2], 2.25, kAngleTol_arcmin);
  EXPECT_NEAR(e[3], 0.5, kAngleTol_arcmin);
  // One element only.
  const std::vector<double> e0 = angularErrors(p.ref, p.ref.seen, p.frame.seen, 0);
  EXPECT_NEAR(e0[0], 1.5, kAngleTol_arcmin);
  EXPECT_TRUE(std::isnan(e0[2]));
  // The angle is measured at the element point, not at the eye: a seen point moved along its own direction
  // from the element point has no error.
  EXPECT_NEAR(arcminutes(seenAngle(Vec3(1, 2, 3), Vec3(1, 2, 4), Vec3(1, 2, 30))), 0, kAngleTol_arcmin);
}

TEST(AngularErrors, AreNanWhereTheFrameHasNoSeenPoints) {
  const Pair p = rotatedSeenPoints({0, 0, 0, 0}, {1, 2, 3, 4});
  for (double e : angularErrors(p.ref, p.ref.seen, {})) EXPECT_TRUE(std::isnan(e));
}

TEST(SummarizeErrors, MedianP95AndMaxOfTheFiniteErrorsInARegion) {
  const double nan = std::nan("");
  const std::vector<double> e = {4, nan, 1, 3, 2, 10};
  const ErrorStats all = summarizeErrors(e);
  EXPECT_EQ(all.pixels, 5u);
  EXPECT_EQ(all.median_arcmin, 3);                   // 1 2 [3] 4 10
  EXPECT_NEAR(all.p95_arcmin, 4 + 0.8 * 6, kExact);  // position 3.8 of the five
  EXPECT_EQ(all.max_arcmin, 10);
  const std::vector<int8_t> region = {1, 1, 1, 0, 1, 0};
  const ErrorStats in = summarizeErrors(e, &region, 1);
  EXPECT_EQ(in.pixels, 3u);
  EXPECT_EQ(in.median_arcmin, 2);  // 1 [2] 4
  const ErrorStats out = summarizeErrors(e, &region, 0);
  EXPECT_EQ(out.pixels, 2u);
  EXPECT_EQ(out.median_arcmin, 6.5);  // (3 + 10) / 2
  const ErrorStats none = summarizeErrors(e, &region, 2);
  EXPECT_EQ(none.pixels, 0u);
  EXPECT_EQ(none.median_arcmin, 0);
  EXPECT_EQ(summarizeErrors({}).pixels, 0u);
}

TEST(CompareToReference, SummarisesTheAnglesAndTheColourOverElementPixels) {
  Pair p = rotatedSeenPoints({0, -1, 0, 0}, {1, 50, 2, 4});
  // Identical colours: no colour error.
  std::vector<double> errors;
  ErrorStats s = compareToReference(p.ref, p.frame, &errors);
  EXPECT_EQ(s.pixels, 3u);
  EXPECT_NEAR(s.median_arcmin, 2, kAngleTol_arcmin);
  EXPECT_NEAR(s.max_arcmin, 4, kAngleTol_arcmin);
  EXPECT_EQ(s.rmse, 0);
  EXPECT_EQ(s.psnr_db, 99);
  ASSERT_EQ(errors.size(), 4u);
  EXPECT_TRUE(std::isnan(errors[1]));
  // Black against white on one of the three element pixels (sRGB difference 1 in each channel; the pixel
  // without an element is not counted): RMSE sqrt(3 / 9), PSNR 20 log10(sqrt(3)) = 4.771 dB.
  p.ref.color[0] = Vec3(1);
  p.frame.color[0] = Vec3(0);
  p.ref.color[1] = Vec3(0);
  p.frame.color[1] = Vec3(1);
  s = compareToReference(p.ref, p.frame);
  EXPECT_NEAR(s.rmse, std::sqrt(1.0 / 3.0), kExact);
  EXPECT_NEAR(s.psnr_db, 10 * std::log10(3.0), kExact);
  // Colours beyond [0, 1] are clamped before encoding, as in the 8-bit pictures.
  p.ref.color[0] = Vec3(5);
  EXPECT_NEAR(compareToReference(p.ref, p.frame).rmse, std::sqrt(1.0 / 3.0), kExact);
  // Only element 0's pixels.
  p.ref.element[3] = 1;
  EXPECT_EQ(compareToReference(p.ref, p.frame, nullptr, 0).pixels, 2u);
}

TEST(ColourError, PsnrOfKnownRmse) {
  EXPECT_NEAR(psnrDb(0.1), 20, kExact);
  EXPECT_NEAR(psnrDb(1), 0, kExact);
  EXPECT_EQ(psnrDb(0), 99);
  EXPECT_EQ(colourRmse(12, 0), 0);
  EXPECT_NEAR(colourRmse(12, 4), 1, kExact);
  // The sRGB encoding of linear 0.5 (IEC 61966-2-1: 1.055 L^(1/2.4) - 0.055 = 0.7354): its difference to black,
  // squared, in three channels.
  const double half = 1.055 * std::pow(0.5, 1 / 2.4) - 0.055;
  EXPECT_NEAR(srgbSquaredError(Vec3(0.5), Vec3(0)), 3 * half * half, kExact);
}

TEST(ColourError, ElementPsnrCountsOnlyElementPixels) {
  Frame ref;
  ref.element = {0, -1, 2, -1};
  const std::vector<Vec3> truth = {Vec3(1), Vec3(1), Vec3(0), Vec3(0)}, colour = {Vec3(0), Vec3(0), Vec3(0), Vec3(1)};
  EXPECT_NEAR(elementPsnr(ref, truth, colour), 10 * std::log10(2.0), kExact);  // RMSE sqrt(1 / 2)
  ref.element = {-1, -1, -1, -1};
  EXPECT_EQ(elementPsnr(ref, truth, colour), 0);
}

}  // namespace
}  // namespace pvrr
