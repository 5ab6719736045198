// The scene file's `vehicle` section (docs/scene-format.md "vehicle"), read for pvrr fov.
#include <algorithm>
#include <cmath>

#include "pvrr/scene/scene_json_read.h"

namespace pvrr::scene_json_detail {

// The vehicle frame (pvrr fov). Checked here: up and forward perpendicular, the ocular points and outermost
// points above the road, each left point to the left of its right one, obstructions naming environment objects.
VehicleDesc readVehicle(const Ctx& c, const json* j, const std::vector<EnvObjectDesc>& environment) {
  Obj o(c, j, "vehicle",
        "an object {\"forward\", \"up\", \"road_height\", \"outermost\", \"ocular_points\" or \"seat_reference\", "
        "\"eye_ellipse\", \"driver_side\", \"obstructions\", \"regulations\"}",
        {"forward", "up", "road_height", "outermost", "ocular_points", "seat_reference", "eye_ellipse", "driver_side",
         "obstructions", "regulations"});
  VehicleDesc v;
  v.up = o.vec3("up", VecKind::Direction);
  v.forward = o.vec3("forward", VecKind::Direction);
  if (std::abs(glm::dot(v.up, v.forward)) > std::sin(radians(0.1)))
    o.expected("forward", "a direction perpendicular to vehicle.up (within 0.1 deg)");
  v.forward = glm::normalize(v.forward - glm::dot(v.forward, v.up) * v.up);
  v.road_height_m = o.length("road_height", kAny, 0);
  const Vec3 left = glm::cross(v.up, v.forward);
  auto pair = [&](const std::string& key, Vec3& l, Vec3& r) {
    Obj p(c, o.get(key), o.at(key), "an object {\"left\": [x, y, z], \"right\": [x, y, z]}", {"left", "right"});
    l = p.point("left");
    r = p.point("right");
    for (const auto& [side, q] : {std::pair<const char*, Vec3>{"left", l}, {"right", r}})
      if (glm::dot(q, v.up) - v.road_height_m <= 0) p.expected(side, "a point above the road (vehicle.road_height)");
    if (glm::dot(l - r, left) <= 0)
      p.expected("left", "a point to the left of " + p.at("right") + " (seen facing vehicle.forward)");
  };
  pair("outermost", v.outermost_left, v.outermost_right);
  if (o.has("ocular_points") == o.has("seat_reference"))
    c.fail(o.path(), "expected exactly one of \"ocular_points\" and \"seat_reference\"");
  if (o.has("ocular_points")) {
    pair("ocular_points", v.eye_left, v.eye_right);
  } else {
    // The ocular points from the seat reference point R (VehicleDesc::SeatReference).
    Obj r(c, o.get("seat_reference"), o.at("seat_reference"),
          "an object {\"point\": [x, y, z], \"eye_height\", \"eye_separation\"}",
          {"point", "eye_height", "eye_separation"});
    VehicleDesc::SeatReference seat;
    seat.point = r.point("point");
    if (glm::dot(seat.point, v.up) - v.road_height_m <= 0)
      r.expected("point", "a point above the road (vehicle.road_height)");
    seat.eye_height_m = r.length("eye_height", kPositive, seat.eye_height_m);
    seat.eye_separation_m = r.length("eye_separation", kPositive, seat.eye_separation_m);
    const Vec3 mid = seat.point + seat.eye_height_m * v.up;
    v.eye_left = mid + 0.5 * seat.eye_separation_m * left;
    v.eye_right = mid - 0.5 * seat.eye_separation_m * left;
    v.seat_reference = seat;
  }
  if (o.has("eye_ellipse")) {
    Obj e(c, o.get("eye_ellipse"), o.at("eye_ellipse"), "an object {\"axes\": [forward, left, up], \"tilt_deg\"}",
          {"axes", "tilt_deg"});
    VehicleDesc::EyeEllipse ell;
    ell.axes_m = e.point("axes");  // three finite lengths, in the file's unit
    if (!(ell.axes_m.x >= 0 && ell.axes_m.y >= 0 && ell.axes_m.z >= 0))
      e.expected("axes", "three lengths >= 0 (the ellipsoid's full axes along forward, left and up)");
    ell.tilt_deg = e.number("tilt_deg", closed(-45, 45), 0.0, "an angle (degrees)");
    v.eye_ellipse = ell;
  }
  v.driver_side = o.choice<VehicleDesc::Side>("driver_side");
  if (const json* obs =
          arrayAt(c, o.get("obstructions"), o.at("obstructions"), "an array of environment object names")) {
    std::vector<std::string> names;
    for (const EnvObjectDesc& e : environment) names.push_back(e.name);
    for (size_t i = 0; i < obs->size(); ++i) {
      const json& n = (*obs)[i];
      const std::string path = indexPath(o.at("obstructions"), i);
      if (!n.is_string() || std::find(names.begin(), names.end(), n.get<std::string>()) == names.end()) {
        const std::string near = n.is_string() ? nearest(n.get<std::string>(), names) : "";
        c.fail(path, "expected the name of an environment object, got " + show(&n) +
                         (near.empty() ? "" : "; did you mean " + inQuotes(near) + "?"));
      }
      v.obstructions.push_back(n.get<std::string>());
    }
  } else {
    for (const EnvObjectDesc& e : environment)
      if (e.type != EnvObjectDesc::Type::Ground) v.obstructions.push_back(e.name);
  }
  if (const json* regs = arrayAt(c, o.get("regulations"), o.at("regulations"), "an array of regulation ids"))
    for (size_t i = 0; i < regs->size(); ++i) {
      if (!(*regs)[i].is_string() || (*regs)[i].get<std::string>().empty())
        c.expected(indexPath(o.at("regulations"), i), "a regulation id (a string)", &(*regs)[i]);
      v.regulations.push_back((*regs)[i].get<std::string>());
    }
  return v;
}

}  // namespace pvrr::scene_json_detail
