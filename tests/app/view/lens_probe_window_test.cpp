// The viewer's lens probe (app/view/lens_probe.*; issue 27 item 5; label `window`): the readings shown for the
// lens point under the cursor are pvrr lensmap's at the gaze through that point.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>

#include "app/run_pvrr.h"
#include "app/view/run_view.h"
#include "pvrr/analysis/lensmap.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr::test {
namespace {

namespace fs = std::filesystem;

// The lens point: the same exact intersection of the same pixel ray, in another process: double rounding.
constexpr double kPointTol_mm = 1e-9;
// The readings: the same analysis at the same gaze (the stats print 17 digits).
constexpr double kReadingTol = 1e-9;

TEST(ViewLensProbe, ReadingsUnderTheCursorAreTheLensMapsThere) {
  const fs::path dir = freshTestDir("view-lens-probe");
  const fs::path script = dir / "script.json", stats = dir / "stats.json";
  constexpr int kX = 230, kY = 80;  // right of and above the lens centre (the picture's centre is 160, 120)
  // First another point of the lens: the reading checked below comes from the lens map built for that one.
  writeText(script, R"({"size": [320, 240], "events": [
      {"at_frame": 1, "do": "cursor", "at": [190.5, 130.5]},
      {"at_frame": 2, "do": "cursor", "at": [230.3, 80.7]},
      {"at_frame": 4, "do": "quit"}]})");
  CliResult r;
  RUN_VIEW_OR_SKIP("models/spectacle-lens.json --script '" + script.string() + "' --stats '" + stats.string() + "'",
                   &r);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json probe = nlohmann::json::parse(std::ifstream(stats))["lens_probe"];
  ASSERT_TRUE(probe["valid"].get<bool>()) << probe.dump();
  EXPECT_EQ(probe["lensmaps_built"], 1);  // one lens map for both points: the lens did not move
  EXPECT_EQ(probe["pixel"][0], kX + 0.5);
  EXPECT_EQ(probe["pixel"][1], kY + 0.5);

  // The same view built here: the lens point under that pixel, independently.
  SceneDesc desc = loadScene(PVRR_SOURCE_DIR "/models/spectacle-lens.json", {"observer.image_size=[320,240]"});
  Scene scene = buildScene(desc);
  const RayScene rays(scene);
  const Observer& ob = scene.observer;
  const RayHit hit = rays.intersect(ob.eye, glm::normalize(ob.pixelDirection(kX + 0.5, kY + 0.5)));
  ASSERT_EQ(hit.kind, HitKind::Element);
  const Element& el = scene.elements[size_t(hit.element)];
  const Vec3 p = el.toLocalPoint(hit.point);
  // The reading's chief ray crosses the eye-side surface at that point: its gaze looks through it.
  EXPECT_NEAR(probe["lens_x_mm"].get<double>(), 1e3 * p.x, kPointTol_mm);
  EXPECT_NEAR(probe["lens_y_mm"].get<double>(), 1e3 * p.y, kPointTol_mm);

  // And the readings are the lens map's at that gaze, against the lens centre.
  LensmapOptions o;
  o.rotation_centre_m = el.eye_rotation_centre_m;
  const Lensmap map(rays, hit.element, o);
  const LensmapPoint centre = map.evaluate(0, 0);
  const LensmapPoint want = map.evaluate(probe["gaze_x_deg"], probe["gaze_y_deg"], &centre);
  ASSERT_TRUE(want.valid);
  for (const auto& [name, v] :
       {std::pair{"sphere_d", want.sphere_d}, std::pair{"cylinder_d", want.cylinder_d},
        std::pair{"axis_deg", want.axis_deg}, std::pair{"mean_power_d", want.mean_power_d},
        std::pair{"power_error_d", want.power_error_d}, std::pair{"unwanted_cylinder_d", want.unwanted_cylinder_d},
        std::pair{"prism_h", want.prism_h}, std::pair{"prism_v", want.prism_v}})
    EXPECT_NEAR(probe[name].get<double>(), v, kReadingTol) << name;
  // Seen right of and above the centre of a minus lens: base right and base up (Prentice).
  EXPECT_GT(probe["prism_h"].get<double>(), 0);
  EXPECT_GT(probe["prism_v"].get<double>(), 0);
  fs::remove_all(dir);
}

// Where the cursor is off the lens, the probe says so.
TEST(ViewLensProbe, SaysWhenNoLensIsUnderTheCursor) {
  const fs::path dir = freshTestDir("view-lens-probe-miss");
  const fs::path script = dir / "script.json", stats = dir / "stats.json";
  writeText(script, R"({"size": [320, 240], "events": [
      {"at_frame": 1, "do": "cursor", "at": [-5, 10]},
      {"at_frame": 3, "do": "quit"}]})");
  CliResult r;
  RUN_VIEW_OR_SKIP("models/spectacle-lens.json --script '" + script.string() + "' --stats '" + stats.string() + "'",
                   &r);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json probe = nlohmann::json::parse(std::ifstream(stats))["lens_probe"];
  EXPECT_FALSE(probe["valid"].get<bool>());
  EXPECT_EQ(probe["reason"], "outside the picture");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pvrr::test
