#include "pvrr/trace/specular.h"

#include "pvrr/optics/optics.h"
#include "pvrr/optics/spectrum.h"

namespace pvrr {

SpecularEvent specularEvent(const Element& el, const RayHit& hit, const Vec3& d, int inside, double n_glass,
                            bool metal_spectral, double wavelength_nm) {
  SpecularEvent e;
  e.inside = inside;
  const double cos_i = -glm::dot(d, hit.normal);
  if (el.type == ElementType::Mirror) {
    if (cos_i <= 0) {
      e.kind = SpecularKind::MirrorBack;
      return e;
    }
    Vec3 refl = el.mirror.reflectance;
    if (el.mirror.metal) {
      if (metal_spectral && el.mirror.metal_table) {
        const ComplexIndex nk = el.mirror.metal_table->index(wavelength_nm > 0 ? wavelength_nm : kLineD_nm);
        refl = Vec3(fresnelConductor(cos_i, 1.0, nk.n, nk.k));
      } else {
        for (int c = 0; c < 3; ++c) refl[c] = fresnelConductor(cos_i, 1.0, el.mirror.n[c], el.mirror.k[c]);
      }
    }
    e.factor = refl;
    e.direction = reflect(d, hit.normal);
    return e;
  }
  const bool entering = inside < 0;
  e.n1 = entering ? 1.0 : n_glass;
  e.n2 = entering ? n_glass : 1.0;
  const Refraction rf = refract(d, hit.normal, e.n1, e.n2);
  if (rf.tir) {
    e.kind = SpecularKind::TotalInternal;
    e.direction = reflect(d, hit.normal);
    return e;
  }
  e.kind = SpecularKind::Refract;
  e.factor = Vec3(1.0 - fresnelDielectric(std::abs(cos_i), e.n1, e.n2));
  e.direction = rf.direction;
  e.inside = entering ? hit.element : -1;
  return e;
}

RayHit hitInsideLens(const RayScene& rays, int inside, const Vec3& o, const Vec3& d, double t_min) {
  const RayHit back = rays.intersectElementSurface(inside, 1, o, d, t_min);
  const RayHit front = rays.intersectElementSurface(inside, 0, o, d, t_min);
  return back.t <= front.t ? back : front;
}

}  // namespace pvrr
