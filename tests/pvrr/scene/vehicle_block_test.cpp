// The scene's "vehicle" block (docs/scene-format.md): the frame pvrr fov works in, and its errors.
#include <gtest/gtest.h>

#include <string>

#include "pvrr/base/error.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr {
namespace {

std::string scene(const std::string& vehicle) {
  return R"({"version": 1,
    "observer": {"eye": [0, 1.2, 0], "target": [0, 1.2, -1]},
    "environment": [{"type": "ground", "name": "road", "point": [0, 0, 0], "normal": [0, 1, 0], "size": [10, 10]},
                    {"type": "box", "name": "own-door", "centre": [-0.4, 0.5, 0], "size": [0.05, 1, 1]},
                    {"type": "box", "name": "other-car", "centre": [0, 0.5, 10], "size": [1, 1, 1]}])" +
         (vehicle.empty() ? "" : ", \"vehicle\": " + vehicle) + "}";
}

const std::string kGood = R"({"forward": [0, 0, -1], "up": [0, 1, 0], "road_height": 0,
    "outermost": {"left": [-0.45, 1, 0], "right": [1.35, 1, 0]},
    "ocular_points": {"left": [-0.0325, 1.2, 0], "right": [0.0325, 1.2, 0]}, "driver_side": "left")";

std::string errorOf(const std::string& json) {
  try {
    parseScene(json, "x.json", ".");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(VehicleBlock, OptionalAndRead) {
  EXPECT_FALSE(parseScene(scene(""), "x.json", ".").vehicle.has_value());
  const SceneDesc d =
      parseScene(scene(kGood + R"(, "obstructions": ["own-door"], "regulations": ["r46-class-iii"]})"), "x.json", ".");
  ASSERT_TRUE(d.vehicle.has_value());
  EXPECT_EQ(d.vehicle->forward, Vec3(0, 0, -1));
  EXPECT_EQ(d.vehicle->eye_left, Vec3(-0.0325, 1.2, 0));
  EXPECT_EQ(d.vehicle->driver_side, VehicleDesc::Side::Left);
  EXPECT_EQ(d.vehicle->obstructions, std::vector<std::string>{"own-door"});
  EXPECT_EQ(d.vehicle->regulations, std::vector<std::string>{"r46-class-iii"});
}

TEST(VehicleBlock, ObstructionsDefaultToEverythingButGrounds) {
  const SceneDesc d = parseScene(scene(kGood + "}"), "x.json", ".");
  EXPECT_EQ(d.vehicle->obstructions, (std::vector<std::string>{"own-door", "other-car"}));
}

TEST(VehicleBlock, EyeEllipse) {
  // Full axes along forward, left, up, in the file's unit; no default size.
  const SceneDesc d =
      parseScene(scene(kGood + R"(, "eye_ellipse": {"axes": [0.2, 0.06, 0.09], "tilt_deg": 12}})"), "x.json", ".");
  ASSERT_TRUE(d.vehicle->eye_ellipse.has_value());
  EXPECT_EQ(d.vehicle->eye_ellipse->axes_m, Vec3(0.2, 0.06, 0.09));
  EXPECT_EQ(d.vehicle->eye_ellipse->tilt_deg, 12);
  EXPECT_FALSE(parseScene(scene(kGood + "}"), "x.json", ".").vehicle->eye_ellipse.has_value());
  EXPECT_NE(errorOf(scene(kGood + R"(, "eye_ellipse": {"axes": [0.2, -0.06, 0.09]}})"))
                .find("x.json: vehicle.eye_ellipse.axes: expected three lengths >= 0"),
            std::string::npos);
  EXPECT_NE(errorOf(scene(kGood + R"(, "eye_ellipse": {"axes": [0.2, 0.06, 0.09], "tilt_deg": 60}})"))
                .find("vehicle.eye_ellipse.tilt_deg"),
            std::string::npos);
  EXPECT_NE(errorOf(scene(kGood + R"(, "eye_ellipse": {"axis": [0.2, 0.06, 0.09]}})"))
                .find("vehicle.eye_ellipse.axis: unknown key"),
            std::string::npos);
}

TEST(VehicleBlock, ErrorsNameTheJsonPath) {
  auto with = [](const std::string& from, const std::string& to) {
    std::string v = kGood;
    v.replace(v.find(from), from.size(), to);
    return scene(v + "}");
  };
  EXPECT_NE(errorOf(with(R"("forward": [0, 0, -1])", R"("forward": [0, 1, -1])"))
                .find("x.json: vehicle.forward: expected a direction perpendicular"),
            std::string::npos);
  EXPECT_NE(errorOf(with(R"("left": [-0.0325, 1.2, 0])", R"("left": [0.5, 1.2, 0])"))
                .find("vehicle.ocular_points.left: expected a point to the left"),
            std::string::npos);
  EXPECT_NE(errorOf(with(R"("left": [-0.45, 1, 0])", R"("left": [-0.45, -1, 0])"))
                .find("vehicle.outermost.left: expected a point above the road"),
            std::string::npos);
  EXPECT_NE(errorOf(with(R"("driver_side": "left")", R"("driver_side": "lefft")")).find("vehicle.driver_side"),
            std::string::npos);
  EXPECT_NE(errorOf(scene(kGood + R"(, "obstructions": ["own-dor"]})"))
                .find("vehicle.obstructions[0]: expected the name of an environment object, got \"own-dor\"; did you "
                      "mean \"own-door\"?"),
            std::string::npos);
  EXPECT_NE(errorOf(scene(kGood + R"(, "ocular": 1})")).find("vehicle.ocular: unknown key"), std::string::npos);
}

}  // namespace
}  // namespace pvrr
