// A command writes all of its outputs or none (pvrr/base/atomic_file.h, OutputTransaction around every command):
// when a later output cannot be written, the earlier ones of the same command do not appear either, nor the
// folders made for them, and the files that were there before are unchanged.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/run_pvrr.h"

namespace {

namespace fs = std::filesystem;
using pvrr::test::CliResult;
using pvrr::test::expectOneLineError;
using pvrr::test::runPvrr;

class Outputs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = pvrr::test::freshTestDir(std::string("outputs-") +
                                    ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // A non-empty folder at `name`: no file can be renamed onto it.
  std::string occupy(const std::string& name) const {
    fs::create_directories(dir_ / name);
    std::ofstream(dir_ / name / "keep.txt") << "x";
    return path(name);
  }
  // Every entry below the test folder, as paths relative to it.
  std::vector<std::string> entries() const {
    std::vector<std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir_)) out.push_back(fs::relative(e.path(), dir_).string());
    std::sort(out.begin(), out.end());
    return out;
  }
  fs::path dir_;
};

TEST_F(Outputs, RenderWhoseStatsCannotBeWrittenLeavesNoPicture) {
  std::ofstream(path("old.png")) << "the file from before";
  const std::string stats = occupy("stats.json");
  const CliResult r = runPvrr("render models/plane-mirror.json --size 32x24 --gl osmesa --out '" + path("new/sub/a.png") +
                              "' --stats '" + stats + "'");
  expectOneLineError(r, stats);
  // Only what was there before: no picture, no temporary, no folder made for the picture.
  EXPECT_EQ(entries(), (std::vector<std::string>{"old.png", "stats.json", "stats.json/keep.txt"}));
  // The same command with a free stats path writes both.
  const CliResult ok = runPvrr("render models/plane-mirror.json --size 32x24 --gl osmesa --out '" + path("new/sub/a.png") +
                               "' --stats '" + path("s.json") + "'");
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_TRUE(fs::exists(path("new/sub/a.png")));
  EXPECT_TRUE(fs::exists(path("s.json")));
}

TEST_F(Outputs, CompareWhoseMetricsCannotBeWrittenLeavesNoImages) {
  const std::string metrics = occupy("cmp/metrics.json");
  const CliResult r = runPvrr("compare models/plane-mirror.json --modes raster --size 24x18 --gl osmesa --out '" +
                              path("cmp") + "'");
  expectOneLineError(r, metrics);
  EXPECT_EQ(entries(), (std::vector<std::string>{"cmp", "cmp/metrics.json", "cmp/metrics.json/keep.txt"}));
}

TEST_F(Outputs, VerticesWhoseCamerasCannotBeWrittenLeavesNoCsv) {
  const std::string cameras = occupy("v.json");
  const CliResult r = runPvrr("vertices models/plane-mirror.json --out '" + path("v.csv") + "'");
  expectOneLineError(r, cameras);
  EXPECT_EQ(entries(), (std::vector<std::string>{"v.json", "v.json/keep.txt"}));
}

}  // namespace
