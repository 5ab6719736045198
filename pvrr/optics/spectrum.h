// Wavelengths and colour weights of the dispersion modes.
//
// THE MODEL. A lens (or metal mirror) is traced with one monochrome ray per wavelength sample: the ray uses the
// index n(lambda_i) (pvrr/optics/material.h) at every interface, and returns the linear RGB colour c_i that the scene
// shows along its final direction (the environment is RGB; it is not re-lit spectrally). The pixel is
//     colour = sum_i  w_i (*) c_i          ((*): per-channel product)
// with per-sample RGB weights w_i. The weights of both modes sum to (1, 1, 1), so that when nothing disperses
// (all c_i equal to c) the result is exactly c: the modes only add colour fringes, never a tint.
//
//  - RGB mode: three samples, one per channel, w_R = (1,0,0) at kRgbWavelengths_nm[0], w_G = (0,1,0) at [1],
//    w_B = (0,0,1) at [2]. The wavelengths are the Abbe number's own lines, R = C (656.27 nm), G = d (587.56 nm),
//    B = F (486.13 nm). Why: the spread of index between the R and B rays is then exactly n_F - n_C =
//    (n_d - 1) / V_d, the quantity a spectacle lens's Abbe number specifies, and the G ray uses n_d, the index
//    the lens power is computed from. The red/blue fringe seen in RGB mode is therefore the catalogue's
//    transverse chromatic aberration, not a spread chosen by us. (The sRGB primaries' dominant wavelengths,
//    about 612/549/465 nm, lie inside the C..F interval, so RGB mode shows slightly wider fringes than a
//    perceptual match would; the spectral mode is the accurate one.)
//  - Spectral mode: N >= 3 samples at the midpoints of N equal bins over [400, 700] nm. For each sample the
//    CIE 1931 2-degree colour-matching functions (xbar, ybar, zbar)(lambda_i) (the analytic fit below) are
//    converted to linear sRGB with the IEC 61966-2-1 XYZ -> sRGB (D65) matrix, giving rgb_i; then each channel
//    is normalised over the samples: w_i,c = rgb_i,c / sum_j rgb_j,c. This is the white normalisation: an
//    equal-energy spectrum over 400..700 nm maps to RGB (1, 1, 1) (a per-channel, von Kries-like scaling of
//    equal-energy white to display white), which is what makes the no-dispersion result the unmodified colour.
//    Some w_i,c are negative (spectral colours lie outside the sRGB gamut); each channel's sum is still 1. With
//    strong dispersion a channel of the sum may therefore dip slightly below 0; clamp when displaying.
#pragma once
#include <vector>

#include "pvrr/base/math.h"
#include "pvrr/optics/material.h"

namespace pvrr {

// RGB mode: (R, G, B) = (C line, d line, F line), see above.
inline constexpr double kRgbWavelengths_nm[3] = {kLineC_nm, kLineD_nm, kLineF_nm};

// Spectral mode range.
constexpr double kSpectralMin_nm = 400.0;
constexpr double kSpectralMax_nm = 700.0;
constexpr int kMinSpectralSamples = 3;

// One wavelength sample of a dispersion mode and its RGB weight.
struct SpectralSample {
  double wavelength_nm = kLineD_nm;
  Vec3 rgb_weight{1.0};
};

// CIE 1931 2-degree colour-matching functions (xbar, ybar, zbar) at lambda_nm, by the multi-lobe piecewise-
// Gaussian fit of C. Wyman, P.-P. Sloan, P. Shirley, "Simple Analytic Approximations to the CIE XYZ Color
// Matching Functions", Journal of Computer Graphics Techniques 2(2), 2013 (their Equation 2 / listing
// "xFit_1931"). The fit follows the CIE table to about 0.015 absolute (about 1 % of the peaks).
Vec3 cieXyzFit(double lambda_nm);

// CIE XYZ (D65-relative, Y = 1 for white) -> linear sRGB, the IEC 61966-2-1 matrix.
Vec3 xyzToLinearSrgb(const Vec3& xyz);

// Midpoints of n equal bins over [kSpectralMin_nm, kSpectralMax_nm]. Throws pvrr::Error when n < 3.
std::vector<double> spectralWavelengths(int n);

// The spectral mode's n samples with their weights (see the model above); the weights sum to (1, 1, 1).
// Throws pvrr::Error when n < 3.
std::vector<SpectralSample> spectralSamples(int n);

// The RGB mode's three samples: (kRgbWavelengths_nm[c], unit vector of channel c).
std::vector<SpectralSample> rgbSamples();

}  // namespace pvrr
