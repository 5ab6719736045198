// The viewer's live reference (app/view/reference_tiles.*, wipe.*; label `window`): the reference traced in the
// window is pvrr compare's reference of the same view, pixel for pixel; the error overlay's figures are compare's,
// and its heat map is compare's heat map; the wipe's line is dragged; closing mid-reference exits cleanly.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

#include "app/run_pvrr.h"
#include "app/view/run_view.h"
#include "pvrr/base/image.h"

namespace pvrr::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The reference is traced by the same tracer at the same pixel centres and encoded as compare encodes it.
constexpr double kReferenceCodes = 0;
// The overlay's median and p95 against compare's: the issue allows 1 %; the computation is the same, so any
// difference comes from the mode's frame (drawn by another context of the same GL implementation).
constexpr double kMedianRelTol = 0.01;
// The heat map: the same colours of the same errors and scale; one code for a p95 (so a scale) that differs in
// its last bits between the two frames.
constexpr double kHeatCodes = 1;
// compare's heat map paints pixels without an error this grey (app/compare.cpp); no heat colour is grey.
constexpr int kNoErrorGrey = 40;

json readJson(const fs::path& p) { return json::parse(std::ifstream(p)); }

// The view traced second (after a reference of the design view, then a head turn): the seen-points worker
// (app/view/seen_frames.h) draws it with the renderer it built for the first, moved to the new observer. The
// window's thread builds no program for either: the worker does (structural, not timed).
// The window's overlay `shot` against compare's heat map `heat`: every pixel compare colours (its colour bar lies to
// the right: the same x) within kHeatCodes of it in the overlay, and as many of them as the live reference compared.
void expectOverlayIsTheHeatMap(const ImageRGB8& heat, const ImageRGB8& shot, int compared_by_the_viewer) {
  int compared = 0, failing = 0;
  for (int y = 0; y < shot.height; ++y)
    for (int x = 0; x < shot.width; ++x) {
      const uint8_t* h = heat.at(x, y);
      if (h[0] == kNoErrorGrey && h[1] == kNoErrorGrey && h[2] == kNoErrorGrey) continue;
      ++compared;
      const uint8_t* s = shot.at(x, y);
      for (int k = 0; k < 3; ++k) failing += std::abs(int(h[k]) - int(s[k])) > kHeatCodes;
    }
  EXPECT_EQ(compared, compared_by_the_viewer);
  EXPECT_EQ(failing, 0) << "of " << compared << " heat-map pixels";
}

TEST(ViewReference, MatchesCompareForTheSameView) {
  const fs::path dir = freshTestDir("view-reference");
  const fs::path script = dir / "script.json", overlay = dir / "overlay.png", reference = dir / "reference.png",
                 view = dir / "view.json", stats = dir / "stats.json", cmp = dir / "compare";
  writeText(script, R"({"size": [320, 240], "events": [
      {"at_frame": 1, "do": "reference"},
      {"at_frame": 2, "do": "turn_head", "yaw_deg": 3, "pitch_deg": -1},
      {"at_frame": 3, "do": "reference"},
      {"at_frame": 4, "do": "wipe", "x": 1},
      {"at_frame": 4, "do": "overlay", "on": true},
      {"at_frame": 5, "do": "screenshot", "file": ")" +
                        overlay.string() + R"("},
      {"at_frame": 6, "do": "wipe", "x": 0},
      {"at_frame": 7, "do": "screenshot", "file": ")" +
                        reference.string() + R"("},
      {"at_frame": 7, "do": "save_view", "file": ")" +
                        view.string() + R"("},
      {"at_frame": 8, "do": "quit"}]})");
  CliResult r;
  RUN_VIEW_OR_SKIP("models/car-mirror.json --script '" + script.string() + "' --stats '" + stats.string() + "'", &r);
  ASSERT_EQ(r.code, 0) << r.err;
  const CliResult c = runPvrr("compare '" + view.string() + "' --modes pvrr --frames 1 --out '" + cmp.string() + "'");
  ASSERT_EQ(c.code, 0) << c.err;

  const ImageDiff d =
      compareImages(readPng(reference.string()), readPng((cmp / "reference.png").string()), kReferenceCodes);
  EXPECT_EQ(d.failing_pixels, 0) << describe(d);

  const json live = readJson(stats)["reference"], metrics = readJson(cmp / "metrics.json")["modes"]["pvrr"];
  ASSERT_EQ(live["state"], "done") << live.dump();
  EXPECT_EQ(live["started"], 2);
  EXPECT_EQ(live["worker_frames"], 2);
  EXPECT_GT(live["worker_programs"].get<int>(), 0);                  // the seen-points renderer's, built on the worker
  EXPECT_EQ(live["window_programs_since_start"], 0) << live.dump();  // none on the window's thread
  EXPECT_EQ(live["pixels"], metrics["pixels"]);
  for (const char* q : {"median", "p95"}) {
    const double a = live["angular_error_arcmin"][q], b = metrics["angular_error_arcmin"][q];
    EXPECT_NEAR(a, b, kMedianRelTol * b) << q;
  }
  EXPECT_GT(live["pixels"].get<int>(), 1000);  // the mirror fills a good part of the view

  // The overlay (wipe at 1: the mode's side everywhere) shows compare's heat map at every pixel with an error.
  expectOverlayIsTheHeatMap(readPng((cmp / "pvrr-error.png").string()), readPng(overlay.string()),
                            live["pixels"].get<int>());
  fs::remove_all(dir);
}

// Pixels whose reference path ended at the depth limit (render.max_depth reached on an element: no seen point,
// drawn black): the live reference records them as compare's does, leaves them out of the overlay's figures and
// heat map ('not compared'), and counts them. `scene` at render.max_depth 1, the view saved and compared: the
// median, p95, the compared pixels and the depth-limited count are compare's. Returns the stats' reference part
// (null on a failure above; {"skipped": why} where no X server can be started).
json depthLimitedAgainstCompare(const std::string& name, const std::string& scene) {
  const fs::path dir = freshTestDir("view-reference-depth-limit-" + name);
  const fs::path script = dir / "script.json", overlay = dir / "overlay.png", view = dir / "view.json",
                 stats = dir / "stats.json", cmp = dir / "compare";
  writeText(script, R"({"size": [200, 150], "events": [
      {"at_frame": 1, "do": "reference"},
      {"at_frame": 2, "do": "wipe", "x": 1},
      {"at_frame": 2, "do": "overlay", "on": true},
      {"at_frame": 3, "do": "screenshot", "file": ")" +
                        overlay.string() + R"("},
      {"at_frame": 3, "do": "save_view", "file": ")" +
                        view.string() + R"("},
      {"at_frame": 4, "do": "quit"}]})");
  CliResult r;
  const std::string args =
      scene + " --set render.max_depth=1 --script '" + script.string() + "' --stats '" + stats.string() + "'";
  std::string why;
  if (!runView(args, &r, &why)) return json{{"skipped", why}};
  EXPECT_EQ(r.code, 0) << r.err;
  const CliResult c = runPvrr("compare '" + view.string() + "' --modes pvrr --frames 1 --out '" + cmp.string() + "'");
  EXPECT_EQ(c.code, 0) << c.err;
  if (r.code != 0 || c.code != 0) return json();
  const json all = readJson(cmp / "metrics.json"), live = readJson(stats)["reference"],
             metrics = all["modes"]["pvrr"];
  EXPECT_EQ(live["state"], "done") << live.dump();
  const long limited = all["reference"]["depth_limit_pixels"].get<long>();
  EXPECT_EQ(live["depth_limit_pixels"].get<long>(), limited);
  EXPECT_EQ(live["depth_limit"]["pixels"], metrics["depth_limit"]["pixels"]);
  EXPECT_EQ(live["depth_limit"]["drawn_lit"], metrics["depth_limit"]["drawn_lit"]);
  EXPECT_EQ(live["pixels"], metrics["pixels"]);
  for (const char* q : {"median", "p95"}) {
    const double a = live["angular_error_arcmin"][q], b = metrics["angular_error_arcmin"][q];
    EXPECT_NEAR(a, b, kMedianRelTol * b) << q;
  }
  // The heat map colours only the compared pixels, as compare's does: the depth-limited ones are not compared.
  expectOverlayIsTheHeatMap(readPng((cmp / "pvrr-error.png").string()), readPng(overlay.string()),
                            live["pixels"].get<int>());
  json out = live;
  out["compare_depth_limit_pixels"] = limited;
  fs::remove_all(dir);
  return out;
}

// The mirror pair at render.max_depth 1: the convex mirror's pixels that see the wall mirror end there (1401 of
// 2662 element pixels at 200 x 150); the rest keep their errors, whose median is compare's.
TEST(ViewReference, DepthLimitedPixelsLeftOutAsCompareDoesMirrorPair) {
  const json live = depthLimitedAgainstCompare("pair", "models/mirror-pair.json");
  if (live.contains("skipped")) GTEST_SKIP() << live["skipped"].get<std::string>();
  if (live.is_null()) return;  // failed above
  EXPECT_GT(live["depth_limit_pixels"].get<long>(), 500);
  EXPECT_GT(live["pixels"].get<long>(), 500);  // both kinds in the view: a median of its own
}

// The reading lens at render.max_depth 1 (the hunt's finding 4, tests/app/hunt_cli_test.cpp): its light needs two
// refractions, so every lens pixel's path ends at the depth limit: no error figures, all counted apart.
TEST(ViewReference, DepthLimitedPixelsLeftOutAsCompareDoesReadingLens) {
  const json live = depthLimitedAgainstCompare("lens", "models/reading-lens.json");
  if (live.contains("skipped")) GTEST_SKIP() << live["skipped"].get<std::string>();
  if (live.is_null()) return;
  EXPECT_GT(live["depth_limit_pixels"].get<long>(), 500);  // most of the lens
}

// Spectacles move with the head: the worker's renderer, kept from the first reference, re-poses the lens for the
// turned head as the window does, and the second reference's errors are compare's of the saved view.
TEST(ViewReference, SpectaclesTurnedWithTheHeadMatchCompare) {
  const fs::path dir = freshTestDir("view-reference-lens");
  const fs::path script = dir / "script.json", view = dir / "view.json", stats = dir / "stats.json",
                 cmp = dir / "compare";
  writeText(script, R"({"size": [200, 150], "events": [
      {"at_frame": 1, "do": "reference"},
      {"at_frame": 2, "do": "turn_head", "yaw_deg": 4, "pitch_deg": 2},
      {"at_frame": 3, "do": "reference"},
      {"at_frame": 4, "do": "save_view", "file": ")" +
                        view.string() + R"("},
      {"at_frame": 5, "do": "quit"}]})");
  CliResult r;
  RUN_VIEW_OR_SKIP("models/spectacle-lens.json --script '" + script.string() + "' --stats '" + stats.string() + "'",
                   &r);
  ASSERT_EQ(r.code, 0) << r.err;
  const CliResult c = runPvrr("compare '" + view.string() + "' --modes pvrr --frames 1 --out '" + cmp.string() + "'");
  ASSERT_EQ(c.code, 0) << c.err;
  const json live = readJson(stats)["reference"], metrics = readJson(cmp / "metrics.json")["modes"]["pvrr"];
  ASSERT_EQ(live["state"], "done") << live.dump();
  EXPECT_EQ(live["worker_frames"], 2);
  EXPECT_EQ(live["window_programs_since_start"], 0);
  EXPECT_EQ(live["pixels"], metrics["pixels"]);
  for (const char* q : {"median", "p95"}) {
    const double a = live["angular_error_arcmin"][q], b = metrics["angular_error_arcmin"][q];
    EXPECT_NEAR(a, b, kMedianRelTol * b) << q;
  }
  fs::remove_all(dir);
}

// A light with caustics on: the live reference adds the caustic light as compare's reference does (the burning
// lens's focal spot on the table, whose brightest pixels are several times the sun's irradiance), pixel for
// pixel. Without it the spot's pixels differ by tens of codes and the lens passes the sun by Fresnel.
TEST(ViewReference, CausticLightMatchesCompare) {
  const fs::path dir = freshTestDir("view-reference-caustic");
  const fs::path script = dir / "script.json", reference = dir / "reference.png", view = dir / "view.json",
                 stats = dir / "stats.json", cmp = dir / "compare";
  writeText(script, R"({"size": [160, 120], "events": [
      {"at_frame": 1, "do": "reference"},
      {"at_frame": 2, "do": "wipe", "x": 0},
      {"at_frame": 3, "do": "screenshot", "file": ")" +
                        reference.string() + R"("},
      {"at_frame": 3, "do": "save_view", "file": ")" +
                        view.string() + R"("},
      {"at_frame": 4, "do": "quit"}]})");
  CliResult r;
  RUN_VIEW_OR_SKIP("models/burning-lens.json --script '" + script.string() + "' --stats '" + stats.string() + "'",
                   &r);
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(readJson(stats)["reference"]["state"], "done");
  const CliResult c = runPvrr("compare '" + view.string() + "' --modes pvrr --frames 1 --out '" + cmp.string() + "'");
  ASSERT_EQ(c.code, 0) << c.err;
  const ImageRGB8 ref = readPng((cmp / "reference.png").string());
  const ImageDiff d = compareImages(readPng(reference.string()), ref, kReferenceCodes);
  EXPECT_EQ(d.failing_pixels, 0) << describe(d);
  // The comparison covers the spot: compare's reference shows it (saturated pixels on the table).
  int saturated = 0;
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x) saturated += ref.at(x, y)[0] == 255 && ref.at(x, y)[1] == 255;
  EXPECT_GT(saturated, 0);
  fs::remove_all(dir);
}

// The split line follows a drag that starts on it; a drag elsewhere turns the head, which makes the reference
// another view's: it is discarded, saying why.
TEST(ViewReference, DragMovesTheSplitLineOrTurnsTheHead) {
  const fs::path dir = freshTestDir("view-reference-drag");
  const fs::path script = dir / "script.json", stats = dir / "stats.json", line = dir / "line.json";
  // 256 px wide: the line starts at 0.5 x 256 = 128.
  writeText(script, R"({"size": [256, 192], "events": [
      {"at_frame": 1, "do": "reference"},
      {"at_frame": 2, "do": "drag", "from": [130, 100], "to": [64, 90]},
      {"at_frame": 3, "do": "quit"}]})");
  CliResult r;
  RUN_VIEW_OR_SKIP("models/plane-mirror.json --script '" + script.string() + "' --stats '" + stats.string() + "'", &r);
  ASSERT_EQ(r.code, 0) << r.err;
  const json a = readJson(stats)["reference"];
  EXPECT_EQ(a["state"], "done") << a.dump();
  EXPECT_DOUBLE_EQ(a["wipe_x"].get<double>(), 0.25);

  writeText(script, R"({"size": [256, 192], "events": [
      {"at_frame": 1, "do": "reference"},
      {"at_frame": 2, "do": "drag", "from": [30, 100], "to": [40, 100]},
      {"at_frame": 4, "do": "quit"}]})");
  RUN_VIEW_OR_SKIP("models/plane-mirror.json --script '" + script.string() + "' --stats '" + stats.string() + "'", &r);
  ASSERT_EQ(r.code, 0) << r.err;
  const json b = readJson(stats)["reference"];
  EXPECT_EQ(b["state"], "discarded") << b.dump();
  EXPECT_EQ(b["note"], "discarded: the view changed");
  EXPECT_DOUBLE_EQ(b["wipe_x"].get<double>(), 0.5);
  fs::remove_all(dir);
}

// Closing the window while the reference traces: exit 0, the tracing threads stopped, no file but the stats
// asked for. At 1280 x 720 the trace takes far longer than the two frames before the quit.
TEST(ViewReference, ClosingMidReferenceExitsCleanly) {
  const fs::path dir = freshTestDir("view-reference-close");
  const fs::path script = dir / "script.json", stats = dir / "stats.json";
  writeText(script, R"({"size": [1280, 720], "events": [
      {"at_frame": 1, "do": "key", "key": "T"},
      {"at_frame": 3, "do": "quit"}]})");
  CliResult r;
  RUN_VIEW_OR_SKIP("models/car-mirror.json --script '" + script.string() + "' --stats '" + stats.string() + "'", &r);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const json s = readJson(stats)["reference"];
  EXPECT_EQ(s["state"], "cancelled") << s.dump();
  EXPECT_EQ(s["note"], "cancelled: the window closed");
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 2);  // the script and the stats
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pvrr::test
