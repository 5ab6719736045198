#include "pvrr/method/refine_plan.h"

#include "pvrr/method/pass_plan.h"

namespace pvrr {

std::string refineSkipReason(const Scene& scene, const ElementFrame& f, int steps) {
  if (steps <= 0) return "off";
  const Element& el = scene.elements[size_t(f.element)];
  // A lens refines each channel of its one draw (up to three); more are drawn in additive sets of three.
  if (el.type == ElementType::Lens && f.rays.size() > 3) return "more than three channels (additive sets)";
  if (el.type != ElementType::Lens && f.rays.size() != 1) return "more than one channel";
  if (beyondDepth(scene, f)) return "drawn dark at the depth limit";
  std::string reason;
  for (const PatchView& pv : f.views) {
    const std::string why = refineViewSkipReason(pv);
    if (why.empty()) return "";
    if (reason.empty()) reason = why;
  }
  return f.views.size() > 1 ? "every patch view skipped (first: " + reason + ")" : reason;
}

std::string refineViewSkipReason(const PatchView& pv) {
  if (pv.draw_traced) return "drawn from traced colours";
  if (pv.fit.max_angle_rad <= kExactFitRad) return "the vertex fit is exact (a plane): interpolation is exact";
  return "";
}

}  // namespace pvrr
