#include "pvrr/accuracy.h"

#include <algorithm>
#include <cmath>

#include "pvrr/image.h"

namespace pvrr {

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = q * double(v.size() - 1);
  const size_t i = size_t(pos);
  const double f = pos - double(i);
  return i + 1 < v.size() && f > 0 ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

std::vector<double> angularErrors(const Frame& ref, const std::vector<Vec3>& ref_seen, const std::vector<Vec3>& seen,
                                  int only_element) {
  const size_t n = ref.element.size();
  std::vector<double> e(n, std::nan(""));
  if (ref_seen.size() != n || seen.size() != n || ref.element_point.size() != n) return e;
  for (size_t i = 0; i < n; ++i) {
    if (ref.element[i] < 0 || (only_element >= 0 && ref.element[i] != only_element)) continue;
    const double a = arcminutes(seenAngle(ref.element_point[i], ref_seen[i], seen[i]));
    if (std::isfinite(a)) e[i] = a;
  }
  return e;
}

ErrorStats summarizeErrors(const std::vector<double>& errors_arcmin, const std::vector<int8_t>* region, int8_t value) {
  std::vector<double> e;
  for (size_t i = 0; i < errors_arcmin.size(); ++i)
    if (std::isfinite(errors_arcmin[i]) && (!region || (i < region->size() && (*region)[i] == value)))
      e.push_back(errors_arcmin[i]);
  ErrorStats s;
  s.pixels = e.size();
  if (e.empty()) return s;
  s.median_arcmin = quantile(e, 0.5);
  s.p95_arcmin = quantile(e, 0.95);
  s.max_arcmin = *std::max_element(e.begin(), e.end());
  return s;
}

ErrorStats compareToReference(const Frame& ref, const Frame& frame, std::vector<double>* errors, int only_element) {
  std::vector<double> e = angularErrors(ref, ref.seen, frame.seen, only_element);
  double se = 0;
  if (frame.color.size() == ref.color.size() && ref.color.size() == e.size())
    for (size_t i = 0; i < e.size(); ++i)
      if (std::isfinite(e[i])) se += srgbSquaredError(ref.color[i], frame.color[i]);
  ErrorStats s = summarizeErrors(e);
  if (errors) *errors = std::move(e);
  if (s.pixels == 0) return s;
  s.rmse = colourRmse(se, s.pixels);
  s.psnr_db = psnrDb(s.rmse);
  return s;
}

double srgbSquaredError(const Vec3& a, const Vec3& b) {
  double se = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = linearToSrgb(std::clamp(a[k], 0.0, 1.0)) - linearToSrgb(std::clamp(b[k], 0.0, 1.0));
    se += d * d;
  }
  return se;
}

double colourRmse(double se, size_t pixels) { return pixels ? std::sqrt(se / (3.0 * double(pixels))) : 0.0; }

double psnrDb(double rmse) { return rmse > 0 ? 20.0 * std::log10(1.0 / rmse) : 99.0; }

double elementPsnr(const Frame& ref, const std::vector<Vec3>& truth, const std::vector<Vec3>& colour) {
  double se = 0;
  size_t n = 0;
  for (size_t i = 0; i < ref.element.size() && i < truth.size() && i < colour.size(); ++i) {
    if (ref.element[i] < 0) continue;
    se += srgbSquaredError(truth[i], colour[i]);
    ++n;
  }
  return n == 0 ? 0.0 : psnrDb(colourRmse(se, n));
}

}  // namespace pvrr
