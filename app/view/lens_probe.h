// The viewer's lens probe (issue 27 item 5): the readings of pvrr lensmap (pvrr/analysis/lensmap.h) at the lens
// point under the cursor. The pixel's ray from the observer's eye meets the lens's eye-side surface at p; the
// reading is the lens map's at the gaze that looks through p from the eye's centre of rotation (the lens's
// `eye` block; the chief ray of that gaze runs straight from the centre to p), for a distant object, with the
// power error and unwanted cylinder against the lens's centre (gaze 0, 0).
#pragma once
#include <memory>
#include <string>

#include "pvrr/analysis/lensmap.h"
#include "pvrr/scene/scene.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr::app::view {

struct LensProbe {
  bool valid = false;
  std::string reason;     // why not valid: no lens under the pixel, its back surface, or the lens map's reason
  double px = 0, py = 0;  // the pixel's centre (pixel coordinates, origin top-left)
  int element = -1;
  Vec3 lens_point_local{0};  // p in the lens frame (m)
  LensmapPoint reading;      // valid: the lens map at p's gaze
};

// The lens map of the last lens probed and its centre's reading, kept while that lens stands where it stood (its
// local_to_world unchanged) in the same ray scene: building a Lensmap costs far more than evaluating it, and the
// probe follows every mouse move. Clear it (reset()) when the ray scene is rebuilt.
struct LensmapCache {
  int element = -1;
  Mat4 local_to_world{1.0};
  std::unique_ptr<Lensmap> map;
  LensmapPoint centre;
  int builds = 0;  // lens maps built through this cache
  void reset() {
    map.reset();
    element = -1;
  }
};

// The probe at the centre of pixel (x, y) (integer parts of a cursor position) of `scene`'s observer. With a
// cache, its lens map is reused while it fits (LensmapCache).
LensProbe probeLens(const Scene& scene, const RayScene& rays, int x, int y, LensmapCache* cache = nullptr);

}  // namespace pvrr::app::view
