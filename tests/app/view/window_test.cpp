// `pvrr view` in a window (label `window`): scripted runs under a virtual X display (xvfb-run, installed by
// scripts/setup), checked against `pvrr render` of the same view. Skipped, saying why, only where no X server
// can be started.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>

#include "app/run_pvrr.h"
#include "app/view/run_view.h"
#include "pvrr/base/image.h"

namespace pvrr::test {
namespace {

namespace fs = std::filesystem;

// The window and pvrr render both draw with the renderer into a linear target; the window encodes sRGB in a
// shader (float), render on the CPU (double): a value on a rounding boundary may land one code apart.
constexpr double kWindowVsRenderCodes = 1;
// A saved pose against the move asked for: a few double additions of metre-sized numbers.
constexpr double kSavedPoseTol = 1e-12;

// A scripted run's screenshot equals pvrr render of the view it saved; the saved view reloads to the same pixels.
// `check_saved` (optional) looks at the saved view.
void checkScreenshotMatchesRender(const std::string& name, const std::string& scene, const std::string& moves,
                                  const std::function<void(const nlohmann::json&)>& check_saved = {}) {
  const fs::path dir = freshTestDir(name);
  const fs::path script = dir / "script.json", shot = dir / "window.png", view = dir / "view.json",
                 rendered = dir / "render.png", again = dir / "again.png", stats = dir / "stats.json";
  writeText(script, R"({"size": [320, 240], "events": [)" + moves + R"(,
      {"at_frame": 6, "do": "screenshot", "file": ")" + shot.string() + R"("},
      {"at_frame": 6, "do": "save_view", "file": ")" + view.string() + R"("},
      {"at_frame": 7, "do": "quit"}]})");
  CliResult r;
  RUN_VIEW_OR_SKIP(scene + " --script '" + script.string() + "' --stats '" + stats.string() + "'", &r);
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(fs::exists(shot));
  ASSERT_TRUE(fs::exists(view));

  const CliResult rr = runPvrr("render '" + view.string() + "' --out '" + rendered.string() + "'");
  ASSERT_EQ(rr.code, 0) << rr.err;
  const ImageRGB8 a = readPng(shot.string()), b = readPng(rendered.string());
  const ImageDiff d = compareImages(a, b, kWindowVsRenderCodes);
  EXPECT_EQ(d.failing_pixels, 0) << describe(d);

  // The saved view in the window again: the same picture.
  writeText(script, R"({"events": [{"at_frame": 1, "do": "screenshot", "file": ")" + again.string() +
                        R"("}, {"at_frame": 2, "do": "quit"}]})");
  CliResult r2;
  RUN_VIEW_OR_SKIP("'" + view.string() + "' --script '" + script.string() + "'", &r2);
  ASSERT_EQ(r2.code, 0) << r2.err;
  const ImageDiff d2 = compareImages(a, readPng(again.string()), kWindowVsRenderCodes);
  EXPECT_EQ(d2.failing_pixels, 0) << describe(d2);

  const nlohmann::json st = nlohmann::json::parse(std::ifstream(stats));
  EXPECT_EQ(st["frames"], 7);
  EXPECT_GT(st["fps_median"].get<double>(), 0);
  EXPECT_GE(st["frame_ms_max"].get<double>(), st["frame_ms_median"].get<double>());
  EXPECT_EQ(st["mode"], "pvrr");
  EXPECT_EQ(st["gl"].get<std::string>().rfind("glfw-", 0), 0u) << st["gl"];
  if (check_saved) check_saved(nlohmann::json::parse(std::ifstream(view)));
  fs::remove_all(dir);
}

TEST(ViewWindow, CarMirrorHeadTurnedMatchesRender) {
  checkScreenshotMatchesRender("view-car", "models/car-mirror.json",
                               R"({"at_frame": 2, "do": "turn_head", "yaw_deg": 4, "pitch_deg": -2},
                                  {"at_frame": 3, "do": "move_eye", "by": [0.02, 0.01, -0.03]},
                                  {"at_frame": 4, "do": "turn_head", "yaw_deg": 1})");
}

// Spectacles move with the head: the lens is re-posed every frame the head turns.
TEST(ViewWindow, SpectacleLensTurnsWithTheHeadAndMatchesRender) {
  checkScreenshotMatchesRender("view-lens", "models/spectacle-lens.json",
                               R"({"at_frame": 2, "do": "turn_head", "yaw_deg": 6, "pitch_deg": 3},
                                  {"at_frame": 4, "do": "move_eye", "by": [0.01, 0, 0]})");
}

// A mirror turned about its vertex (turn_element, and the key L through the keyboard's path): the saved view holds
// its pose, so pvrr render reproduces the screenshot.
TEST(ViewWindow, TurnedMirrorMatchesRenderOfTheSavedView) {
  checkScreenshotMatchesRender("view-turn", "models/car-mirror.json",
                               R"({"at_frame": 2, "do": "turn_element", "element": "door-mirror", "yaw_deg": 3,
                                   "pitch_deg": -2},
                                  {"at_frame": 3, "do": "key", "key": "L", "shift": true},
                                  {"at_frame": 4, "do": "turn_head", "yaw_deg": 2})",
                               [](const nlohmann::json& saved) {
                                 // Turned by 3 + 10 deg of yaw and 2 deg of pitch from the scene's normal.
                                 const auto& n = saved["elements"][0]["pose"]["normal"];
                                 const double dot = 0.3834 * n[0].get<double>() + 0.1238 * n[1].get<double>() +
                                                    0.9153 * n[2].get<double>();
                                 EXPECT_LT(dot, std::cos(12 * M_PI / 180));
                               });
}

// A mirror moved in its own frame: the saved view holds the new vertex, 2 cm along the mirror's local x.
TEST(ViewWindow, MovedMirrorMatchesRenderOfTheSavedView) {
  checkScreenshotMatchesRender("view-move", "models/car-mirror.json",
                               R"({"at_frame": 2, "do": "move_element", "element": "door-mirror",
                                   "by": [0.02, 0, 0]})",
                               [](const nlohmann::json& saved) {
                                 const auto& p = saved["elements"][0]["pose"]["position"];
                                 const double d[3] = {
                                     p[0].get<double>() + 0.5, p[1].get<double>() - 1.05,
                                     p[2].get<double>() + 0.35};  // from the scene's [-0.5, 1.05, -0.35]
                                 EXPECT_NEAR(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), 0.02, kSavedPoseTol);
                                 EXPECT_NEAR(d[1], 0, kSavedPoseTol);  // local x is horizontal: up x normal with up = y
                               });
}

// Keys go through the keyboard's path: Left turns the head 1 degree, as turn_head does; H returns to the design
// eye point.
TEST(ViewWindow, KeysTurnTheHeadAndReturnToTheDesignEye) {
  const fs::path dir = freshTestDir("view-keys");
  const fs::path script = dir / "script.json", by_key = dir / "key.png", by_turn = dir / "turn.png",
                 home = dir / "home.png", start = dir / "start.png";
  writeText(script, R"({"size": [256, 192], "events": [
      {"at_frame": 1, "do": "screenshot", "file": ")" + start.string() + R"("},
      {"at_frame": 2, "do": "key", "key": "LEFT"},
      {"at_frame": 3, "do": "screenshot", "file": ")" + by_key.string() + R"("},
      {"at_frame": 4, "do": "key", "key": "W", "shift": true},
      {"at_frame": 4, "do": "key", "key": "UP"},
      {"at_frame": 5, "do": "key", "key": "H"},
      {"at_frame": 6, "do": "screenshot", "file": ")" + home.string() + R"("},
      {"at_frame": 7, "do": "quit"}]})");
  CliResult r;
  RUN_VIEW_OR_SKIP("models/plane-mirror.json --script '" + script.string() + "'", &r);
  ASSERT_EQ(r.code, 0) << r.err;
  writeText(script, R"({"size": [256, 192], "events": [
      {"at_frame": 2, "do": "turn_head", "yaw_deg": 1},
      {"at_frame": 3, "do": "screenshot", "file": ")" + by_turn.string() + R"("},
      {"at_frame": 4, "do": "quit"}]})");
  RUN_VIEW_OR_SKIP("models/plane-mirror.json --script '" + script.string() + "'", &r);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(compareImages(readPng(by_key.string()), readPng(by_turn.string()), 0).failing_pixels, 0);
  EXPECT_GT(compareImages(readPng(by_key.string()), readPng(start.string()), 0).failing_pixels, 0);  // it turned
  EXPECT_EQ(compareImages(readPng(home.string()), readPng(start.string()), 0).failing_pixels, 0);
  fs::remove_all(dir);
}

// "set" rebuilds the scene: a mode change by script shows that mode's picture.
TEST(ViewWindow, SetChangesTheModeLive) {
  const fs::path dir = freshTestDir("view-set");
  const fs::path script = dir / "script.json", shot = dir / "window.png", rendered = dir / "render.png";
  writeText(script, R"({"size": [256, 192], "events": [
      {"at_frame": 1, "do": "set", "path": "render.mode", "value": "envmap"},
      {"at_frame": 3, "do": "screenshot", "file": ")" + shot.string() + R"("},
      {"at_frame": 3, "do": "quit"}]})");
  CliResult r;
  RUN_VIEW_OR_SKIP("models/concave-mirror.json --script '" + script.string() + "'", &r);
  ASSERT_EQ(r.code, 0) << r.err;
  const CliResult rr =
      runPvrr("render models/concave-mirror.json --mode envmap --size 256x192 --out '" + rendered.string() + "'");
  ASSERT_EQ(rr.code, 0) << rr.err;
  const ImageDiff d = compareImages(readPng(shot.string()), readPng(rendered.string()), kWindowVsRenderCodes);
  EXPECT_EQ(d.failing_pixels, 0) << describe(d);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pvrr::test
