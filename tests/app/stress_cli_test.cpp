// Stiff cases as a user meets them (issue 26): map sizes beyond what the GL can hold, the eye behind a mirror
// or a lens, lens surfaces that cross, and the issue's extreme scenes in every raster mode. Each is either
// refused (exit 1, one line naming the scene and the setting or element, no output file) or rendered, and a
// rendered picture agrees with the reference tracer's (median under 60') or is flagged in the stats and on
// the command line, never wrong and passed as good.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/run_pvrr.h"
#include "pvrr/base/image.h"

namespace fs = std::filesystem;

namespace {

using pvrr::test::CliResult;
using pvrr::test::runPvrr;

class StressCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = pvrr::test::freshTestDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

// A curved mirror facing +z at the origin, a red ball in front of it and a green one behind it.
const char* kMirrorScene = R"({
  "version": 1,
  "observer": {"eye": [0, 0, 1], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 45, "image_size": [64, 48]},
  "environment": [{"type": "sphere", "name": "red", "centre": [0.3, 0, 2], "radius": 0.5, "material": {"color": [0.8, 0.2, 0.2]}},
                  {"type": "sphere", "name": "green", "centre": [0.3, 0, -3], "radius": 0.5, "material": {"color": [0.2, 0.8, 0.2]}}],
  "lights": [{"type": "ambient", "color": [1, 1, 1]}],
  "elements": [{"name": "left", "type": "mirror", "pose": {"position": [0, 0, 0], "normal": [0, 0, 1], "up": [0, 1, 0]},
                "outline": {"shape": "rectangle", "width": 0.5, "height": 0.5}, "surface": {"type": "sphere", "radius": 1.0},
                "tessellation": 7, "material": {"metal": "silver"}}]
})";

// The mean absolute difference of two PNGs of the same size, in 8-bit code values over all channels.
double meanCodeDifference(const std::string& a, const std::string& b) {
  const pvrr::ImageRGB8 x = pvrr::readPng(a), y = pvrr::readPng(b);
  EXPECT_EQ(x.rgb.size(), y.rgb.size());
  double sum = 0;
  for (size_t i = 0; i < std::min(x.rgb.size(), y.rgb.size()); ++i) sum += std::abs(int(x.rgb[i]) - int(y.rgb[i]));
  return sum / double(std::max<size_t>(1, x.rgb.size()));
}

// --- map sizes against the GL's limits and memory (pvrr/method/map_limits.h) ---

TEST_F(StressCli, MapSizeBeyondTheMemoryBudgetIsRefusedBeforeAnyPass) {
  const std::string scene = write("maps.json", kMirrorScene), out = path("out.png"), stats = path("stats.json");
  ::setenv("PVRR_GPU_MEMORY_MB", "64", 1);
  // pvrr: one 4096^2 map of colour and depth (20 B a texel: 320 MiB); envmap: a 2048^2 cube (6 x 8 B + 4 B).
  const CliResult pvrr = runPvrr("render '" + scene + "' --gl osmesa --set render.map_size=4096 --out '" + out +
                                 "' --stats '" + stats + "'");
  pvrr::test::expectOneLineError(pvrr,
                {"maps.json: render.map_size 4096: pvrr mode needs at least 320",
                 "memory budget of 64 MiB (PVRR_GPU_MEMORY_MB)", "the largest render.map_size that fits is "},
                {out, stats});
  const CliResult envmap =
      runPvrr("render '" + scene + "' --gl osmesa --mode envmap --set render.map_size=2048 --out '" + out + "'");
  pvrr::test::expectOneLineError(envmap, {"maps.json: render.map_size 2048: envmap mode needs at least"}, {out});
  const CliResult fits = runPvrr("render '" + scene + "' --gl osmesa --set render.map_size=1024 --out '" + out + "'");
  ::unsetenv("PVRR_GPU_MEMORY_MB");
  EXPECT_EQ(fits.code, 0) << fits.err;  // the same budget holds a 1024^2 map
  EXPECT_TRUE(fs::exists(out));
}

TEST_F(StressCli, TheLargestMapSizeTheRefusalAdvisesRenders) {
  const std::string scene = write("maps.json", kMirrorScene), out = path("out.png");
  ::setenv("PVRR_GPU_MEMORY_MB", "40", 1);
  const CliResult refused =
      runPvrr("render '" + scene + "' --gl osmesa --set render.map_size=2048 --out '" + out + "'");
  const size_t at = refused.err.find("fits is ");
  ASSERT_NE(at, std::string::npos) << refused.err;
  const int best = std::atoi(refused.err.c_str() + at + 8);
  EXPECT_GT(best, 1024);
  EXPECT_LT(best, 2048);
  const CliResult ok = runPvrr("render '" + scene + "' --gl osmesa --set render.map_size=" + std::to_string(best) +
                               " --out '" + out + "'");
  ::unsetenv("PVRR_GPU_MEMORY_MB");
  EXPECT_EQ(ok.code, 0) << ok.err;
}

TEST_F(StressCli, AMalformedMemoryBudgetIsOneLine) {
  const std::string scene = write("maps.json", kMirrorScene), out = path("out.png");
  ::setenv("PVRR_GPU_MEMORY_MB", "lots", 1);
  const CliResult r = runPvrr("render '" + scene + "' --gl osmesa --out '" + out + "'");
  ::unsetenv("PVRR_GPU_MEMORY_MB");
  pvrr::test::expectOneLineError(r, {"PVRR_GPU_MEMORY_MB: expected a positive number of MiB, got \"lots\""}, {out});
}

// --- the eye on or behind an element (pvrr/method/eye_side.h) ---

TEST_F(StressCli, EyeBehindAMirrorIsExplainedAndDrawnAsTheReference) {
  std::string text = kMirrorScene;
  text.replace(text.find("\"eye\": [0, 0, 1]"), 16, "\"eye\": [0, 0, -1]");  // behind the mirror's back
  const std::string scene = write("behind.json", text), out = path("pvrr.png"), ref = path("ref.png"),
                    stats = path("stats.json");
  const CliResult r = runPvrr("render '" + scene + "' --gl osmesa --out '" + out + "' --stats '" + stats + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string note =
      "the eye is behind mirror 'left' (its back side faces the eye): nothing is reflected toward it";
  EXPECT_NE(r.out.find("note: " + note), std::string::npos) << r.out;
  EXPECT_NE(pvrr::test::slurp(stats).find(note), std::string::npos);
  ASSERT_EQ(runPvrr("render '" + scene + "' --mode raytrace --out '" + ref + "'").code, 0);
  EXPECT_LT(meanCodeDifference(out, ref), 1.0);  // the dark back and the green ball beside it, as traced
  // From the front the same mirror gets no note.
  const CliResult front = runPvrr("render '" + write("front.json", kMirrorScene) + "' --gl osmesa --out '" + out + "'");
  ASSERT_EQ(front.code, 0) << front.err;
  EXPECT_EQ(front.out.find("note:"), std::string::npos) << front.out;
}

// The reading lens seen from behind: pvrr mode's vertex rays enter a lens at its front, so before this the
// picture was garbage (PSNR 1.5 dB against the reference, exit 0, verdict good).
TEST_F(StressCli, EyeBehindALensIsFlaggedAndDrawnFromTheTracer) {
  const std::string sets = " --set 'observer.eye=[0,0.85,0.06]' --set 'observer.target=[0,1.25,0.3]' --size 96x72";
  const std::string out = path("pvrr.png"), ref = path("ref.png"), front = path("front.png"),
                    front_ref = path("front-ref.png");
  const CliResult r = runPvrr("render models/reading-lens.json --gl osmesa --out '" + out + "'" + sets);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("note: the eye is behind lens 'reading-lens' (its back surface faces the eye)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("quality: reading-lens fallback"), std::string::npos) << r.out;
  ASSERT_EQ(runPvrr("render models/reading-lens.json --mode raytrace --out '" + ref + "'" + sets).code, 0);
  const double behind = meanCodeDifference(out, ref);
  // The same lens from the front (verdict good) for scale: the traced vertex colours are interpolated.
  ASSERT_EQ(runPvrr("render models/reading-lens.json --gl osmesa --size 96x72 --out '" + front + "'").code, 0);
  ASSERT_EQ(runPvrr("render models/reading-lens.json --mode raytrace --size 96x72 --out '" + front_ref + "'").code, 0);
  const double from_front = meanCodeDifference(front, front_ref);
  EXPECT_LT(behind, 4.0) << "from the front: " << from_front;
}

// --- lens surfaces that cross or touch (cad::makeLens, named by the scene build) ---

TEST_F(StressCli, LensSurfacesThatCrossOrTouchAreRefusedNamingTheElement) {
  const std::string out = path("out.png");
  // The reading lens's edge is 1.57 mm thick at 5 mm in the centre: at 3 mm its surfaces cross near the rim.
  pvrr::test::expectOneLineError(
      runPvrr("render models/reading-lens.json --gl osmesa --set elements[0].centre_thickness=0.003 --out '" + out +
              "'"),
      {"reading-lens.json: elements[0] (reading-lens): the surfaces cross or touch inside the outline: thickness -"},
      {out});
  // A meniscus whose front is more curved than its back: at 1 mm in the centre, the thickness 1 mm - r^2 / 0.4 m
  // reaches 0 at r = 20 mm, between the centre and the 30 mm rim.
  const std::string meniscus = write("meniscus.json", R"({
  "version": 1,
  "observer": {"eye": [0, 0, 0.3], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 30, "image_size": [32, 24]},
  "environment": [{"type": "sphere", "name": "ball", "centre": [0, 0, -2], "radius": 0.5, "material": {"color": [0.5, 0.5, 0.5]}}],
  "lights": [{"type": "ambient", "color": [1, 1, 1]}],
  "elements": [{"name": "thin", "type": "lens", "pose": {"position": [0, 0, 0], "normal": [0, 0, 1], "up": [0, 1, 0]},
                "outline": {"shape": "circle", "diameter": 0.06}, "front": {"type": "sphere", "radius": 0.1},
                "back": {"type": "sphere", "radius": 0.2}, "centre_thickness": 0.001, "tessellation": 9,
                "material": {"name": "cr39"}}]
})");
  pvrr::test::expectOneLineError(runPvrr("render '" + meniscus + "' --gl osmesa --out '" + out + "'"),
                {"meniscus.json: elements[0] (thin): the surfaces cross or touch inside the outline"}, {out});
  // Touching at the rim: 2 (R - sqrt(R^2 - r^2)) = 3.4260252 mm of sag at R 0.46787 m, r 40 mm leaves the
  // surfaces 4e-12 m apart across the rim (a contact, as far as any lens tolerance goes).
  pvrr::test::expectOneLineError(
      runPvrr("render models/reading-lens.json --gl osmesa --set elements[0].centre_thickness=0.0034260252 --out '" +
              out + "'"),
      {"reading-lens.json: elements[0] (reading-lens): the surfaces cross or touch inside the outline"}, {out});
}

// --- the issue's extreme scenes in every raster mode: right, or flagged (pvrr/method/frame_quality.h,
// pvrr/method/cube_quality.h) ---

// The issue's line between a right picture and a wrong one.
constexpr double kRightArcmin = 60.0;

struct ExtremeCase {
  const char* name;
  std::string scene;  // relative to the source tree
  std::string sets;   // --set options and the size
  std::vector<std::string> must_be_right;  // modes whose picture must be right (fixed, or right by design)
  double impostor_min_psnr_db = 0;          // impostor mode's colour PSNR against the reference must exceed it
};

// Its name in gtest's messages (gtest prints a parameter's bytes otherwise).
void PrintTo(const ExtremeCase& c, std::ostream* os) { *os << c.name; }

std::vector<ExtremeCase> extremeCases() {
  const std::string small = " --size 64x48";
  return {
      // A 100 m mirror 10 km away: impostor mode's cubes could not order depths with a 1 mm near plane.
      {"far mirror", "tests/data/stress/far-mirror.json", small, {"pvrr", "impostor"}},
      // Two facing plane mirrors: envmap's parallax (flagged). Impostor mode: the back mirror's rays that pass
      // behind the red ball and over the front mirror's edge escape to the sky (they ended on the front
      // mirror's texel and went on in its cubes: 1.4' median, 37 % of the searches off the maps, PSNR 13.4 dB),
      // now 0.014' median, 1.1 % off the maps (still flagged: the depth edges of the nested reflections,
      // p95 7454'), PSNR 20.1 dB (pvrr mode 20.9 dB).
      {"mirror tunnel", "tests/data/stress/mirror-tunnel.json", small, {"pvrr", "impostor"}, 18.0},
      // 1 m of sag at the rim, 87 deg slopes: the reference and impostor mode agree (0.07' median).
      {"steep asphere", "tests/data/stress/steep-asphere.json", small, {"impostor"}},
      // A 35 mm thick biconvex lens of radii 45 mm: total internal reflection over much of it.
      {"thick lens with TIR", "models/reading-lens.json",
       R"( --set 'elements[0].front={"type":"sphere","radius":0.045}' --set 'elements[0].back={"type":"sphere","radius":-0.045}')"
       R"( --set elements[0].centre_thickness=0.035 --set 'elements[0].outline={"shape":"circle","diameter":0.07}')" +
           small,
       {"pvrr", "impostor"}},  // pvrr: refined where the traced directions spread (24' -> 4.1' here), still flagged
      // About -30 D: a toric front of radii 14.6 and 20 mm, 25 mm across.
      {"toric lens of -30 D", "models/spectacle-lens.json",
       R"( --set 'elements[0].front={"type":"toric","radius_a":-0.0146,"radius_b":-0.02}' --set elements[0].centre_thickness=0.001)"
       R"( --set 'elements[0].outline={"shape":"circle","diameter":0.025}')" + small,
       {"pvrr", "envmap", "impostor"}},
      // The reading lens seen from below its back surface.
      {"lens seen from behind", "models/reading-lens.json",
       " --set 'observer.eye=[0,0.85,0.06]' --set 'observer.target=[0,1.25,0.3]'" + small, {"pvrr", "impostor"}},
      // The mirror pair with the wall mirror turned to the wall: seen from behind inside the convex mirror.
      {"nested mirror seen from behind", "models/mirror-pair.json", " --set 'elements[1].pose.normal=[0,0,1]'" + small,
       {"pvrr", "impostor"}},
      // A lens behind the observer with its front turned away from a plane mirror: the mirror's viewpoint sees
      // its back (a nested element seen from behind).
      {"nested lens seen from behind", "tests/data/stress/lens-behind-in-mirror.json", small, {"pvrr"}},
      // The issue's toric mirror (radius 0.05 m across 80 mm against -50 m): right in pvrr mode by default.
      {"toric mirror", "models/car-mirror.json",
       R"( --set 'elements[0].surface={"type":"toric","radius_a":0.05,"radius_b":-50}')"
       R"( --set 'elements[0].outline={"shape":"circle","diameter":0.08}' --set elements[0].tessellation=15)"
       " --size 160x120",  // the mirror covers 44 pixels at 64 x 48
       {"pvrr", "impostor"}},
  };
}

class ExtremeScene : public StressCli, public ::testing::WithParamInterface<ExtremeCase> {};

TEST_P(ExtremeScene, RightOrFlaggedInEveryRasterMode) {
  const ExtremeCase& c = GetParam();
  {
    const std::string out = path("compare");
    const CliResult r =
        runPvrr("compare '" + c.scene + "' --modes pvrr,envmap,impostor --gl osmesa --out '" + out + "'" + c.sets);
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json m = nlohmann::json::parse(pvrr::test::slurp(out + "/metrics.json"));
    for (const std::string mode : {"pvrr", "envmap", "impostor"}) {
      const nlohmann::json& j = m["modes"][mode];
      ASSERT_GT(j["pixels"].get<long>(), 100) << mode;
      const double median = j["angular_error_arcmin"]["median"].get<double>();
      ASSERT_TRUE(std::isfinite(median)) << mode;
      std::vector<std::string> flagged;
      for (const nlohmann::json& e : j["element_stats"])
        if (e["quality"]["verdict"] != "good") flagged.push_back(e["name"].get<std::string>());
      std::cout << "[ measured ] " << c.name << ", " << mode << ": median " << median << "', "
                << (flagged.empty() ? "good" : "flagged") << "\n";
      const bool must = std::find(c.must_be_right.begin(), c.must_be_right.end(), mode) != c.must_be_right.end();
      if (must) {
        EXPECT_LT(median, kRightArcmin) << mode;
      }
      if (mode == "impostor") {
        EXPECT_GT(j["psnr_db"].get<double>(), c.impostor_min_psnr_db) << mode;
      }
      if (median >= kRightArcmin) {
        EXPECT_FALSE(flagged.empty()) << mode << ": median " << median << "' and good";
      }
      // Each flagged element has its line on the command line.
      for (const std::string& name : flagged) {
        // compare's prefix: the mode padded to 8 characters (app/compare.cpp).
        const std::string prefix =
            mode + std::string(mode.size() < 8 ? 8 - mode.size() : 0, ' ') + " quality: " + name + " ";
        EXPECT_NE(r.out.find(prefix), std::string::npos) << prefix << "\n" << r.out;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Issue26, ExtremeScene, ::testing::ValuesIn(extremeCases()),
                         [](const ::testing::TestParamInfo<ExtremeCase>& i) {
                           std::string n;
                           for (const char ch : std::string(i.param.name)) n += std::isalnum(ch) ? ch : '_';
                           return n;
                         });

}  // namespace
