#include "pvrr/trace/shadow_rays.h"

#include <cmath>
#include <optional>

#include "cad/lens_chord.h"

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
    t_min = hit.t + rays_.epsilon();
    if (!el.absorbing()) {
      passed *= glm::sqrt(lensShadowPassed(el));  // one interface: 1 - R0
      continue;
    }
    // A tinted lens: both interfaces and the glass along the chord, to where the segment crosses the other
    // surface (its exact hit), else out through the edge (cad::chordInside in the lens's frame).
    const RayHit out = rays_.intersectElementSurface(hit.element, 1 - hit.surface, p, d, t_min, t_max);
    if (out.hit()) {
      passed *= lensShadowTransmittance(el) * el.internalTransmittance(out.t - hit.t);
      t_min = out.t + rays_.epsilon();
      continue;
    }
    const Vec3 local_p = Vec3(el.world_to_local * Vec4(hit.point, 1.0));
    const Vec3 local_d = Mat3(el.world_to_local) * d;
    const std::optional<cad::LensChord> chord = cad::chordInside(el.lens, hit.surface, local_p, local_d);
    if (chord && chord->through_edge)
      passed *= lensShadowTransmittance(el) * el.internalTransmittance(chord->length_m);
    else
      passed *= glm::sqrt(lensShadowPassed(el));  // grazing: one interface and half the mean thickness's glass
  }
  return Vec3(0.0);
}

}  // namespace pvrr
