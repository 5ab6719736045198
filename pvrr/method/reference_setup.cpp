#include "pvrr/method/reference_setup.h"

namespace pvrr {

ReferenceSetup::ReferenceSetup(const RayScene& rays) {
  const Scene& scene = rays.scene();
  options_.max_depth = scene.render.max_depth;
  options_.dispersion = scene.render.dispersion;
  options_.spectral_samples = scene.render.spectral_samples;
  CausticPlanOptions po;
  po.dispersion = scene.render.dispersion;
  po.spectral_samples = scene.render.spectral_samples;
  caustics_ = referenceCaustics(rays, po, kReferenceCausticPhotons, stages_);
  if (caustics_) options_.caustics = &*caustics_;
}

}  // namespace pvrr
