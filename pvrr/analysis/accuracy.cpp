#include "pvrr/analysis/accuracy.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pvrr/base/image.h"

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
    if (ref.element[i] < 0 || (only_element >= 0 && ref.element[i] != only_element) || depthLimited(ref, i)) continue;
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

namespace {

double maxSrgb(const Vec3& c) {
  double m = 0;
  for (int k = 0; k < 3; ++k) m = std::max(m, linearToSrgb(std::clamp(c[k], 0.0, 1.0)));
  return m;
}

}  // namespace

bool drawnDark(const Vec3& linear) { return maxSrgb(linear) < kDarkSrgb; }
bool drawnLit(const Vec3& linear) { return maxSrgb(linear) > kLitSrgb; }

DepthLimitColour depthLimitColour(const Frame& ref, const Frame& frame, int only_element) {
  DepthLimitColour d;
  const size_t n = ref.element.size();
  if (ref.color.size() != n || frame.color.size() != n) return d;
  double se = 0;
  for (size_t i = 0; i < n; ++i) {
    if (ref.element[i] < 0 || (only_element >= 0 && ref.element[i] != only_element)) continue;
    if (depthLimited(ref, i)) {
      ++d.pixels;
      d.drawn_lit += drawnLit(frame.color[i]);
      se += srgbSquaredError(ref.color[i], frame.color[i]);
    } else if (drawnLit(ref.color[i])) {
      ++d.reference_lit;
      d.drawn_dark += drawnDark(frame.color[i]);
    }
  }
  if (d.pixels > 0) d.psnr_db = psnrDb(colourRmse(se, d.pixels));
  return d;
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

std::vector<int8_t> zoomingRegion(const Frame& ref, const std::vector<ElementFrame>& frames, const Scene* scene) {
  const size_t n = ref.element.size();
  std::vector<int8_t> region(n, -1);
  for (const ElementFrame& f : frames) {
    if (f.views.empty()) continue;
    // The patch of each vertex (the first patch listing it: shared boundary vertices belong to either).
    std::vector<int> vertex_view(f.world_pos.size(), -1);
    for (size_t v = 0; v < f.views.size(); ++v)
      for (uint32_t vi : f.grid_patches[size_t(f.views[v].patch)].vertices)
        if (vi < vertex_view.size() && vertex_view[vi] < 0) vertex_view[vi] = int(v);
    // The forward direction of each patch's forward volume: the normalised mean of its outgoing ray directions
    // (pvrr/method/view_volume.h; a patch rendered with the reversed volume keeps only forward' in its volume).
    const size_t fit_channel = f.rays.size() / 2;
    std::vector<Vec3> forward(f.views.size());
    for (size_t v = 0; v < f.views.size(); ++v) {
      const ViewVolume& vv = f.views[v].volume;
      if (!vv.backward || f.rays.empty()) {
        forward[v] = vv.forward;
        continue;
      }
      Vec3 sum(0);
      for (uint32_t vi : f.grid_patches[size_t(f.views[v].patch)].vertices)
        if (vi < f.rays[fit_channel].size() && f.rays[fit_channel][vi].status != VertexStatus::Tir) sum += f.rays[fit_channel][vi].dir;
      forward[v] = glm::length(sum) > 0 ? glm::normalize(sum) : -vv.forward;
    }
    // Specular events of a path that meets this element only: a mirror reflects once, a lens refracts twice.
    const int own_events = scene && scene->elements[size_t(f.element)].type == ElementType::Lens ? 2 : 1;
    for (size_t i = 0; i < n; ++i) {
      if (ref.element[i] != f.element) continue;
      if (ref.bounces.size() == n && ref.bounces[i] > own_events) {
        region[i] = 2;
        continue;
      }
      size_t view = 0;
      if (f.views.size() > 1) {
        double best = std::numeric_limits<double>::infinity();
        for (size_t vi = 0; vi < f.world_pos.size(); ++vi) {
          const Vec3 d = f.world_pos[vi] - ref.element_point[i];
          const double d2 = glm::dot(d, d);
          if (d2 < best && vertex_view[vi] >= 0) best = d2, view = size_t(vertex_view[vi]);
        }
      }
      const double depth = glm::dot(ref.seen[i] - f.views[view].fit.eye, forward[view]);
      if (std::isfinite(depth)) region[i] = depth <= 0 ? 1 : 0;
    }
  }
  return region;
}

FringeStats fringeStats(const Vec3& eye, const std::vector<Vec3>& element_point, const std::vector<Vec3>& red_seen,
                        const std::vector<Vec3>& blue_seen, const std::vector<int8_t>& mask, double min_difference_arcmin) {
  FringeStats s;
  const size_t n = element_point.size();
  if (red_seen.size() != n || blue_seen.size() != n || mask.size() != n) return s;
  std::vector<double> diff;
  size_t more = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    const Vec3 p = element_point[i], in = p - eye;
    const double dev_r = arcminutes(angleBetween(in, red_seen[i] - p)), dev_b = arcminutes(angleBetween(in, blue_seen[i] - p));
    const double d = dev_b - dev_r;
    if (!std::isfinite(d) || std::abs(d) < min_difference_arcmin) continue;
    diff.push_back(d);
    more += d > 0;
  }
  s.pixels = diff.size();
  if (diff.empty()) return s;
  s.median_blue_minus_red_arcmin = quantile(diff, 0.5);
  s.fraction_blue_bends_more = double(more) / double(diff.size());
  return s;
}

}  // namespace pvrr
