#include "pvrr/trace/shadow_rays.h"

#include <cmath>

namespace pvrr {

namespace {

// A segment that crosses more surfaces than this (a stack of lenses) is taken as blocked.
constexpr int kMaxCrossings = 16;

}  // namespace

double lensShadowTransmittance(const Element& lens) {
  const double n = lens.dispersion.index(kLineD_nm);
  const double r0 = ((n - 1.0) / (n + 1.0)) * ((n - 1.0) / (n + 1.0));
  return (1.0 - r0) * (1.0 - r0);
}

Vec3 lensShadowPassed(const Element& lens) {
  const Vec3 fresnel(lensShadowTransmittance(lens));
  return lens.absorbing() ? fresnel * lens.internalTransmittance(lens.shadow_path_m) : fresnel;
}

Vec3 ShadowRays::transmittance(const Light& l, const Vec3& p) const {
  if (!l.shadows || l.type == Light::Type::Ambient) return Vec3(1.0);
  Vec3 d;
  double t_max = kInf;
  if (l.type == Light::Type::Directional) {
    d = -l.direction;
  } else {
    const Vec3 to = l.position - p;
    t_max = glm::length(to);
    if (!(t_max > 0)) return Vec3(1.0);
    d = to / t_max;
  }
  const Scene& scene = rays_.scene();
  double t_min = rays_.epsilon();
  Vec3 passed(1.0);
  for (int crossing = 0; crossing < kMaxCrossings; ++crossing) {
    const RayHit hit = rays_.intersect(p, d, t_min, t_max);
    if (!hit.hit()) return passed;
    if (hit.kind == HitKind::Environment) return Vec3(0.0);
    const Element& el = scene.elements[size_t(hit.element)];
    if (el.type == ElementType::Mirror || (caustic_lights_block_ && l.caustics)) return Vec3(0.0);
    passed *= glm::sqrt(lensShadowPassed(el));  // one interface: 1 - R0 (and half the glass's absorption)
    t_min = hit.t + rays_.epsilon();
  }
  return Vec3(0.0);
}

}  // namespace pvrr
