// app/view/script.*: the scripted runs' format and its one-message errors; app/view/head.*: the head's pose.
#include "app/view/script.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include <glm/gtc/matrix_transform.hpp>

#include "app/view/head.h"
#include "pvrr/base/error.h"
#include "app/run_pvrr.h"

namespace pvrr::app::view {
namespace {

std::string errorOf(const std::string& text) {
  try {
    parseScript(text, "s.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ViewScript, ReadsEveryEventInFrameOrder) {
  const Script s = parseScript(R"({"size": [320, 240], "events": [
      {"at_frame": 5, "do": "quit"},
      {"at_frame": 1, "do": "turn_head", "yaw_deg": 10, "pitch_deg": -2},
      {"at_frame": 1, "do": "move_eye", "by": [0.1, 0, -0.2]},
      {"at_frame": 2, "do": "set", "path": "render.mode", "value": "envmap"},
      {"at_frame": 3, "do": "screenshot", "file": "a.png"},
      {"at_frame": 3, "do": "save_view", "file": "v.json"}]})",
                               "s.json");
  EXPECT_EQ(s.width, 320);
  EXPECT_EQ(s.height, 240);
  ASSERT_EQ(s.events.size(), 6u);
  EXPECT_EQ(s.events[0].kind, EventKind::TurnHead);
  EXPECT_EQ(s.events[0].yaw_deg, 10);
  EXPECT_EQ(s.events[0].pitch_deg, -2);
  EXPECT_EQ(s.events[1].kind, EventKind::MoveEye);
  EXPECT_EQ(s.events[1].by_m, Vec3(0.1, 0, -0.2));
  EXPECT_EQ(s.events[2].kind, EventKind::Set);
  EXPECT_EQ(s.events[2].path, "render.mode");
  EXPECT_EQ(s.events[2].value_json, "\"envmap\"");
  EXPECT_EQ(s.events[3].file, "a.png");
  EXPECT_EQ(s.events[4].kind, EventKind::SaveView);
  EXPECT_EQ(s.events[5].kind, EventKind::Quit);
  EXPECT_EQ(s.events[5].where, "events[0]");
}

TEST(ViewScript, ReadsTheScreenshotsKinds) {
  const Script s = parseScript(R"({"events": [
      {"at_frame": 1, "do": "screenshot", "file": "a.png"},
      {"at_frame": 1, "do": "screenshot", "file": "b.png", "panel": true},
      {"at_frame": 1, "do": "screenshot", "file": "c.png", "panel": "shown"}]})",
                               "s.json");
  ASSERT_EQ(s.events.size(), 3u);
  EXPECT_FALSE(s.events[0].with_panel || s.events[0].shown);
  EXPECT_TRUE(s.events[1].with_panel && !s.events[1].shown);
  EXPECT_TRUE(!s.events[2].with_panel && s.events[2].shown);
  try {
    parseScript(R"({"events": [{"at_frame": 1, "do": "screenshot", "file": "a.png", "panel": "yes"}]})", "s.json");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("events[0].panel"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("\"shown\""), std::string::npos) << e.what();
  }
}

TEST(ViewScript, ReadsTheReferenceEvents) {
  const Script s = parseScript(R"({"events": [
      {"at_frame": 1, "do": "reference"},
      {"at_frame": 2, "do": "wipe", "x": 0.25},
      {"at_frame": 3, "do": "overlay", "on": true},
      {"at_frame": 4, "do": "drag", "button": "left", "from": [10, 20], "to": [30.5, 40]},
      {"at_frame": 5, "do": "cursor", "at": [7, 8.5]},
      {"at_frame": 6, "do": "turn_element", "element": "m", "yaw_deg": 2}]})",
                               "s.json");
  ASSERT_EQ(s.events.size(), 6u);
  EXPECT_EQ(s.events[4].kind, EventKind::Cursor);
  EXPECT_EQ(s.events[4].at_px, Vec2(7, 8.5));
  EXPECT_EQ(s.events[5].kind, EventKind::TurnElement);
  EXPECT_EQ(s.events[5].element, "m");
  EXPECT_EQ(s.events[5].yaw_deg, 2);
  EXPECT_EQ(s.events[5].pitch_deg, 0);
  EXPECT_EQ(s.events[0].kind, EventKind::Reference);
  EXPECT_EQ(s.events[1].kind, EventKind::Wipe);
  EXPECT_EQ(s.events[1].wipe_x, 0.25);
  EXPECT_EQ(s.events[2].kind, EventKind::Overlay);
  EXPECT_TRUE(s.events[2].on);
  EXPECT_EQ(s.events[3].kind, EventKind::Drag);
  EXPECT_EQ(s.events[3].from_px, Vec2(10, 20));
  EXPECT_EQ(s.events[3].to_px, Vec2(30.5, 40));
}

TEST(ViewScript, ErrorsNameTheFileAndTheJsonPath) {
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "teleport"}]})"),
            "s.json: events[0].do: expected one of cursor, drag, key, move_element, move_eye, overlay, quit, "
            "reference, save_view, "
            "screenshot, "
            "set, time, turn_element, turn_head, wipe, got \"teleport\"");
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "quit"}, {"at_frame": -1, "do": "quit"}]})"),
            "s.json: events[1].at_frame: expected a frame number >= 0, got -1");
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "turn_head", "yaw_dg": 3}]})"),
            "s.json: events[0].yaw_dg: unknown key; did you mean \"yaw_deg\"?");
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "move_eye", "by": [1, 2]}]})"),
            "s.json: events[0].by: expected [x, y, z] in metres, got [1,2]");
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "screenshot", "file": "a.jpg"}]})"),
            "s.json: events[0].file: expected a file name ending in \".png\", got \"a.jpg\"");
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "time", "t": -1}]})"),
            "s.json: events[0].t: expected a time in seconds from 0 to 1e6, got -1");
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "time", "t": 1, "play": "yes"}]})"),
            "s.json: events[0].play: expected true or false, got \"yes\"");
  EXPECT_EQ(errorOf(R"({"size": [320], "events": []})"), "s.json: size: expected [width, height] in pixels, got [320]");
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "wipe", "x": 1.5}]})"),
            "s.json: events[0].x: expected a number from 0 (all reference) to 1 (all mode), got 1.5");
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "overlay", "on": 1}]})"),
            "s.json: events[0].on: expected true or false, got 1");
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "drag", "from": [1, 2], "to": [3]}]})"),
            "s.json: events[0].to: expected [x, y] in window pixels, got [3]");
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "drag", "button": "middle", "from": [1, 2], "to": [3, 4]}]})"),
            "s.json: events[0].button: expected \"left\", got \"middle\"");
  EXPECT_EQ(errorOf(R"({"events": [{"at_frame": 1, "do": "key", "key": "HOM"}]})").substr(0, 32),
            "s.json: events[0].key: expected ");
  EXPECT_NE(errorOf(R"({"events": [{"at_frame": 1, "do": "key", "key": "HOM"}]})").find("did you mean \"HOME\"?"),
            std::string::npos);
  EXPECT_EQ(errorOf("{\"events\": [\n  {\"at_frame\": 1,}]}"), "s.json:2:18: syntax error: syntax error while parsing object key - unexpected '}'; expected string literal");
  EXPECT_EQ(errorOf(R"({"size": [320, 240]})"), "s.json: (top level): missing \"events\"");
}

// A bad script is refused before any window opens: one line, exit 1, no X server needed.
TEST(ViewScript, CommandRefusesABadScriptWithOneLine) {
  const auto dir = test::freshTestDir("view-bad-script");
  const std::string script = (dir / "bad.json").string();
  {
    std::ofstream(script) << R"({"events": [{"at_frame": 0, "do": "turn_head", "yaw_deg": "left"}]})";
  }
  const test::CliResult r = test::runPvrr("view --script '" + script + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, script + ": events[0].yaw_deg: expected a number, got \"left\"\n");
  // A "set" the scene refuses names the event too.
  {
    std::ofstream(script) << R"({"events": [{"at_frame": 0, "do": "set", "path": "render.map_size", "value": -3}]})";
  }
  const test::CliResult s = test::runPvrr("view --script '" + script + "'");
  EXPECT_EQ(s.code, 1);
  EXPECT_EQ(s.err.find(script + ": events[0]: models/car-mirror.json: render.map_size"), 0u) << s.err;
  EXPECT_EQ(std::count(s.err.begin(), s.err.end(), '\n'), 1) << s.err;
  // turn_element names an element of the scene.
  {
    std::ofstream(script)
        << R"({"events": [{"at_frame": 0, "do": "turn_element", "element": "door-miror", "yaw_deg": 1}]})";
  }
  const test::CliResult t = test::runPvrr("view --script '" + script + "'");
  EXPECT_EQ(t.code, 1);
  EXPECT_EQ(t.err, script +
                       ": events[0].element: models/car-mirror.json has no element named \"door-miror\"; did you "
                       "mean \"door-mirror\"?\n");
  std::filesystem::remove_all(dir);
}

// Each tolerance: exact up to double rounding of a few matrix products.
constexpr double kPoseTol = 1e-12;

TEST(ViewHead, YawTurnsAsRenderOrbitDoes) {
  Observer design;
  design.eye = Vec3(0, 1.2, 0);
  design.target = Vec3(-0.5, 1.05, -0.35);
  HeadPose pose;
  turnHead(pose, radians(20), 0);
  const Observer ob = headObserver(design, pose);
  // pvrr render --orbit: the target turned about the up axis through the eye.
  const Vec3 expect = design.eye + Vec3(glm::rotate(Mat4(1.0), radians(20), design.up) * Vec4(design.target - design.eye, 0));
  EXPECT_NEAR(glm::length(ob.target - expect), 0, kPoseTol);
  EXPECT_EQ(ob.eye, design.eye);
}

TEST(ViewHead, PitchLooksUpAndIsClamped) {
  Observer design;  // looking along -z
  HeadPose pose;
  turnHead(pose, 0, radians(30));
  const Vec3 dir = glm::normalize(headObserver(design, pose).target - design.eye);
  EXPECT_NEAR(dir.y, std::sin(radians(30)), kPoseTol);
  turnHead(pose, 0, radians(200));
  EXPECT_NEAR(pose.pitch_rad, radians(kMaxPitchDeg), kPoseTol);
}

TEST(ViewHead, EyeMovesInTheTurnedObserverFrame) {
  Observer design;  // eye at the origin looking along -z, up +y
  HeadPose pose;
  turnHead(pose, radians(90), 0);  // now looking along -x; right is -z
  moveEye(pose, design, Vec3(0.1, 0.2, -0.3));  // 0.1 right, 0.2 up, 0.3 forward
  EXPECT_NEAR(glm::length(pose.eye_offset_m - Vec3(-0.3, 0.2, -0.1)), 0, kPoseTol);
  const Observer ob = headObserver(design, pose);
  EXPECT_NEAR(glm::length(ob.eye - Vec3(-0.3, 0.2, -0.1)), 0, kPoseTol);
  EXPECT_NEAR(glm::length(glm::normalize(ob.target - ob.eye) - Vec3(-1, 0, 0)), 0, kPoseTol);
}

}  // namespace
}  // namespace pvrr::app::view
