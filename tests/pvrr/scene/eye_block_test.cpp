// A lens's "eye" block (docs/scene-format.md): the wearer's centre of rotation behind the eye-side vertex.
#include <gtest/gtest.h>

#include <string>

#include "pvrr/base/error.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr {
namespace {

std::string lensScene(const std::string& extra, const std::string& units = "m") {
  return R"({"version": 1, "units": ")" + units + R"(",
    "observer": {"eye": [0, 0, 0], "target": [0, 0, -1], "up": [0, 1, 0], "fov_y_deg": 50, "image_size": [64, 48]},
    "environment": [{"type": "quad", "centre": [0, 0, -4], "normal": [0, 0, 1], "up": [0, 1, 0], "size": [5, 3],
                     "material": {"color": [0.8, 0.8, 0.8]}}],
    "lights": [{"type": "ambient", "color": [1, 1, 1]}],
    "elements": [{"name": "lens", "type": "lens", "attached_to_observer": true,
      "pose": {"position": [0, 0, -0.012], "normal": [0, 0, 1]},
      "outline": {"shape": "circle", "diameter": 0.04},
      "front": {"type": "sphere", "radius": -0.0709}, "back": {"type": "sphere", "radius": -0.1245},
      "centre_thickness": 0.002, "material": {"name": "cr39"})" +
         extra + "}]}";
}

TEST(EyeBlock, DefaultsTo25_5mm) {
  const Scene s = buildScene(parseScene(lensScene(""), "x.json", "."));
  EXPECT_DOUBLE_EQ(s.elements[0].eye_rotation_centre_m, 0.0255);
}

TEST(EyeBlock, ReadsTheRotationCentreInTheScenesUnit) {
  EXPECT_DOUBLE_EQ(
      parseScene(lensScene(R"(, "eye": {"rotation_centre": 0.027})"), "x.json", ".").elements[0].eye_rotation_centre_m,
      0.027);
  const Scene s = buildScene(parseScene(lensScene(R"(, "eye": {"rotation_centre": 0.027})"), "x.json", "."));
  EXPECT_DOUBLE_EQ(s.elements[0].eye_rotation_centre_m, 0.027);
}

TEST(EyeBlock, ErrorsNameTheJsonPath) {
  try {
    parseScene(lensScene(R"(, "eye": {"rotation_centre": -1})"), "x.json", ".");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("x.json: elements[0].eye.rotation_centre"), std::string::npos) << e.what();
  }
  try {
    parseScene(lensScene(R"(, "eye": {"rotation_center": 0.02})"), "x.json", ".");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("elements[0].eye"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("rotation_centre"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pvrr
