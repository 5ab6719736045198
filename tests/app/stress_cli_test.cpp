// Stiff cases as a user meets them (issue 26): map sizes beyond what the GL can hold, the eye behind a mirror
// or a lens, lens surfaces that cross. Each is either refused (exit 1, one line naming the scene and the
// setting or element, no output file) or rendered with a note, and a rendered picture agrees with the
// reference tracer's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

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

  // Exit code 1, exactly one line on stderr holding every piece of `parts`, and none of `outputs` written.
  static void expectRefusal(const CliResult& r, std::initializer_list<std::string> parts,
                            std::initializer_list<std::string> outputs) {
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "expected one line, got:\n" << r.err;
    for (const std::string& p : parts)
      EXPECT_NE(r.err.find(p), std::string::npos) << "no \"" << p << "\" in: " << r.err;
    for (const std::string& o : outputs) EXPECT_FALSE(fs::exists(o)) << o;
  }

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
  expectRefusal(pvrr,
                {"maps.json: render.map_size 4096: pvrr mode needs at least 320",
                 "memory budget of 64 MiB (PVRR_GPU_MEMORY_MB)", "the largest render.map_size that fits is "},
                {out, stats});
  const CliResult envmap =
      runPvrr("render '" + scene + "' --gl osmesa --mode envmap --set render.map_size=2048 --out '" + out + "'");
  expectRefusal(envmap, {"maps.json: render.map_size 2048: envmap mode needs at least"}, {out});
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
  expectRefusal(r, {"PVRR_GPU_MEMORY_MB: expected a positive number of MiB, got \"lots\""}, {out});
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
  expectRefusal(
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
  expectRefusal(runPvrr("render '" + meniscus + "' --gl osmesa --out '" + out + "'"),
                {"meniscus.json: elements[0] (thin): the surfaces cross or touch inside the outline"}, {out});
  // Touching at the rim: 2 (R - sqrt(R^2 - r^2)) = 3.4260252 mm of sag at R 0.46787 m, r 40 mm leaves the
  // surfaces 4e-12 m apart across the rim (a contact, as far as any lens tolerance goes).
  expectRefusal(
      runPvrr("render models/reading-lens.json --gl osmesa --set elements[0].centre_thickness=0.0034260252 --out '" +
              out + "'"),
      {"reading-lens.json: elements[0] (reading-lens): the surfaces cross or touch inside the outline"}, {out});
}

}  // namespace
