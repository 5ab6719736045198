#include "app/view/head.h"

#include <algorithm>
#include <glm/gtc/matrix_transform.hpp>

namespace pvrr::app::view {

Observer headObserver(const Observer& design, const HeadPose& pose) {
  Observer ob = design;
  const Vec3 forward = design.target - design.eye;
  const Vec3 right = glm::normalize(glm::cross(forward, design.up));
  const Mat4 turn = glm::rotate(Mat4(1.0), pose.yaw_rad, design.up) * glm::rotate(Mat4(1.0), pose.pitch_rad, right);
  ob.eye = design.eye + pose.eye_offset_m;
  ob.target = ob.eye + Vec3(turn * Vec4(forward, 0.0));
  return ob;
}

void turnHead(HeadPose& pose, double yaw_rad, double pitch_rad) {
  pose.yaw_rad += yaw_rad;
  const double max_pitch = radians(kMaxPitchDeg);
  pose.pitch_rad = std::clamp(pose.pitch_rad + pitch_rad, -max_pitch, max_pitch);
}

void moveEye(HeadPose& pose, const Observer& design, const Vec3& by_m) {
  const Observer ob = headObserver(design, pose);
  const Vec3 forward = glm::normalize(ob.target - ob.eye);
  const Vec3 right = glm::normalize(glm::cross(forward, ob.up));
  const Vec3 up = glm::cross(right, forward);
  pose.eye_offset_m += right * by_m.x + up * by_m.y - forward * by_m.z;
}

}  // namespace pvrr::app::view
