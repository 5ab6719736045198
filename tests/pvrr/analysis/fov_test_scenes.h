// Shared by the fov tests: a plane door mirror in front of a driver, its vehicle frame, and R46 Class III-like zones.
#pragma once
#include <cmath>
#include <cstdio>
#include <vector>

#include "pvrr/analysis/fov.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr::test {

inline constexpr double kDeg = kPi / 180;

// The door-mirror geometry of fov_test.cpp (x right, y up, the car faces -z; driver's side left), a plane mirror
// of the given size whose normal is the bisector towards the eyes' midpoint and `out`, turned by (yaw, pitch).
inline SceneDesc planeMirrorDesc(double width, double height, double yaw_deg, double pitch_deg,
                                 const char* extra = "") {
  const Vec3 mirror(-0.5, 1.05, -0.35);
  const Vec3 n0 = glm::normalize(glm::normalize(Vec3(0, 1.2, 0) - mirror) + glm::normalize(Vec3(-0.12, -0.1, 1)));
  // Turn the normal: yaw about up (+y), pitch about the horizontal axis in the mirror plane.
  auto rot = [](const Vec3& v, const Vec3& k, double a) {
    return v * std::cos(a) + glm::cross(k, v) * std::sin(a) + k * glm::dot(k, v) * (1 - std::cos(a));
  };
  const Vec3 h = glm::normalize(glm::cross(Vec3(0, 1, 0), n0));
  const Vec3 n = rot(rot(n0, h, pitch_deg * kDeg), Vec3(0, 1, 0), yaw_deg * kDeg);
  char buf[4096];
  std::snprintf(buf, sizeof buf, R"({"version": 1,
    "observer": {"eye": [0, 1.2, 0], "target": [-0.5, 1.05, -0.35]},
    "elements": [{"name": "m", "type": "mirror",
      "pose": {"position": [-0.5, 1.05, -0.35], "normal": [%.17g, %.17g, %.17g], "up": [0, 1, 0]},
      "surface": {"type": "plane"}, "outline": {"shape": "rectangle", "width": %.17g, "height": %.17g}%s}],
    "vehicle": {"forward": [0, 0, -1], "up": [0, 1, 0], "road_height": 0,
      "outermost": {"left": [-0.45, 1, 0], "right": [1.35, 1, 0]},
      "ocular_points": {"left": [-0.0325, 1.2, 0], "right": [0.0325, 1.2, 0]},
      "driver_side": "left"}})",
                n.x, n.y, n.z, width, height, extra);
  return parseScene(buf, "test.json", ".");
}

// The same as a built scene.
inline Scene planeMirror(double width, double height, double yaw_deg, double pitch_deg, const char* extra = "") {
  return buildScene(planeMirrorDesc(width, height, yaw_deg, pitch_deg, extra));
}

inline VehicleFrame frameOf(const Scene&) {
  VehicleDesc v;
  v.forward = Vec3(0, 0, -1);
  v.up = Vec3(0, 1, 0);
  v.outermost_left = Vec3(-0.45, 1, 0);
  v.outermost_right = Vec3(1.35, 1, 0);
  v.eye_left = Vec3(-0.0325, 1.2, 0);
  v.eye_right = Vec3(0.0325, 1.2, 0);
  return VehicleFrame(v);
}

// R46 Class III's two driver-side strips as models/regulations/r46-class-iii.json has them (4 m wide from 20 m
// behind, 1 m wide from 4 m behind, both to the horizon, 10 % obstruction allowed, either eye).
inline std::vector<FovZone> classIII() {
  std::vector<FovZone> z(2);
  z[0].name = "4 m from 20 m";
  z[0].polygon = {Vec2(-20, 0), Vec2(-20, 4), Vec2(-kInf, 4), Vec2(-kInf, 0)};
  z[1].name = "1 m from 4 m";
  z[1].polygon = {Vec2(-4, 0), Vec2(-4, 1), Vec2(-kInf, 1), Vec2(-kInf, 0)};
  for (FovZone& f : z) f.allowed_obstructed_fraction = 0.1;
  return z;
}

}  // namespace pvrr::test
