// Moving scenes from the command line (issue 24): `pvrr render --time / --frames --fps` poses the animation at
// each frame's instant, and `pvrr compare --frames N --fps F` reports the error of every frame against the
// reference at that instant, and each mode's worst frame.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "run_pvrr.h"

namespace pvrr {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::runPvrr;

// The pvrr frames of the overtaking car at 96 x 72 against the reference at each instant: the static
// car-mirror scene measures a median of 0.785' at this size (pvrr compare, osmesa). The moving car is posed
// exactly for both, so no frame may be worse than this much over it (issue 24: accuracy does not drop for
// moving objects); the frames measured 0.785' to 0.795'.
constexpr double kStaticMedianArcmin = 0.785;
constexpr double kMovingOverStatic = 1.1;

TEST(MotionCli, RenderAtATimeIsTheFrameOfAClipAtThatTime) {
  const fs::path dir = test::freshTestDir("motion-render");
  const std::string common = " models/overtaking-car.json --size 96x72 --gl osmesa --mode impostor";
  const auto a = runPvrr("render" + common + " --time 0.8 --out '" + (dir / "at.png").string() + "'");
  ASSERT_EQ(a.code, 0) << a.err;
  const auto clip = runPvrr("render" + common + " --frames 3 --fps 2.5 --out '" + (dir / "clip.png").string() +
                            "' --stats '" + (dir / "clip.json").string() + "'");
  ASSERT_EQ(clip.code, 0) << clip.err;
  const auto start = runPvrr("render" + common + " --out '" + (dir / "start.png").string() + "'");
  ASSERT_EQ(start.code, 0) << start.err;
  // Frame 2 of the clip is at 0 + 2 / 2.5 = 0.8 s: the same picture, to the byte; t = 0 is another one.
  EXPECT_EQ(test::slurp(dir / "at.png"), test::slurp(dir / "clip.png"));
  EXPECT_NE(test::slurp(dir / "start.png"), test::slurp(dir / "clip.png")) << "the car did not move";
  const json stats = json::parse(test::slurp(dir / "clip.json"));
  EXPECT_TRUE(stats["animated"].get<bool>());
  EXPECT_EQ(stats["frames_moved"].get<int>(), 2);
  EXPECT_NE(clip.out.find("animation: t = 0 s to 0.8 s at 2.5 fps"), std::string::npos) << clip.out;
}

TEST(MotionCli, BadTimeArgumentsAreOneLineRefusals) {
  test::expectOneLineError(runPvrr("render models/overtaking-car.json --size 32x24 --fps 0 --out /tmp/x.png"), "--fps");
  test::expectOneLineError(runPvrr("render models/overtaking-car.json --size 32x24 --time abc --out /tmp/x.png"),
                           "--time");
  test::expectOneLineError(runPvrr("compare models/overtaking-car.json --size 32x24 --fps -1 --out /tmp/x"), "--fps");
}

TEST(MotionCli, CompareOverTimeReportsEveryFrameAndTheWorst) {
  const fs::path dir = test::freshTestDir("motion-compare");
  const auto r = runPvrr(
      "compare models/overtaking-car.json --modes pvrr,impostor --size 96x72 --frames 3 --fps 2 "
      "--gl osmesa --out '" +
      dir.string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const json m = json::parse(test::slurp(dir / "metrics.json"));
  const json& ot = m["over_time"];
  ASSERT_EQ(ot["frames"].size(), 3u);
  for (const std::string mode : {"pvrr", "impostor"}) {
    double worst_p95 = -1;
    int worst = -1;
    for (size_t i = 0; i < 3; ++i) {
      const json& f = ot["frames"][i];
      EXPECT_DOUBLE_EQ(f["time_s"].get<double>(), 0.5 * double(i));
      EXPECT_EQ(f["moved"].get<bool>(), i > 0);
      const json& e = f["modes"][mode];
      EXPECT_GT(e["pixels"].get<int>(), 100) << mode << " frame " << i;
      const double p95 = e["angular_error_arcmin"]["p95"].get<double>();
      if (p95 > worst_p95) worst_p95 = p95, worst = int(i);
      if (mode == "pvrr") {
        EXPECT_LT(e["angular_error_arcmin"]["median"].get<double>(), kMovingOverStatic * kStaticMedianArcmin)
            << "frame " << i;
      }
    }
    EXPECT_EQ(ot["worst_frame"][mode]["frame"].get<int>(), worst) << mode;
    EXPECT_DOUBLE_EQ(ot["worst_frame"][mode]["angular_error_arcmin"]["p95"].get<double>(), worst_p95) << mode;
  }
  // frames.csv: a header and one row per frame and mode.
  std::istringstream csv(test::slurp(dir / "frames.csv"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(csv, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 7u);
  EXPECT_EQ(lines[0], "frame,time_s,mode,pixels,median_arcmin,p95_arcmin,max_arcmin,psnr_db");
  EXPECT_EQ(lines[6].rfind("2,1,impostor,", 0), 0u) << lines[6];
  EXPECT_NE(r.out.find("worst frame"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace pvrr
