// A light's "shadows" switch (docs/scene-format.md "lights"): on unless a scene says otherwise, for
// directional and point lights; a bad value stops the load with one line naming the place.
#include <gtest/gtest.h>

#include <filesystem>

#include "pvrr/base/error.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr {
namespace {

const std::string kName = "scenes/lights.json";

std::string sceneWithLights(const std::string& lights) {
  return R"({"version": 1, "observer": {"eye": [0, 1.2, 0], "target": [0, 1.2, -1]},
             "environment": [{"type": "box", "centre": [0, 0.5, -3], "size": [1, 1, 1]}],
             "lights": [)" +
         lights + "]}";
}

std::string errorOf(const std::string& text) {
  try {
    parseScene(text, kName, "");
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for the scene";
  return "";
}

TEST(LightShadows, OnUnlessTheSceneSaysOtherwise) {
  const SceneDesc d = parseScene(sceneWithLights(R"({"type": "directional", "direction": [0, -1, 0]},
      {"type": "point", "position": [0, 2, 0], "shadows": false}, {"type": "point", "position": [0, 2, 1], "shadows": true},
      {"type": "ambient"})"),
                                 kName, "");
  ASSERT_EQ(d.lights.size(), 4u);
  EXPECT_TRUE(d.lights[0].shadows);
  EXPECT_FALSE(d.lights[1].shadows);
  EXPECT_TRUE(d.lights[2].shadows);
  EXPECT_FALSE(d.lights[3].shadows);  // ambient light casts none
  const Scene s = buildScene(d);
  EXPECT_TRUE(s.lights[0].shadows);
  EXPECT_FALSE(s.lights[1].shadows);
  EXPECT_FALSE(s.lights[3].shadows);
  // A scene built in code has none unless asked.
  EXPECT_FALSE(Light{}.shadows);
}

TEST(LightShadows, BadValuesAreRejectedInOneLine) {
  EXPECT_EQ(errorOf(sceneWithLights(R"({"type": "point", "position": [0, 2, 0], "shadows": "yes"})")),
            kName + ": lights[0].shadows: expected true or false, got \"yes\"");
  EXPECT_EQ(errorOf(sceneWithLights(R"({"type": "directional", "direction": [0, -1, 0], "shadows": 1})")),
            kName + ": lights[0].shadows: expected true or false, got 1");
  const std::string m = errorOf(sceneWithLights(R"({"type": "ambient", "shadows": false})"));
  EXPECT_NE(m.find("lights[0].shadows: unknown key"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos);
}

// The shipped scenes keep their unshadowed pictures (and golden images): every light says so.
// Shipped scenes turn shadows off (their pictures predate them), except the caustic scenes, whose sun has
// caustics on and so needs the lens's shadow (docs/scene-format.md "caustics").
TEST(LightShadows, ShippedScenesTurnThemOffExplicitly) {
  int scenes = 0, caustic = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(PVRR_SOURCE_DIR) / "models")) {
    if (entry.path().extension() != ".json") continue;
    ++scenes;
    for (const LightDesc& l : loadScene(entry.path().string()).lights) {
      EXPECT_EQ(l.shadows, l.caustics) << entry.path();
      caustic += l.caustics;
    }
  }
  EXPECT_GE(scenes, 8);
  EXPECT_EQ(caustic, 2);  // burning-lens and shaving-mirror-sun
}

// A light's "caustics" switch: off unless a scene turns it on; ambient light has none; bad values in one line.
TEST(LightShadows, CausticsAreOffUnlessTurnedOn) {
  const SceneDesc d = parseScene(sceneWithLights(R"({"type": "directional", "direction": [0, -1, 0]},
      {"type": "point", "position": [0, 2, 0], "caustics": true})"),
                                 kName, "");
  EXPECT_FALSE(d.lights[0].caustics);
  EXPECT_TRUE(d.lights[1].caustics);
  EXPECT_TRUE(buildScene(d).lights[1].caustics);
  EXPECT_FALSE(Light{}.caustics);
  EXPECT_EQ(errorOf(sceneWithLights(R"({"type": "directional", "direction": [0, -1, 0], "caustics": 1})")),
            kName + ": lights[0].caustics: expected true or false, got 1");
  const std::string m = errorOf(sceneWithLights(R"({"type": "ambient", "caustics": true})"));
  EXPECT_NE(m.find("lights[0].caustics: unknown key"), std::string::npos) << m;
}

}  // namespace
}  // namespace pvrr
