#include "app/view/lens_probe.h"

#include <algorithm>
#include <cmath>

namespace pvrr::app::view {

LensProbe probeLens(const Scene& scene, const RayScene& rays, int x, int y, LensmapCache* cache) {
  LensProbe p;
  p.px = x + 0.5;
  p.py = y + 0.5;
  const Observer& ob = scene.observer;
  if (x < 0 || y < 0 || x >= ob.width || y >= ob.height) {
    p.reason = "outside the picture";
    return p;
  }
  const RayHit hit = rays.intersect(ob.eye, glm::normalize(ob.pixelDirection(p.px, p.py)));
  if (hit.kind != HitKind::Element || scene.elements[size_t(hit.element)].type != ElementType::Lens) {
    p.reason = "no lens under the cursor";
    return p;
  }
  p.element = hit.element;
  if (hit.surface != 0) {
    p.reason = "the lens is seen from its object side";
    return p;
  }
  const Element& el = scene.elements[size_t(hit.element)];
  LensmapOptions o;
  o.rotation_centre_m = el.eye_rotation_centre_m;
  LensmapCache local;
  LensmapCache& c = cache ? *cache : local;
  if (!c.map || c.element != hit.element || c.local_to_world != el.local_to_world) {
    c.map = std::make_unique<Lensmap>(rays, hit.element, o);
    c.element = hit.element;
    c.local_to_world = el.local_to_world;
    c.centre = c.map->evaluate(0, 0);
    ++c.builds;
  }
  const Lensmap& map = *c.map;
  // The gaze through p from the centre of rotation (0, 0, r) of the lens frame, as Fick angles
  // (pvrr/analysis/lensmap.h: g = (cos gy sin gx, sin gy, -cos gy cos gx)).
  p.lens_point_local = el.toLocalPoint(hit.point);
  const Vec3 g = glm::normalize(p.lens_point_local - Vec3(0, 0, o.rotation_centre_m));
  const double gaze_y = std::asin(std::clamp(g.y, -1.0, 1.0)), gaze_x = std::atan2(g.x, -g.z);
  p.reading = map.evaluate(degrees(gaze_x), degrees(gaze_y), c.centre.valid ? &c.centre : nullptr);
  p.valid = p.reading.valid;
  if (!p.valid) p.reason = p.reading.reason;
  return p;
}

}  // namespace pvrr::app::view
