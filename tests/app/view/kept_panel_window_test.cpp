// Frames that keep the panel the window shows (label `window`; app/view/panel_cache.h): where the window shows
// part of its back buffer (GLX_MESA_copy_sub_buffer, as Xvfb's software GLX does), a frame whose panel picture
// the window already shows is sent less the panel's rectangle. What the display then shows (GL's front buffer,
// the screenshot "panel": "shown") must be the new frame around the panel and the earlier panel in its place.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <string>

#include "app/run_pvrr.h"
#include "app/view/run_view.h"
#include "pvrr/base/image.h"

namespace pvrr::test {
namespace {

namespace fs = std::filesystem;

// As in present_window_test.cpp: the frame drawn into the window is within a code of pvrr render's but where a
// pixel's centre lies exactly on a triangle's edge (it is rasterized mirrored): at most this fraction of the
// pixels outside the panel more than a code apart. Pixels within kPanelMarginPx of the panel are not judged.
constexpr int kWindowVsRenderCodes = 1;
constexpr double kMirroredEdgeTieFraction = 1e-4;
constexpr int kPanelMarginPx = 2;

bool nearPanel(const std::vector<int>& rect, int x, int y) {
  return x >= rect[0] - kPanelMarginPx && x < rect[2] + kPanelMarginPx && y >= rect[1] - kPanelMarginPx &&
         y < rect[3] + kPanelMarginPx;
}

int maxCodeDiff(const ImageRGB8& a, const ImageRGB8& b, int x, int y) {
  int d = 0;
  for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a.at(x, y)[c]) - int(b.at(x, y)[c])));
  return d;
}

TEST(ViewKeptPanel, ShownWindowIsTheNewFrameAroundTheEarlierPanel) {
  const fs::path dir = freshTestDir("view-kept-panel");
  const fs::path script = dir / "script.json", stats = dir / "stats.json", with_panel = dir / "panel.png";
  // A shown screenshot after each of these frames' events, and the view that frame draws saved among the same
  // events, after the turn (save_view writes the head as it stands).
  constexpr int kFirst = 5, kLast = 12;
  std::string events = R"({"at_frame": 2, "do": "turn_head", "yaw_deg": 1.5, "pitch_deg": -0.5},
      {"at_frame": 4, "do": "screenshot", "file": ")" + with_panel.string() + R"(", "panel": true},
      {"at_frame": 4, "do": "screenshot", "file": ")" + (dir / "shown-4.png").string() + R"(", "panel": "shown"},)";
  for (int i = kFirst; i <= kLast; ++i) {
    const std::string n = std::to_string(i);
    events += R"({"at_frame": )" + n + R"(, "do": "turn_head", "yaw_deg": 0.4},
      {"at_frame": )" + n + R"(, "do": "screenshot", "file": ")" + (dir / ("shown-" + n + ".png")).string() +
              R"(", "panel": "shown"},
      {"at_frame": )" + n + R"(, "do": "save_view", "file": ")" +
              (dir / ("view-" + n + ".json")).string() + R"("},)";
  }
  writeText(script, R"({"size": [800, 450], "events": [)" + events + R"(
      {"at_frame": )" + std::to_string(kLast + 1) + R"(, "do": "quit"}]})");
  CliResult r;
  // Map reuse off: every frame drawn whole, as pvrr render draws the saved view.
  RUN_VIEW_OR_SKIP("models/car-mirror.json --set render.map_reuse_margin_deg=0 --script '" + script.string() +
                       "' --stats '" + stats.string() + "'",
                   &r);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json all = nlohmann::json::parse(std::ifstream(stats));
  if (!all["present"]["shows_part"].get<bool>()) GTEST_SKIP() << "this X server's GLX shows no part of a window";
  const auto rect = all["present"]["panel_rect"].get<std::vector<int>>();
  ASSERT_EQ(rect.size(), 4u);
  ASSERT_LT(rect[2], 800 - 100) << "the panel leaves a part of the window to check";

  // A frame shown whole: the display shows the back buffer as the screenshot with the panel read it.
  {
    const ImageRGB8 a = readPng(with_panel.string()), b = readPng((dir / "shown-4.png").string());
    ASSERT_EQ(a.width, b.width);
    int differ = 0;
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x) differ += maxCodeDiff(a, b, x, y) > 0;
    EXPECT_EQ(differ, 0) << "the window shown whole differs from its back buffer";
  }

  const nlohmann::json& shots = all["shown_screenshots"];
  ASSERT_EQ(shots.size(), size_t(kLast - kFirst + 2)) << shots;
  int kept_checked = 0;
  for (size_t k = 1; k < shots.size() && kept_checked < 2; ++k) {
    if (!shots[k]["panel_kept"].get<bool>()) continue;
    // This frame kept the panel: around it the display shows this frame (pvrr render of its saved view), in its
    // place what the frame before showed there.
    const int n = kFirst + int(k) - 1;
    const fs::path rendered = dir / ("render-" + std::to_string(n) + ".png");
    const CliResult rr = runPvrr("render '" + (dir / ("view-" + std::to_string(n) + ".json")).string() + "' --out '" +
                                 rendered.string() + "'");
    ASSERT_EQ(rr.code, 0) << rr.err;
    const ImageRGB8 shown = readPng(shots[k]["file"].get<std::string>()),
                    before = readPng(shots[k - 1]["file"].get<std::string>()), want = readPng(rendered.string());
    ASSERT_EQ(shown.width, want.width);
    ASSERT_EQ(shown.height, want.height);
    int outside = 0, failing = 0, moved = 0, panel_differs = 0, panel_pixels = 0;
    for (int y = 0; y < shown.height; ++y)
      for (int x = 0; x < shown.width; ++x) {
        // The panel's rectangle with its border (the reported one is a pixel inside it all round).
        if (x >= rect[0] - 1 && x < rect[2] + 1 && y >= rect[1] - 1 && y < rect[3] + 1) {
          ++panel_pixels;
          panel_differs += maxCodeDiff(shown, before, x, y) > 0;
        }
        if (nearPanel(rect, x, y)) continue;
        ++outside;
        failing += maxCodeDiff(shown, want, x, y) > kWindowVsRenderCodes;
        moved += maxCodeDiff(before, want, x, y) > kWindowVsRenderCodes;
      }
    EXPECT_GT(outside, 100000);
    EXPECT_LE(failing, int(kMirroredEdgeTieFraction * outside)) << "frame " << n << ": of " << outside << " pixels";
    EXPECT_GT(moved, 1000) << "frame " << n << ": the head turned, so the frame before differs";
    EXPECT_GT(panel_pixels, 100000);
    EXPECT_EQ(panel_differs, 0) << "frame " << n << ": the kept panel differs from the one shown before";
    ++kept_checked;
  }
  // The panel's picture is made again at most every 250 ms: of 8 frames, some keep it.
  EXPECT_GE(kept_checked, 1) << shots;
  EXPECT_GE(all["panel"]["kept"].get<int>(), 1) << all["panel"];
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pvrr::test
