#include "pvrr/scene/animation.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "pvrr/base/error.h"

namespace pvrr {

double interpolationWeight(Interpolation i, double s) {
  s = std::clamp(s, 0.0, 1.0);
  return i == Interpolation::Smooth ? s * s * (3.0 - 2.0 * s) : s;
}

Keyframe sampleAnimation(const AnimationDesc& a, double t_s) {
  PVRR_CHECK(!a.keys.empty(), "(an animation without keys)");
  const std::vector<Keyframe>& k = a.keys;
  if (!(t_s > k.front().time_s)) return {t_s, k.front().offset_m, k.front().rotation_deg};
  if (t_s >= k.back().time_s) return {t_s, k.back().offset_m, k.back().rotation_deg};
  // The first key after t: t lies in [k[i - 1], k[i]).
  const size_t i =
      size_t(std::upper_bound(k.begin(), k.end(), t_s, [](double t, const Keyframe& key) { return t < key.time_s; }) -
             k.begin());
  const Keyframe &a0 = k[i - 1], &a1 = k[i];
  const double w = interpolationWeight(a.interpolation, (t_s - a0.time_s) / (a1.time_s - a0.time_s));
  return {t_s, a0.offset_m + w * (a1.offset_m - a0.offset_m),
          a0.rotation_deg + w * (a1.rotation_deg - a0.rotation_deg)};
}

Mat3 rotationFromDeg(const Vec3& deg) {
  const auto about = [](const Vec3& axis, double angle_deg) {
    return Mat3(glm::rotate(Mat4(1.0), radians(angle_deg), axis));
  };
  return about(Vec3(0, 0, 1), deg.z) * about(Vec3(0, 1, 0), deg.y) * about(Vec3(1, 0, 0), deg.x);
}

Mat4 motionAt(const AnimationDesc& a, const Vec3& pivot, double t_s) {
  const Keyframe s = sampleAnimation(a, t_s);
  Mat4 m(rotationFromDeg(s.rotation_deg));
  m[3] = Vec4(pivot + s.offset_m - Mat3(m) * pivot, 1.0);
  return m;
}

SweepSamples sweepSamples(const AnimationDesc& a) {
  SweepSamples out;
  const std::vector<Keyframe>& k = a.keys;
  if (!k.empty()) out.times_s.push_back(k.front().time_s);
  for (size_t i = 1; i < k.size(); ++i) {
    const Vec3 turn = glm::abs(k[i].rotation_deg - k[i - 1].rotation_deg);
    const double turn_deg = turn.x + turn.y + turn.z;
    const int steps = std::clamp(int(std::ceil(turn_deg / kSweepStepDeg)), 1, kMaxSweepSteps);
    // Equal steps of the interpolation weight (both weights are monotonic in time): the angles and the
    // offset change by a fixed share of the interval's change per step.
    for (int j = 1; j <= steps; ++j) {
      const double w = double(j) / steps;
      // The time whose weight is w: linear w; smooth inverts 3 s^2 - 2 s^3 by bisection.
      double lo = 0, hi = 1;
      for (int it = 0; it < 60 && a.interpolation == Interpolation::Smooth; ++it)
        (interpolationWeight(a.interpolation, 0.5 * (lo + hi)) < w ? lo : hi) = 0.5 * (lo + hi);
      const double s = a.interpolation == Interpolation::Smooth ? 0.5 * (lo + hi) : w;
      out.times_s.push_back(j == steps ? k[i].time_s : k[i - 1].time_s + s * (k[i].time_s - k[i - 1].time_s));
    }
    out.max_step_rad = std::max(out.max_step_rad, radians(turn_deg) / steps);
  }
  return out;
}

}  // namespace pvrr
