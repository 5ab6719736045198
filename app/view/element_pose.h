// Turning (or moving) a mirror or lens in the viewer like a powered mirror: about its vertex (pose.position, the
// pivot), yaw about its local +y, then pitch about its local +x (docs/scene-format.md "Element frame": local +z is
// pose.normal, local +y follows pose.up). The turned pose is written as --set overrides of the element's
// pose.normal and pose.up, so that the scene rebuilt from them, and a saved view, hold it exactly.
#pragma once
#include <string>
#include <vector>

#include "pvrr/base/math.h"

namespace pvrr::app::view {

struct TurnedPose {
  Vec3 normal{0, 0, 1}, up{0, 1, 0};  // unit; up is orthogonal to normal
};

// `normal` and `up` (a hint, not parallel to normal) turned by `yaw_rad` (positive turns the normal towards the
// element's local +x = up x normal) and then `pitch_rad` (positive tilts it towards its local +y, up).
TurnedPose turnElementPose(const Vec3& normal, const Vec3& up, double yaw_rad, double pitch_rad);

// `position` moved by `by_m` in the element's frame (x = up x normal, y = up orthogonalised, z = normal).
Vec3 movedElementPosition(const Vec3& position, const Vec3& normal, const Vec3& up, const Vec3& by_m);
// "elements[I].pose.position=[x,y,z]" in the scene file's unit (`unit_m` metres per unit), at full double precision.
std::string positionOverride(int element, const Vec3& position_m, double unit_m);

// "elements[I].pose.normal=[x,y,z]" and "elements[I].pose.up=[x,y,z]", at full double precision.
std::vector<std::string> poseOverrides(int element, const TurnedPose& pose);

}  // namespace pvrr::app::view
