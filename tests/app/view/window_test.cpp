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
#include "pvrr/base/math.h"

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

// The normal expected after turning an element whose frame is (x, y, z) = (up x normal, up, normal) by yaw a1 and
// pitch b1, then by yaw a2 (degrees; element_pose.h: yaw about local y takes z towards x, pitch tilts it towards y,
// each turn in the frame the last one left), written out in that frame:
//   n1 = (cos b1 sin a1, sin b1, cos b1 cos a1), up1 = (-sin b1 sin a1, cos b1, -sin b1 cos a1),
//   n2 = cos a2 n1 + sin a2 (up1 x n1).
Vec3 twiceTurnedNormal(const Vec3& normal, const Vec3& up, double a1_deg, double b1_deg, double a2_deg) {
  const double a1 = a1_deg * M_PI / 180, b1 = b1_deg * M_PI / 180, a2 = a2_deg * M_PI / 180;
  const Vec3 z = glm::normalize(normal), y = glm::normalize(up - glm::dot(up, z) * z), x = glm::cross(y, z);
  const Vec3 n1 = std::cos(b1) * std::sin(a1) * x + std::sin(b1) * y + std::cos(b1) * std::cos(a1) * z;
  const Vec3 up1 = -std::sin(b1) * std::sin(a1) * x + std::cos(b1) * y - std::sin(b1) * std::cos(a1) * z;
  return std::cos(a2) * n1 + std::sin(a2) * glm::cross(up1, n1);
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
                                 // Turned by yaw 3 and pitch -2 deg, then yaw 10 (L with Shift), from the scene's
                                 // pose (models/car-mirror.json: normal [0.3834, 0.1238, 0.9153], up [0, 1, 0]).
                                 const auto& n = saved["elements"][0]["pose"]["normal"];
                                 const Vec3 got(n[0].get<double>(), n[1].get<double>(), n[2].get<double>());
                                 const Vec3 want = twiceTurnedNormal({0.3834, 0.1238, 0.9153}, {0, 1, 0}, 3, -2, 10);
                                 for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], kSavedPoseTol) << k;
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

// Time in an animated scene (issue 24 item 1): the "time" event poses the scene as pvrr render --time does, so the
// window's picture at t = 1.5 s is render's of the saved view at 1.5 s; and it is not the picture at 0 (the
// overtaking car moved). Space (the keyboard's path) plays: the time runs on.
TEST(ViewWindow, TimeShowsTheAnimatedSceneAsRenderAtThatTime) {
  const fs::path dir = freshTestDir("view-time");
  const fs::path script = dir / "script.json", shot = dir / "window.png", view = dir / "view.json",
                 at_t = dir / "render.png", at_0 = dir / "render0.png", stats = dir / "stats.json";
  writeText(script, R"({"size": [320, 240], "events": [
      {"at_frame": 2, "do": "time", "t": 1.5},
      {"at_frame": 4, "do": "screenshot", "file": ")" +
                        shot.string() + R"("},
      {"at_frame": 4, "do": "save_view", "file": ")" +
                        view.string() + R"("},
      {"at_frame": 5, "do": "key", "key": "SPACE"},
      {"at_frame": 8, "do": "quit"}]})");
  CliResult r;
  RUN_VIEW_OR_SKIP("models/overtaking-car.json --script '" + script.string() + "' --stats '" + stats.string() + "'",
                   &r);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const auto& [t, out] : {std::pair{"1.5", at_t}, std::pair{"0", at_0}}) {
    const CliResult rr = runPvrr("render '" + view.string() + "' --time " + t + " --out '" + out.string() + "'");
    ASSERT_EQ(rr.code, 0) << rr.err;
  }
  const ImageRGB8 window = readPng(shot.string());
  const ImageDiff d = compareImages(window, readPng(at_t.string()), kWindowVsRenderCodes);
  EXPECT_EQ(d.failing_pixels, 0) << describe(d);
  EXPECT_GT(compareImages(window, readPng(at_0.string()), kWindowVsRenderCodes).failing_pixels, 0);  // it moved
  const nlohmann::json st = nlohmann::json::parse(std::ifstream(stats));
  EXPECT_TRUE(st["playing"].get<bool>());
  EXPECT_GT(st["time_s"].get<double>(), 1.5);  // played on from 1.5 s
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
