// The viewer's field-of-view overlay (pvrr view, issue 21 item 7): the road footprint of a mirror (pvrr fov's,
// pvrr/analysis/fov.h) drawn over the frame, where that road lies in the current view. O or the panel's checkbox
// turns it on. The footprint is traced once per mirror pose (and per scene build), never per frame; each frame only
// projects its cells. It is drawn on Dear ImGui's background layer: over the frame, under the panel, with no depth
// test (the car's body does not hide it: it is a marking, not a surface), and only in scenes with a `vehicle`.
//
// Cells: the footprint's ray grid (kOverlaySamples^2 rays per ocular point); a cell is drawn when its four rays meet
// the road (within the footprint's horizon_m), in the eye's colour (left blue, right orange), purple when a corner's
// ray is obstructed. Cells with a vertex behind the observer (or nearer than 1 cm) are not drawn.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pvrr/analysis/fov.h"

namespace pvrr::app::view {

inline constexpr int kOverlaySamples = 41;

class FovOverlay {
 public:
  void toggle() { on_ = !on_; }
  // The panel's checkbox (with what it shows, or why nothing).
  void panel();
  // Traces the footprint again when the mirror's pose or the scene build changed, then draws it (when on) for
  // observer `ob`. `element`: the viewer's selected element (else the first mirror is used).
  void draw(const Scene& scene, const SceneDesc& desc, const RayScene& rays, int element, int scene_build,
            const Observer& ob);
  nlohmann::json stats() const;

 private:
  void trace(const Scene& scene, const SceneDesc& desc, const RayScene& rays, int element);

  bool on_ = false;
  bool traced_ = false;
  int traces_ = 0;
  int build_ = -1, asked_ = -2, element_ = -1;  // the scene build and element traced for; the mirror used
  Mat4 pose_{0.0};
  std::string why_;  // why nothing is drawn (no vehicle, no mirror)
  struct Cell {
    Vec3 world[4];
    bool left, obstructed;
  };
  std::vector<Cell> cells_;
  int drawn_ = 0;  // cells drawn in the last frame
};

}  // namespace pvrr::app::view
