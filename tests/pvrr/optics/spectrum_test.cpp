// Tests of pvrr/optics/spectrum.h: the CIE fit against the CIE 1931 table, the sRGB matrix, the dispersion modes'
// wavelengths and weights.
#include "pvrr/optics/spectrum.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pvrr/base/error.h"
#include "pvrr/optics/material.h"

namespace pvrr {
namespace {

// Sums of at most a few hundred O(1) doubles.
constexpr double kSumTol = 1e-12;

// CIE 1931 2-degree standard observer, 1-nm/5-nm table values (CIE 15:2004), to 4 decimals.
struct CieRow {
  double lambda_nm, x, y, z;
};
constexpr CieRow kCieTable[] = {
    {440, 0.3483, 0.0230, 1.7471}, {445, 0.3481, 0.0298, 1.7826}, {450, 0.3362, 0.0380, 1.7721},
    {500, 0.0049, 0.3230, 0.2720}, {550, 0.4334, 0.9950, 0.0087}, {555, 0.5121, 1.0000, 0.0057},
    {600, 1.0622, 0.6310, 0.0008}, {650, 0.2835, 0.1070, 0.0000}, {700, 0.0114, 0.0041, 0.0000},
};

TEST(Spectrum, CieFitMatchesCie1931Table) {
  // Wyman, Sloan & Shirley (JCGT 2013) show the multi-lobe fit within about 1 % of the CMF peaks of the table
  // everywhere in the visible; at these rows it is off by at most 0.013. 0.02 is 1.1 % of zbar's peak (1.78).
  constexpr double kFitTol = 0.02;
  for (const CieRow& r : kCieTable) {
    const Vec3 f = cieXyzFit(r.lambda_nm);
    EXPECT_NEAR(f.x, r.x, kFitTol) << r.lambda_nm << " nm";
    EXPECT_NEAR(f.y, r.y, kFitTol) << r.lambda_nm << " nm";
    EXPECT_NEAR(f.z, r.z, kFitTol) << r.lambda_nm << " nm";
  }
}

TEST(Spectrum, YbarPeaksNear555) {
  // The table's maximum is at 555 nm (y = 1.0000); the fit's peak may move by a couple of nm.
  constexpr double kPeakTol_nm = 3.0;
  double best = 0, best_l = 0;
  for (double l = 500; l <= 600; l += 0.1) {
    const double y = cieXyzFit(l).y;
    if (y > best) best = y, best_l = l;
  }
  EXPECT_NEAR(best_l, 555.0, kPeakTol_nm);
  EXPECT_NEAR(best, 1.0, 0.01);  // ybar is normalised to a peak of 1
}

TEST(Spectrum, XyzToSrgbInvertsTheStandardSrgbToXyzMatrix) {
  // IEC 61966-2-1 gives both matrices to 4 decimals; their product is the identity to a few 1e-4.
  constexpr double kFourDecimalTol = 1e-3;
  const double to_xyz[3][3] = {{0.4124, 0.3576, 0.1805}, {0.2126, 0.7152, 0.0722}, {0.0193, 0.1192, 0.9505}};
  for (int c = 0; c < 3; ++c) {
    const Vec3 rgb = xyzToLinearSrgb(Vec3(to_xyz[0][c], to_xyz[1][c], to_xyz[2][c]));
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(rgb[r], r == c ? 1.0 : 0.0, kFourDecimalTol) << r << "," << c;
  }
  // D65 white (x, y) = (0.3127, 0.3290) with Y = 1 maps to RGB white.
  const Vec3 white = xyzToLinearSrgb(Vec3(0.3127 / 0.3290, 1.0, (1 - 0.3127 - 0.3290) / 0.3290));
  for (int r = 0; r < 3; ++r) EXPECT_NEAR(white[r], 1.0, kFourDecimalTol);
}

TEST(Spectrum, SpectralWavelengthsAreBinMidpoints) {
  const std::vector<double> three = spectralWavelengths(3);
  ASSERT_EQ(three.size(), 3u);
  EXPECT_NEAR(three[0], 450, kSumTol);
  EXPECT_NEAR(three[1], 550, kSumTol);
  EXPECT_NEAR(three[2], 650, kSumTol);
  const std::vector<double> sixteen = spectralWavelengths(16);
  ASSERT_EQ(sixteen.size(), 16u);
  EXPECT_NEAR(sixteen.front(), 400 + 300.0 / 32, kSumTol);
  EXPECT_NEAR(sixteen.back(), 700 - 300.0 / 32, kSumTol);
  for (size_t i = 1; i < sixteen.size(); ++i) EXPECT_NEAR(sixteen[i] - sixteen[i - 1], 300.0 / 16, kSumTol);
  EXPECT_THROW(spectralWavelengths(2), Error);
  EXPECT_THROW(spectralSamples(0), Error);
}

TEST(Spectrum, SpectralWeightsSumToWhiteSoNoDispersionKeepsTheColour) {
  for (int n : {3, 4, 7, 16, 31, 64, 300}) {
    const std::vector<SpectralSample> s = spectralSamples(n);
    ASSERT_EQ(int(s.size()), n);
    Vec3 sum(0.0);
    for (const SpectralSample& x : s) sum += x.rgb_weight;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], 1.0, kSumTol) << "n=" << n;
    // The model: every wavelength sees the same colour when nothing disperses; the result is that colour.
    const Vec3 colour(0.8, 0.3, 0.05);
    Vec3 seen(0.0);
    for (const SpectralSample& x : s) seen += x.rgb_weight * colour;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(seen[c], colour[c], kSumTol) << "n=" << n;
  }
}

TEST(Spectrum, SpectralWeightsHaveTheRightHue) {
  // Each of 450 / 550 / 650 nm contributes mostly to its own channel (blue / green / red), and the long
  // wavelengths dominate red: a swapped matrix row or channel would fail this.
  const std::vector<SpectralSample> s = spectralSamples(3);
  EXPECT_GT(s[0].rgb_weight.b, 0.9);
  EXPECT_GT(s[1].rgb_weight.g, 0.9);
  EXPECT_GT(s[2].rgb_weight.r, 0.9);
}

// The weights sample one spectral density whatever N is: the weights of N = 300 summed in groups of three
// equal the weights of N = 100 (1-nm and 3-nm midpoint rules of the same integral) up to the midpoint rule's
// error, which for CMFs varying on 15..40 nm scales is about 1e-4 of a weight of ~0.01-0.03.
TEST(Spectrum, SpectralWeightsConvergeWithSampleCount) {
  constexpr double kMidpointRuleTol = 1e-3;
  const std::vector<SpectralSample> coarse = spectralSamples(100);
  const std::vector<SpectralSample> fine = spectralSamples(300);
  for (size_t i = 0; i < coarse.size(); ++i) {
    const Vec3 sum = fine[3 * i].rgb_weight + fine[3 * i + 1].rgb_weight + fine[3 * i + 2].rgb_weight;
    EXPECT_NEAR(fine[3 * i + 1].wavelength_nm, coarse[i].wavelength_nm, kSumTol);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], coarse[i].rgb_weight[c], kMidpointRuleTol) << i << "," << c;
  }
}

TEST(Spectrum, RgbModeUsesTheAbbeLines) {
  EXPECT_EQ(kRgbWavelengths_nm[0], kLineC_nm);
  EXPECT_EQ(kRgbWavelengths_nm[1], kLineD_nm);
  EXPECT_EQ(kRgbWavelengths_nm[2], kLineF_nm);
  const std::vector<SpectralSample> s = rgbSamples();
  ASSERT_EQ(s.size(), 3u);
  Vec3 sum(0.0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(s[size_t(c)].wavelength_nm, kRgbWavelengths_nm[c]);
    EXPECT_EQ(s[size_t(c)].rgb_weight[c], 1.0);
    sum += s[size_t(c)].rgb_weight;
  }
  EXPECT_EQ(sum, Vec3(1.0));
  // The R-B index spread of RGB mode is exactly the catalogue's n_F - n_C = (n_d - 1)/V_d.
  const Dispersion pc = lookupLensMaterial("polycarbonate").dispersion;
  EXPECT_NEAR(pc.index(kRgbWavelengths_nm[2]) - pc.index(kRgbWavelengths_nm[0]), (1.586 - 1) / 30, kSumTol);
  EXPECT_NEAR(pc.index(kRgbWavelengths_nm[1]), 1.586, kSumTol);
}

}  // namespace
}  // namespace pvrr
