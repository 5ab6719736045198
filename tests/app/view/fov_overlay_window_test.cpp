// The viewer's field-of-view overlay (app/view/fov_overlay.*; issue 21 item 7; label `window`): seen from above,
// the pixels it changes are the road the mirror's footprint (pvrr fov's, at the same sampling) covers, and no others.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "app/run_pvrr.h"
#include "app/view/run_view.h"
#include "pvrr/analysis/fov.h"
#include "pvrr/base/image.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr::test {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 320, kH = 240;
// A pixel is changed when a channel moved by more than this (8-bit codes): the overlay's translucent colours move
// the road's by 40 or more, two frames of the same view by 0.
constexpr int kChanged = 20;
// Pixels within this many pixels of the predicted footprint's edge are not judged (the overlay's cells and the
// prediction's polygon are two samplings of the same edge).
constexpr int kEdgePx = 2;

// Seen from 25 m above the road behind the car, looking down (the car's forward up in the picture).
const char* kView =
    "--set 'observer.eye=[-2.5, 25, 12]' --set 'observer.target=[-2.5, 0, 12]' --set 'observer.up=[0, 0, -1]' "
    "--set 'observer.image_size=[320, 240]' --set render.mode=raster";

// The overlay's run (`extra`: more options for pvrr view and pvrr fov, `fov_eyes`: pvrr fov's --eyes) seen from
// above, its pixels compared with pvrr fov's footprint polygons at the overlay's sampling: every pixel whose ray meets
// the road inside one is changed, and no other (pixels within kEdgePx of an edge not judged). Returns the overlay's
// --stats (null when the run failed, or could not start: `skip` then says why).
nlohmann::json overlayMatchesFootprint(const std::string& name, const std::string& extra, const std::string& fov_eyes,
                                       const std::vector<std::string>& sets, std::string* skip) {
  const fs::path dir = freshTestDir(name);
  const fs::path script = dir / "script.json", stats = dir / "stats.json";
  const fs::path off = dir / "off.png", on = dir / "on.png";
  writeText(script, R"({"size": [320, 240], "events": [
      {"at_frame": 1, "do": "key", "key": "TAB"},
      {"at_frame": 2, "do": "screenshot", "file": ")" +
                        off.string() + R"(", "panel": true},
      {"at_frame": 3, "do": "key", "key": "O"},
      {"at_frame": 4, "do": "screenshot", "file": ")" +
                        on.string() + R"(", "panel": true},
      {"at_frame": 6, "do": "quit"}]})");
  CliResult r;
  if (!runView("models/car-mirror.json " + std::string(kView) + extra + " --script '" + script.string() +
                   "' --stats '" + stats.string() + "'",
               &r, skip))
    return nlohmann::json();
  EXPECT_EQ(r.code, 0) << r.err;
  if (r.code != 0) return nlohmann::json();
  const nlohmann::json st = nlohmann::json::parse(std::ifstream(stats))["fov_overlay"];
  EXPECT_TRUE(st["on"].get<bool>());
  EXPECT_EQ(st["traces"].get<int>(), 1);  // traced once for the pose, not per frame (three frames drew it)
  EXPECT_GT(st["cells_drawn"].get<int>(), 100);

  // The prediction: pvrr fov's footprints at the overlay's sampling, each pixel's ray met with the road.
  const CliResult f = runPvrr("fov models/car-mirror.json --samples 41 --eyes " + fov_eyes + extra + " --out '" +
                              (dir / "fov").string() + "'");
  EXPECT_EQ(f.code, 0) << f.err;
  if (f.code != 0) return nlohmann::json();
  const nlohmann::json fp = nlohmann::json::parse(slurp(dir / "fov" / "fov.json"))["footprint"];
  std::vector<std::vector<Vec2>> polys;
  for (const char* eye : {"left", "right"}) {
    std::vector<Vec2> p;
    EXPECT_FALSE(fp[eye]["polygon"].is_null()) << eye;
    for (const auto& v : fp[eye]["polygon"]) p.push_back(Vec2(v[0].get<double>(), v[1].get<double>()));
    polys.push_back(p);
  }
  std::vector<std::string> all = {"observer.eye=[-2.5, 25, 12]", "observer.target=[-2.5, 0, 12]",
                                  "observer.up=[0, 0, -1]", "observer.image_size=[320, 240]"};
  all.insert(all.end(), sets.begin(), sets.end());
  const SceneDesc desc = loadScene(PVRR_SOURCE_DIR "/models/car-mirror.json", all);
  const Scene scene = buildScene(desc);
  const VehicleFrame frame(*desc.vehicle);
  const Observer& ob = scene.observer;
  std::vector<int> inside(size_t(kW) * kH, 0);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const Vec3 d = glm::normalize(ob.pixelDirection(x + 0.5, y + 0.5));
      EXPECT_LT(d.y, 0);  // every pixel looks down at the road (y = 0)
      const Vec3 q = frame.toVehicle(ob.eye - (ob.eye.y / d.y) * d);
      for (const auto& p : polys) inside[size_t(y) * kW + x] |= insidePolygon(p, Vec2(q.x, q.y)) ? 1 : 0;
    }

  const ImageRGB8 a = readPng(off.string()), b = readPng(on.string());
  EXPECT_EQ(a.width, kW);
  EXPECT_EQ(b.height, kH);
  int in = 0, in_changed = 0, out = 0, out_changed = 0;
  for (int y = kEdgePx; y < kH - kEdgePx; ++y)
    for (int x = kEdgePx; x < kW - kEdgePx; ++x) {
      const int label = inside[size_t(y) * kW + x];
      bool uniform = true;
      for (int dy = -kEdgePx; dy <= kEdgePx; ++dy)
        for (int dx = -kEdgePx; dx <= kEdgePx; ++dx) uniform = uniform && inside[size_t(y + dy) * kW + x + dx] == label;
      if (!uniform) continue;
      int diff = 0;
      for (int c = 0; c < 3; ++c) diff = std::max(diff, std::abs(int(a.at(x, y)[c]) - int(b.at(x, y)[c])));
      (label ? in : out)++;
      if (diff > kChanged) (label ? in_changed : out_changed)++;
      if (label && diff <= kChanged && std::getenv("PVRR_DEBUG_OVERLAY"))
        std::printf("unchanged inside at %d %d: diff %d, rgb %d %d %d\n", x, y, diff, a.at(x, y)[0], a.at(x, y)[1],
                    a.at(x, y)[2]);
    }
  std::printf("%s: predicted footprint: %d pixels, %d changed; elsewhere: %d pixels, %d changed\n", name.c_str(), in,
              in_changed, out, out_changed);
  EXPECT_GT(in, 2000);  // the footprint fills a good part of the picture: the check is not about a few pixels
  EXPECT_GT(out, 2000);
  EXPECT_EQ(in_changed, in);
  EXPECT_EQ(out_changed, 0);
  nlohmann::json result = st;
  result["predicted_pixels"] = in;
  if (!std::getenv("PVRR_DEBUG_OVERLAY")) fs::remove_all(dir);
  return result;
}

TEST(ViewFovOverlay, OverlayCoversTheRoadTheFootprintPredicts) {
  std::string skip;
  const nlohmann::json st = overlayMatchesFootprint("view-fov-overlay", "", "both", {}, &skip);
  if (!skip.empty()) GTEST_SKIP() << skip;
  if (st.is_null()) return;
  EXPECT_EQ(st["eyes"], "ocular points");
  EXPECT_EQ(st["eye_samples"], 2);
}

// With an eye ellipse in the scene the overlay follows it: per eye the union of its 15 samples' footprints, the
// polygons pvrr fov --eyes ellipse writes (a J941-like ellipse, as in FovCli.EyeEllipse).
TEST(ViewFovOverlay, OverlayFollowsTheSceneEyeEllipse) {
  const std::string ellipse = R"(vehicle.eye_ellipse={"axes": [0.2, 0.06, 0.09], "tilt_deg": 12})";
  std::string skip;
  const nlohmann::json st =
      overlayMatchesFootprint("view-fov-overlay-ellipse", " --set '" + ellipse + "'", "ellipse", {ellipse}, &skip);
  if (!skip.empty()) GTEST_SKIP() << skip;
  if (st.is_null()) return;
  EXPECT_EQ(st["eyes"], "ellipse");
  EXPECT_EQ(st["eye_samples"], 30);
  EXPECT_FALSE(st["per_sample"].get<bool>());  // each eye's union is one loop
  EXPECT_GT(st["triangles"].get<int>(), 100);
}

}  // namespace
}  // namespace pvrr::test
