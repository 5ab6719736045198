// The viewer's field-of-view overlay (pvrr view, issue 21 item 7): the road footprint of a mirror (pvrr fov's,
// pvrr/analysis/fov.h) drawn over the frame, where that road lies in the current view. O or the panel's checkbox
// turns it on. The footprint is traced once per mirror pose (and per scene build), never per frame; each frame only
// projects its cells. It is drawn on Dear ImGui's background layer: over the frame, under the panel, with no depth
// test (the car's body does not hide it: it is a marking, not a surface), and only in scenes with a `vehicle`.
//
// Eyes: the overlay follows the scene's eye description. With a `vehicle.eye_ellipse` it shows what the driver sees
// from anywhere in the eye ellipse (pvrr fov --eyes ellipse); without one, from the two ocular points (pvrr fov's
// default). The panel's "eye ellipse" checkbox switches between the two where the scene has an ellipse.
//
// Ocular points: the footprint's ray grid (kOverlaySamples^2 rays per ocular point); a cell is drawn when its four
// rays meet the road (within the footprint's horizon_m), in the eye's colour (left blue, right orange), purple when
// a corner's ray is obstructed. Cells with a vertex behind the observer (or nearer than 1 cm) are not drawn.
//
// Eye ellipse: per eye, the union of its samples' footprints (pvrr/analysis/fov_eyes.h: 15 samples an eye, each
// traced at kOverlaySamples^2 rays), the same polygon pvrr fov --eyes ellipse --samples 41 writes as
// footprint.<eye>.polygon, filled in the eye's colour (obstruction is not shown: the polygon is the image of the
// mirror's outline). It is cut into triangles on the road (ear clipping), each clipped at 1 cm in front of the
// observer before it is projected, so the part of the road in view is drawn even where the footprint runs behind
// the observer. Where an eye's union is not one simple loop, each of its samples' polygons is filled instead.
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
  // The eye ellipse (when the scene has one): -1 follow the scene, 0 ocular points, 1 eye ellipse (the panel).
  int ellipse_choice_ = -1;
  bool ellipse_ = false;      // what the last trace used
  bool has_ellipse_ = false;  // whether the scene traced has an eye ellipse
  int eye_samples_ = 0;   // eye positions traced (2 for the ocular points)
  int traces_ = 0;
  int build_ = -1, asked_ = -2, element_ = -1;  // the scene build and element traced for; the mirror used
  bool asked_ellipse_ = false;                  // whether the eye ellipse was asked for (scene and checkbox)
  Mat4 pose_{0.0};
  std::string why_;  // why nothing is drawn (no vehicle, no mirror)
  struct Cell {
    Vec3 world[4];
    bool left, obstructed;
  };
  std::vector<Cell> cells_;
  struct Triangle {
    Vec3 world[3];
    bool left;
  };
  std::vector<Triangle> triangles_;  // the eye ellipse's footprints, on the road
  bool per_sample_ = false;          // an eye's union was not one simple loop: its samples' polygons are filled
  int drawn_ = 0;                    // cells (or triangles) drawn in the last frame
};

}  // namespace pvrr::app::view
