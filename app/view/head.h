// The viewer's head and eye: the scene's design observer, turned about the eye (yaw about the observer's up,
// pitch about its right axis, as `pvrr render --orbit` turns it) and moved in the observer frame.
#pragma once
#include "pvrr/scene/scene.h"

namespace pvrr::app::view {

struct HeadPose {
  Vec3 eye_offset_m{0};  // from the design eye, world frame
  double yaw_rad = 0;    // positive turns left (right-handed about the observer's up)
  double pitch_rad = 0;  // positive looks up; kept within +-kMaxPitchDeg of the design view
};
inline constexpr double kMaxPitchDeg = 80;

// The observer `design` seen with `pose`: same up, field of view and image size.
Observer headObserver(const Observer& design, const HeadPose& pose);
// Turns the head by the given angles (pitch clamped).
void turnHead(HeadPose& pose, double yaw_rad, double pitch_rad);
// Moves the eye by `by_m` in the current observer frame of `design` seen with `pose` (x right, y up, -z forward).
void moveEye(HeadPose& pose, const Observer& design, const Vec3& by_m);

}  // namespace pvrr::app::view
