#include "pvrr/scene/animation.h"

#include <algorithm>

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

}  // namespace pvrr
