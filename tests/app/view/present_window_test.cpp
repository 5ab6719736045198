// The window's present pass around the panel (label `window`): the frame is not presented under the panel's
// opaque rectangle, the panel is copied from its picture (app/view/panel_cache.h), and every pixel outside it
// still equals pvrr render of the view.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdlib>
#include <fstream>

#include "app/run_pvrr.h"
#include "app/view/run_view.h"
#include "pvrr/base/image.h"

namespace pvrr::test {
namespace {

namespace fs = std::filesystem;

// As in window_test.cpp: the window encodes sRGB in a shader, render on the CPU; both from the same 16-bit values,
// so a code apart at most (the float round-trip to the 16-bit value).
constexpr int kWindowVsRenderCodes = 1;
// Pixels this close to the panel's reported rectangle are not judged (its border and the one-pixel margin the
// hole leaves inside it).
constexpr int kPanelMarginPx = 2;

TEST(ViewPresent, FramePresentedAroundThePanelMatchesRenderOutsideIt) {
  const fs::path dir = freshTestDir("view-present-hole");
  const fs::path script = dir / "script.json", shot = dir / "window.png", view = dir / "view.json",
                 rendered = dir / "render.png", stats = dir / "stats.json";
  writeText(script, R"({"size": [800, 450], "events": [
      {"at_frame": 2, "do": "turn_head", "yaw_deg": 1.5, "pitch_deg": -0.5},
      {"at_frame": 3, "do": "turn_head", "yaw_deg": 0.5},
      {"at_frame": 6, "do": "screenshot", "file": ")" + shot.string() + R"(", "panel": true},
      {"at_frame": 6, "do": "save_view", "file": ")" + view.string() + R"("},
      {"at_frame": 7, "do": "quit"}]})");
  CliResult r;
  // Map reuse off: every frame drawn whole, as pvrr render draws the saved view (a frame that reuses an earlier
  // pose's maps differs from it in places; the frame-alone screenshot draws whole by itself, this one does not).
  RUN_VIEW_OR_SKIP("models/car-mirror.json --set render.map_reuse_margin_deg=0 --script '" + script.string() + "' --stats '" + stats.string() + "'", &r);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json all = nlohmann::json::parse(std::ifstream(stats)), st = all["present"];
  // The panel (nobody works it: the pointer is away from it) copied from its picture on the frames after ImGui's
  // first, the picture made on the first of them and again at most every 250 ms (a run of 7 frames under load
  // can take longer than that, hence no upper bound but the frames).
  EXPECT_GE(all["panel"]["copies"].get<int>(), 5) << all["panel"];
  EXPECT_GE(all["panel"]["pictures"].get<int>(), 1) << all["panel"];
  EXPECT_LE(all["panel"]["pictures"].get<int>(), all["panel"]["copies"].get<int>()) << all["panel"];
  // Every frame but ImGui's first (the panel sizes itself unseen) was presented around the panel.
  EXPECT_GE(st["panel_hole_frames"].get<int>(), 5) << st;
  const auto rect = st["panel_rect"].get<std::vector<int>>();
  ASSERT_EQ(rect.size(), 4u);
  ASSERT_LT(rect[2], 800 - 100) << "the panel leaves a part of the window to check";

  const CliResult rr = runPvrr("render '" + view.string() + "' --out '" + rendered.string() + "'");
  ASSERT_EQ(rr.code, 0) << rr.err;
  const ImageRGB8 a = readPng(shot.string()), b = readPng(rendered.string());
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  int outside = 0, failing = 0, inside_differs = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a.at(x, y)[c]) - int(b.at(x, y)[c])));
      const bool in = x >= rect[0] - kPanelMarginPx && x < rect[2] + kPanelMarginPx && y >= rect[1] - kPanelMarginPx &&
                      y < rect[3] + kPanelMarginPx;
      if (in) {
        inside_differs += d > kWindowVsRenderCodes;
        continue;
      }
      ++outside;
      failing += d > kWindowVsRenderCodes;
    }
  EXPECT_GT(outside, 100000);
  EXPECT_EQ(failing, 0) << "of " << outside << " pixels outside the panel";
  EXPECT_GT(inside_differs, 10000);  // the panel is there, over the frame
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pvrr::test
