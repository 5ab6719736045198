#include "app/view/element_pose.h"

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

namespace pvrr::app::view {

TurnedPose turnElementPose(const Vec3& normal, const Vec3& up, double yaw_rad, double pitch_rad) {
  const Vec3 z = glm::normalize(normal);
  const Vec3 y = glm::normalize(up - glm::dot(up, z) * z);
  const Vec3 x = glm::cross(y, z);
  // Yaw about y takes z towards x; pitch about the turned x by -pitch takes z towards y.
  const Mat4 yaw = glm::rotate(Mat4(1.0), yaw_rad, y);
  const Vec3 x1 = Vec3(yaw * Vec4(x, 0.0)), z1 = Vec3(yaw * Vec4(z, 0.0));
  const Mat4 pitch = glm::rotate(Mat4(1.0), -pitch_rad, x1);
  TurnedPose p;
  p.normal = glm::normalize(Vec3(pitch * Vec4(z1, 0.0)));
  p.up = glm::normalize(Vec3(pitch * Vec4(y, 0.0)));
  return p;
}

Vec3 movedElementPosition(const Vec3& position, const Vec3& normal, const Vec3& up, const Vec3& by_m) {
  const Vec3 z = glm::normalize(normal);
  const Vec3 y = glm::normalize(up - glm::dot(up, z) * z);
  const Vec3 x = glm::cross(y, z);
  return position + by_m.x * x + by_m.y * y + by_m.z * z;
}

std::string positionOverride(int element, const Vec3& position_m, double unit_m) {
  const Vec3 p = position_m / unit_m;
  return "elements[" + std::to_string(element) + "].pose.position=" + nlohmann::json::array({p.x, p.y, p.z}).dump();
}

std::vector<std::string> poseOverrides(int element, const TurnedPose& pose) {
  const auto text = [](const Vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}).dump(); };
  const std::string at = "elements[" + std::to_string(element) + "].pose.";
  return {at + "normal=" + text(pose.normal), at + "up=" + text(pose.up)};
}

}  // namespace pvrr::app::view
