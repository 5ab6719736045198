// One specular event at an optical element, shared by the reference tracer (tracer.cpp: eye paths) and the
// light tracer (light_tracer.cpp: photons), in the conventions of pvrr/optics/optics.h: a mirror reflects with
// its reflectance (a metal's conductor Fresnel reflectance per channel, or, spectral, its table's at the
// wavelength); a lens interface refracts with the exact unpolarised Fresnel transmittance 1 - R, or reflects
// totally (TIR: no loss). What each caller does at a mirror's back (shade it dark, absorb) stays its own.
#pragma once
#include "pvrr/scene/scene.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr {

enum class SpecularKind { Reflect, Refract, TotalInternal, MirrorBack };

struct SpecularEvent {
  SpecularKind kind = SpecularKind::Reflect;
  Vec3 direction{0};      // the next direction (unit; not set at a mirror's back)
  Vec3 factor{1.0};       // the throughput's factor: the reflectance, or the interface's transmittance
  int inside = -1;        // the lens the ray is inside after the event, or -1
  double n1 = 1, n2 = 1;  // a lens interface's indices, incident and transmitted
};

// The event at `hit` (on element el) of a ray with unit direction d, inside lens `inside` (or -1) before it.
// n_glass: the lens's index at the ray's wavelength (the caller's rule); metal_spectral: a named metal reflects
// with its table at wavelength_nm (0: the d line).
SpecularEvent specularEvent(const Element& el, const RayHit& hit, const Vec3& d, int inside, double n_glass,
                            bool metal_spectral, double wavelength_nm);

// The next hit of a ray inside lens `inside`: the nearer of its own two surfaces; no hit means the ray leaves
// through the lens's edge band, which is not modelled as a surface.
RayHit hitInsideLens(const RayScene& rays, int inside, const Vec3& o, const Vec3& d, double t_min);

}  // namespace pvrr
