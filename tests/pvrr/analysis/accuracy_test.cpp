// pvrr/analysis/accuracy.h against closed forms: quantiles of known lists (odd and even counts, empty), the angular
// error of seen points placed at known angles, its summaries by region, the colour RMSE / PSNR of known
// sRGB differences, and the zooming region and colour fringes of constructed frames.
#include "pvrr/analysis/accuracy.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
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

// Pixels where the reference's path ended at the depth limit have no seen point: no angular error (the median
// leaves them out), counted and compared by colour only, with the converse (drawn dark where the reference is lit).
TEST(DepthLimit, PixelsWithoutASeenPointAreComparedByColourOnly) {
  // Six element pixels with errors 1 .. 6 arcmin and one without an element; pixels 3, 4 and 5 (errors 4, 5, 6)
  // ended at the depth limit: the reference draws them black.
  Pair p = rotatedSeenPoints({0, 0, 0, 0, 0, 0, -1}, {1, 2, 3, 4, 5, 6, 7});
  p.ref.depth_limited = {0, 0, 0, 1, 1, 1, 0};
  for (size_t i = 3; i < 6; ++i) p.ref.color[i] = Vec3(0);
  p.frame.color[3] = Vec3(0);      // black as well
  p.frame.color[4] = Vec3(0.002);  // sRGB 0.026: dark, not lit
  p.frame.color[5] = Vec3(0.5);    // lit where the reference shows nothing: a disagreement
  p.frame.color[1] = Vec3(0);      // dark where the reference (0.5: sRGB 0.735) is lit: the converse
  std::vector<double> errors;
  const ErrorStats s = compareToReference(p.ref, p.frame, &errors);
  EXPECT_EQ(s.pixels, 3u);
  EXPECT_NEAR(s.median_arcmin, 2, kAngleTol_arcmin);  // 1 [2] 3; without the exclusion 3.5
  EXPECT_NEAR(s.max_arcmin, 3, kAngleTol_arcmin);
  for (size_t i = 3; i < 6; ++i) EXPECT_TRUE(std::isnan(errors[i])) << i;
  const DepthLimitColour d = depthLimitColour(p.ref, p.frame);
  EXPECT_EQ(d.pixels, 3u);
  EXPECT_EQ(d.drawn_lit, 1u);
  EXPECT_EQ(d.reference_lit, 3u);  // pixels 0, 1 and 2
  EXPECT_EQ(d.drawn_dark, 1u);
  EXPECT_EQ(d.disagreements(), 2u);
  // PSNR over the three: squared sRGB differences 0, 3 x 0.02585^2 (linear 0.002 is 12.92 x 0.002 in sRGB) and
  // 3 x 0.7354^2 (linear 0.5).
  const double a = 12.92 * 0.002, b = linearToSrgb(0.5);
  EXPECT_NEAR(d.psnr_db, psnrDb(std::sqrt((3 * a * a + 3 * b * b) / 9.0)), 1e-9);
  // Per element, and without the flag (a raster frame, the viewer's tiles): every element pixel counts.
  EXPECT_EQ(depthLimitColour(p.ref, p.frame, 1).pixels, 0u);
  p.ref.depth_limited.clear();
  EXPECT_EQ(compareToReference(p.ref, p.frame).pixels, 6u);
  EXPECT_EQ(depthLimitColour(p.ref, p.frame).pixels, 0u);
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

// Seen points rotated about the surface point by a known angle give exactly that angle.
TEST(ErrorMetric, RotatedSeenPointsGiveTheRotationAngle) {
  Frame ref, mode;
  const int n = 101;
  ref.width = mode.width = n;
  ref.height = mode.height = 1;
  const Vec3 p(0.3, 1.2, -0.4);
  for (int i = 0; i < n; ++i) {
    const double angle_arcmin = 0.05 * i;  // 0 .. 5 arcmin
    const Vec3 axis = glm::normalize(Vec3(std::sin(i), std::cos(i), 0.3));
    const Vec3 to = glm::normalize(Vec3(1, 0.2 * i / n, -0.5)) * (2.0 + i);
    const Vec3 offset = Vec3(glm::rotate(Mat4(1.0), radians(angle_arcmin / 60.0), axis) * Vec4(to, 0));
    // Rotating about an axis not perpendicular to `to` turns it by less: compute the true angle independently.
    const double expected = arcminutes(std::acos(std::clamp(glm::dot(glm::normalize(to), glm::normalize(offset)), -1.0, 1.0)));
    ref.element.push_back(0);
    ref.element_point.push_back(p);
    ref.seen.push_back(p + to);
    ref.color.push_back(Vec3(0.5));
    mode.element.push_back(0);
    mode.element_point.push_back(p);
    mode.seen.push_back(p + offset);
    mode.color.push_back(Vec3(0.5));
    EXPECT_NEAR(arcminutes(seenAngle(p, p + to, p + offset)), expected, 1e-6);
  }
  std::vector<double> per_pixel;
  const ErrorStats s = compareToReference(ref, mode, &per_pixel);
  EXPECT_EQ(s.pixels, size_t(n));
  EXPECT_GT(s.max_arcmin, 0);
  EXPECT_LE(s.max_arcmin, 5.0 + 1e-9);
  EXPECT_LE(s.median_arcmin, s.p95_arcmin);
  EXPECT_GE(s.psnr_db, 98.0);  // identical colours
}

TEST(ErrorMetric, PureRotationAboutAPerpendicularAxisIsExact) {
  Frame ref, mode;
  ref.width = mode.width = 1;
  ref.height = mode.height = 1;
  const Vec3 p(1, 2, 3), to(0, 0, -5);
  const double a = radians(1.5 / 60.0);  // 1.5 arcmin about +x, perpendicular to `to`
  ref.element = mode.element = {0};
  ref.element_point = mode.element_point = {p};
  ref.seen = {p + to};
  mode.seen = {p + Vec3(glm::rotate(Mat4(1.0), a, Vec3(1, 0, 0)) * Vec4(to, 0))};
  ref.color = mode.color = {Vec3(0.2)};
  EXPECT_NEAR(compareToReference(ref, mode, nullptr).median_arcmin, 1.5, 1e-9);
}

// A constructed two-patch mirror: patch 0 (vertices at x < 0) has a forward volume looking down -z from a
// viewpoint at z = 1; patch 1 (x > 0) was rendered with the reversed volume, whose forward' is the opposite
// of its rays' mean direction (+z here, rays going -z); its viewpoint is at z = 2. A pixel is zooming when
// its reference seen point lies behind its patch's viewpoint along the rays' mean direction.
TEST(ZoomingRegion, PixelsBehindTheirPatchViewpointAreZooming) {
  ElementFrame f;
  f.element = 0;
  f.world_pos = {Vec3(-1, 0, 0), Vec3(-0.5, 0, 0), Vec3(0.5, 0, 0), Vec3(1, 0, 0)};
  f.rays.assign(1, std::vector<VertexRay>(4));
  for (VertexRay& r : f.rays[0]) r.dir = Vec3(0, 0, -1), r.status = VertexStatus::Hit;
  f.grid_patches.resize(2);
  f.grid_patches[0].vertices = {0, 1};
  f.grid_patches[1].vertices = {2, 3};
  f.views.resize(2);
  f.views[0].patch = 0;
  f.views[0].fit.eye = Vec3(0, 0, 1);
  f.views[0].volume.eye = Vec3(0, 0, 1);
  f.views[0].volume.forward = Vec3(0, 0, -1);
  f.views[1].patch = 1;
  f.views[1].fit.eye = Vec3(0, 0, 2);
  f.views[1].volume.eye = Vec3(0, 0, 2);
  f.views[1].volume.forward = Vec3(0, 0, 1);  // reversed: looks back towards the mirror
  f.views[1].volume.backward = true;

  Frame ref;
  // pixel: element point, seen point -> expected region
  struct Px {
    int element;
    Vec3 p, seen;
    int8_t expected;
  };
  const std::vector<Px> px = {
      {0, Vec3(-0.9, 0, 0), Vec3(-0.9, 0, -3), 0},   // patch 0, seen beyond the mirror side: in front of z = 1 along -z
      {0, Vec3(-0.6, 0, 0), Vec3(-0.6, 0, 1.5), 1},  // patch 0, seen at z = 1.5: behind its viewpoint (z = 1)
      {0, Vec3(0.6, 0, 0), Vec3(0.6, 0, 1.5), 0},    // patch 1 (viewpoint z = 2): z = 1.5 is in front
      {0, Vec3(0.9, 0, 0), Vec3(0.9, 0, 2.5), 1},    // patch 1: z = 2.5 is behind
      {-1, Vec3(0), Vec3(0, 0, 5), -1},               // no element
      {1, Vec3(0), Vec3(0, 0, 5), -1},                // an element without frames
  };
  for (const Px& p : px) {
    ref.element.push_back(p.element);
    ref.element_point.push_back(p.p);
    ref.seen.push_back(p.seen);
  }
  ref.width = int(px.size());
  ref.height = 1;
  const std::vector<int8_t> region = zoomingRegion(ref, {f});
  ASSERT_EQ(region.size(), px.size());
  for (size_t i = 0; i < px.size(); ++i) EXPECT_EQ(region[i], px[i].expected) << "pixel " << i;
  // A path that reflects again after this mirror (its seen point lies beyond a second element) is left
  // unclassified.
  ref.bounces = {1, 2, 1, 1, 0, 0};
  const std::vector<int8_t> nested = zoomingRegion(ref, {f});
  EXPECT_EQ(nested[0], 0);
  EXPECT_EQ(nested[1], 2);
  ref.bounces.clear();

  // The region splits the error statistics.
  const std::vector<double> err = {1, 10, 2, 20, std::nan(""), std::nan("")};
  const ErrorStats z = summarizeErrors(err, &region, 1), o = summarizeErrors(err, &region, 0), all = summarizeErrors(err);
  EXPECT_EQ(z.pixels, 2u);
  EXPECT_DOUBLE_EQ(z.median_arcmin, 15);
  EXPECT_DOUBLE_EQ(z.max_arcmin, 20);
  EXPECT_EQ(o.pixels, 2u);
  EXPECT_DOUBLE_EQ(o.median_arcmin, 1.5);
  EXPECT_EQ(all.pixels, 4u);
}

// Fringes: an eye ray along -z; the red seen point deviates by 1 degree, the blue one by 1.5 degrees (blue
// bends more by 30 arcmin) at three pixels, the other way round at one, equal at one (left out).
TEST(Fringe, BlueBendingMoreIsMeasuredFromTheSeenPoints) {
  const Vec3 eye(0, 0, 1);
  auto seenAt = [](const Vec3& p, double deg) { return p + 5.0 * Vec3(std::sin(radians(deg)), 0, -std::cos(radians(deg))); };
  std::vector<Vec3> pts, red, blue;
  std::vector<int8_t> mask;
  const double r_deg[] = {1, 1, 1, 2, 1, 3}, b_deg[] = {1.5, 1.5, 1.5, 1.9, 1, 9};
  for (int i = 0; i < 6; ++i) {
    const Vec3 p(0, 0, 0);
    pts.push_back(p);
    red.push_back(seenAt(p, r_deg[i]));
    blue.push_back(seenAt(p, b_deg[i]));
    mask.push_back(i < 5);  // the last pixel is not a lens pixel
  }
  const FringeStats s = fringeStats(eye, pts, red, blue, mask);
  EXPECT_EQ(s.pixels, 4u);
  EXPECT_NEAR(s.fraction_blue_bends_more, 0.75, 1e-12);
  EXPECT_NEAR(s.median_blue_minus_red_arcmin, 30, 1e-6);

  // Per-channel angular errors: the mode's channel seen point compared with the reference's same channel.
  Frame ref;
  ref.element = {0, 0, -1};
  ref.element_point = {Vec3(0), Vec3(0), Vec3(0)};
  const std::vector<Vec3> ref_b = {seenAt(Vec3(0), 1.5), seenAt(Vec3(0), 1.5), seenAt(Vec3(0), 1)};
  const std::vector<Vec3> mode_b = {seenAt(Vec3(0), 1.5), seenAt(Vec3(0), 1.0), seenAt(Vec3(0), 9)};
  const std::vector<double> e = angularErrors(ref, ref_b, mode_b);
  EXPECT_NEAR(e[0], 0, 1e-6);
  EXPECT_NEAR(e[1], 30, 1e-6);
  EXPECT_TRUE(std::isnan(e[2]));  // not an element pixel
}

}  // namespace
}  // namespace pvrr
