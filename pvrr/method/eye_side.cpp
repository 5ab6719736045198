#include "pvrr/method/eye_side.h"

#include <algorithm>
#include <cmath>

#include "pvrr/method/vertex_stage.h"

namespace pvrr {

EyeSide eyeSide(const ElementFrame& f) {
  EyeSide s;
  for (size_t i = 0; i < f.world_pos.size() && i < f.world_normal.size(); ++i) {
    if (!f.in_view.empty() && f.in_view[i] != 2) continue;
    ++s.seen;
    s.back += glm::dot(f.eye - f.world_pos[i], f.world_normal[i]) < 0;
  }
  return s;
}

std::string eyeSideNote(const Scene& scene, const ElementFrame& f) {
  const EyeSide s = eyeSide(f);
  if (s.back == 0) return "";
  const Element& el = scene.elements[size_t(f.element)];
  const bool mirror = el.type == ElementType::Mirror;
  const std::string who = std::string(mirror ? "mirror '" : "lens '") + el.name + "'";
  if (s.back == s.seen)
    return mirror ? "the eye is behind " + who +
                        " (its back side faces the eye): nothing is reflected toward it; it is drawn as its dark back, "
                        "as the reference draws it"
                  : "the eye is behind " + who + " (its back surface faces the eye)";
  const std::string share = std::to_string(s.back) + " of " + std::to_string(s.seen) + " seen vertices";
  return mirror ? "the eye sees the back side of " + who + " at " + share +
                      " (the eye is near the mirror's plane or the mirror curves around it): those parts are drawn "
                      "as its dark back, as the reference draws them"
                : "the eye sees " + who + " from behind its front surface at " + share;
}

bool lensSeenFromBehind(const Element& el, const ElementFrame& f, size_t i) {
  return el.type == ElementType::Lens && i < f.world_normal.size() &&
         glm::dot(f.eye - f.world_pos[i], f.world_normal[i]) < 0;
}

void applyEyeSide(const Scene& scene, ElementFrame& f) {
  if (f.eye != scene.observer.eye) return;
  f.quality.note = eyeSideNote(scene, f);
  const Element& el = scene.elements[size_t(f.element)];
  if (el.type != ElementType::Lens || f.quality.note.empty()) return;
  f.quality.note +=
      ": pvrr mode's vertex rays enter a lens through its front surface, so the patches seen from "
      "behind are drawn from the reference tracer's colours at their vertices";
  int marked = 0;
  for (PatchView& pv : f.views) {
    if (!pv.in_view) continue;
    int back = 0;
    for (uint32_t vi : f.grid_patches[size_t(pv.patch)].vertices)
      back += (f.in_view.empty() || f.in_view[vi] == 2) && lensSeenFromBehind(el, f, vi);
    if (back == 0) continue;
    pv.quality.verdict = QualityVerdict::kFallback;
    pv.quality.reasons += std::string(pv.quality.reasons.empty() ? "" : "; ") +
                          "the eye is behind the lens's front surface at " + std::to_string(back) + " seen vertices";
    pv.quality.action = "flagged";
    ++marked;
  }
  f.quality.verdict = std::max(f.quality.verdict, QualityVerdict::kFallback);
  f.quality.action = (f.quality.action == "none" ? "" : f.quality.action + "; ") + std::to_string(marked) +
                     " patch(es) seen from behind the lens";
}

}  // namespace pvrr
