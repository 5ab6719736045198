// The reference's shadow rays (Light::shadows): how much of a directional or point light reaches a point of
// the environment along the straight segment towards the light.
//
// What blocks and what transmits:
// - an environment surface blocks fully;
// - a mirror blocks fully, from the front or the back (the light it reflects elsewhere is a caustic, not
//   modelled here);
// - a lens transmits: each of its interfaces that the segment crosses passes (1 - R0), R0 the Fresnel
//   reflectance at normal incidence at the lens's index at the d line (R0 = ((n - 1) / (n + 1))^2), so a
//   segment through both faces keeps (1 - R0)^2 (lensShadowTransmittance). Normal incidence, not the ray's
//   own angle: the raster path's shadow maps hold one Fresnel factor per lens (shaders/shadow_lookup.glsl),
//   and the two agree by construction. The segment is not bent by the lens (where the light it refracts
//   lands is a caustic). A tinted lens (Element::absorption_per_m) also absorbs, per channel, over the
//   straight chord L the segment runs through its glass (cad::chordInside): to where it crosses the other
//   surface (its exact hit), or out through the edge band near the rim; the lens then passes
//   (1 - R0)^2 exp(-alpha_c L), the edge counted as an interface. The shadow maps hold the same chord per
//   caster vertex (pvrr/gl/shadow_pass.h). Where no chord exists (a segment grazing the surface) the lens
//   passes, per interface crossed, the square root of (1 - R0)^2 exp(-alpha_c shadow_path_m), its mean
//   thickness over the outline (lensShadowPassed).
// - with `caustic_lights_block` (the reference picture with the caustic light added, TraceOptions::caustics):
//   for a light with caustics on (Light::caustics), a lens blocks fully too, as in the raster shadow maps: its
//   light arrives refracted, as the caustic (pvrr/trace/light_tracer.h), not straight through.
// The segment starts at the point itself (t > RayScene::epsilon()) and ends at a point light (t < its
// distance) or never (a directional light).
#pragma once
#include "pvrr/trace/ray_scene.h"

namespace pvrr {

// (1 - R0)^2: what a lens passes of light crossing both its faces near normal incidence.
double lensShadowTransmittance(const Element& lens);
// What the shadow rule passes of a lens per channel where it has no chord: lensShadowTransmittance(lens)
// times the glass's absorption over its mean thickness, exp(-alpha_c shadow_path_m); grey (1 - R0)^2 for a
// clear lens (whose chord does not matter).
Vec3 lensShadowPassed(const Element& lens);

class ShadowRays {
 public:
  explicit ShadowRays(const RayScene& rays, bool caustic_lights_block = false)
      : rays_(rays), caustic_lights_block_(caustic_lights_block) {}
  // The fraction of light `l` that reaches `p`, per channel (grey unless a tinted lens is crossed);
  // 1 for a light with shadows off and for an ambient light.
  Vec3 transmittance(const Light& l, const Vec3& p) const;

 private:
  const RayScene& rays_;
  bool caustic_lights_block_ = false;
};

}  // namespace pvrr
