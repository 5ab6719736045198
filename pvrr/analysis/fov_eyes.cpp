#include "pvrr/analysis/fov_eyes.h"

#include <algorithm>
#include <cmath>

namespace pvrr {

namespace {
// Samples of one eye closer than this are one sample.
constexpr double kSameSample_m = 1e-12;
// Loops of a union smaller than this share of its largest are slivers, dropped: two samples' footprints reach the
// horizon (placed horizon_m away) along nearly the same arcs, and their crossings there cut slivers of ~1e-6 of the
// footprint's area.
constexpr double kSliverArea = 1e-5;
}  // namespace

std::vector<EyeSample> eyeEllipseSamples(const VehicleFrame& frame, const VehicleDesc::EyeEllipse& e, double scale) {
  std::vector<Vec3> unit = {Vec3(0)};
  for (int axis = 0; axis < 3; ++axis)
    for (const double s : {1.0, -1.0}) {
      Vec3 u(0);
      u[axis] = s;
      unit.push_back(u);
    }
  const double c = 1 / std::sqrt(3.0);
  for (const double x : {c, -c})
    for (const double y : {c, -c})
      for (const double z : {c, -c}) unit.push_back(Vec3(x, y, z));
  const double t = e.tilt_deg * kPi / 180;
  const Vec3 half = 0.5 * scale * e.axes_m;
  std::vector<EyeSample> out;
  for (const bool left : {true, false}) {
    const Vec3 centre = frame.eye(left);
    const size_t first = out.size();
    for (const Vec3& u : unit) {
      const Vec3 d = u * half;  // in the ellipsoid's axes
      // The x axis turned about y by t, its forward end down: (1, 0, 0) -> (cos t, 0, -sin t).
      const Vec3 v(d.x * std::cos(t) + d.z * std::sin(t), d.y, -d.x * std::sin(t) + d.z * std::cos(t));
      const Vec3 w = frame.toWorld(centre + v);
      bool same = false;
      for (size_t k = first; k < out.size(); ++k) same = same || glm::length(out[k].world - w) < kSameSample_m;
      if (!same) out.push_back({left ? "left" : "right", w, u});
    }
  }
  return out;
}

double signedArea(const std::vector<Vec2>& p) {
  double a = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec2 q = p[(i + 1) % p.size()];
    a += p[i].x * q.y - p[i].y * q.x;
  }
  return 0.5 * a;
}

std::vector<Vec2> unionOfPolygons(const std::vector<std::vector<Vec2>>& polys) {
  if (polys.empty()) return {};
  std::vector<Vec2> acc = polys.front();
  for (size_t i = 1; i < polys.size(); ++i) {
    const std::vector<std::vector<Vec2>> loops = polygonUnion(acc, polys[i]);
    double largest = 0;
    for (const std::vector<Vec2>& l : loops) largest = std::max(largest, std::abs(signedArea(l)));
    std::vector<const std::vector<Vec2>*> kept;
    for (const std::vector<Vec2>& l : loops)
      if (std::abs(signedArea(l)) > kSliverArea * largest) kept.push_back(&l);
    if (kept.size() != 1 || signedArea(*kept.front()) <= 0) return {};
    acc = *kept.front();
  }
  return acc;
}

}  // namespace pvrr
