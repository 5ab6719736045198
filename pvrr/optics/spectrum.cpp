#include "pvrr/optics/spectrum.h"

#include <cmath>
#include <string>

#include "pvrr/base/error.h"

namespace pvrr {

namespace {

// exp(-t^2 / 2) with t = (lambda - mu) * inv_sigma, inv_sigma chosen by the side of the mean: the asymmetric
// Gaussian lobe of Wyman, Sloan & Shirley (JCGT 2013). The constants below are the published 1/sigma values.
double lobe(double lambda_nm, double mu_nm, double inv_sigma_below, double inv_sigma_above) {
  const double t = (lambda_nm - mu_nm) * (lambda_nm < mu_nm ? inv_sigma_below : inv_sigma_above);
  return std::exp(-0.5 * t * t);
}

void checkSampleCount(int n) {
  if (n < kMinSpectralSamples)
    throw Error("spectral samples: expected an integer >= " + std::to_string(kMinSpectralSamples) + ", got " +
                std::to_string(n));
}

}  // namespace

Vec3 cieXyzFit(double lambda_nm) {
  const double l = lambda_nm;
  const double x = 0.362 * lobe(l, 442.0, 0.0624, 0.0374) + 1.056 * lobe(l, 599.8, 0.0264, 0.0323) -
                   0.065 * lobe(l, 501.1, 0.0490, 0.0382);
  const double y = 0.821 * lobe(l, 568.8, 0.0213, 0.0247) + 0.286 * lobe(l, 530.9, 0.0613, 0.0322);
  const double z = 1.217 * lobe(l, 437.0, 0.0845, 0.0278) + 0.681 * lobe(l, 459.0, 0.0385, 0.0725);
  return {x, y, z};
}

Vec3 xyzToLinearSrgb(const Vec3& c) {
  // IEC 61966-2-1:1999, sRGB, D65 white; rows give R, G, B.
  return {3.2406 * c.x - 1.5372 * c.y - 0.4986 * c.z,  //
          -0.9689 * c.x + 1.8758 * c.y + 0.0415 * c.z,  //
          0.0557 * c.x - 0.2040 * c.y + 1.0570 * c.z};
}

std::vector<double> spectralWavelengths(int n) {
  checkSampleCount(n);
  const double step_nm = (kSpectralMax_nm - kSpectralMin_nm) / n;
  std::vector<double> out(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) out[size_t(i)] = kSpectralMin_nm + (i + 0.5) * step_nm;
  return out;
}

std::vector<SpectralSample> spectralSamples(int n) {
  const std::vector<double> wl = spectralWavelengths(n);
  std::vector<SpectralSample> out(wl.size());
  Vec3 sum(0.0);
  for (size_t i = 0; i < wl.size(); ++i) {
    // The bin width is common to all samples and cancels in the normalisation below.
    out[i].wavelength_nm = wl[i];
    out[i].rgb_weight = xyzToLinearSrgb(cieXyzFit(wl[i]));
    sum += out[i].rgb_weight;
  }
  // Each channel's integral of the sRGB colour-matching functions over 400..700 nm is positive; a non-positive
  // sum would be a broken table or matrix.
  PVRR_CHECK(sum.x > 0 && sum.y > 0 && sum.z > 0, << "channel sums " << sum.x << ", " << sum.y << ", " << sum.z);
  for (SpectralSample& s : out) s.rgb_weight /= sum;
  return out;
}

std::vector<SpectralSample> rgbSamples() {
  return {{kRgbWavelengths_nm[0], Vec3(1, 0, 0)},
          {kRgbWavelengths_nm[1], Vec3(0, 1, 0)},
          {kRgbWavelengths_nm[2], Vec3(0, 0, 1)}};
}

}  // namespace pvrr
