// pvrr lensmap from the command line (issue 27): its files, the CSV's columns and empty cells, the JSON's
// counts and conventions, and one-line errors that leave no output.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "app/lensmap_plot.h"
#include "app/run_pvrr.h"
#include "pvrr/base/image.h"

namespace {

namespace fs = std::filesystem;
using pvrr::test::CliResult;
using pvrr::test::expectOneLineError;
using pvrr::test::runPvrr;
using pvrr::test::slurp;


std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == sep) {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

TEST(LensmapCli, WritesCsvJsonAndMaps) {
  const fs::path dir = pvrr::test::freshTestDir("lensmap-ok");
  const CliResult r = runPvrr("lensmap models/spectacle-lens.json --grid 9 --out '" + (dir / "out").string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f :
       {"lensmap.csv", "lensmap.json", "power_error.png", "power_error.svg", "cylinder.png", "cylinder.svg",
        "prism.png", "prism.svg", "lateral_colour.png", "lateral_colour.svg", "distortion.png", "distortion.svg"})
    EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
  const std::vector<std::string> lines = split(slurp(dir / "out" / "lensmap.csv"), '\n');
  ASSERT_GE(lines.size(), 82u);
  const std::vector<std::string> header = split(lines[0], ',');
  const std::vector<std::string> first14(header.begin(), header.begin() + 14);
  EXPECT_EQ(first14,
            (std::vector<std::string>{"gaze_x_deg", "gaze_y_deg", "lens_x_mm", "lens_y_mm", "sphere_d", "cylinder_d",
                                      "axis_deg", "mean_power_d", "power_error_d", "unwanted_cylinder_d", "prism_h",
                                      "prism_v", "distortion_pct", "lateral_colour_arcmin"}));
  int empty_rows = 0;
  for (size_t i = 1; i <= 81; ++i) {
    const std::vector<std::string> cells = split(lines[i], ',');
    ASSERT_EQ(cells.size(), header.size()) << lines[i];
    if (cells[4].empty()) ++empty_rows;
  }
  // Full precision: the centre row (gaze 0, 0) prints 17 significant digits.
  const std::vector<std::string> centre = split(lines[1 + 4 * 9 + 4], ',');
  EXPECT_EQ(centre[0], "0");
  EXPECT_GE(centre[4].size(), 17u) << centre[4];
  const nlohmann::json j = nlohmann::json::parse(slurp(dir / "out" / "lensmap.json"));
  EXPECT_EQ(j["empty"]["count"].get<int>(), empty_rows);
  EXPECT_GT(empty_rows, 0);  // the corners of +-40 deg lie beyond the 50 x 40 mm ellipse
  EXPECT_NEAR(j["prescription"]["sphere_d"].get<double>(), -3.0, 0.02);
  EXPECT_DOUBLE_EQ(j["rotation_centre_mm"].get<double>(), 25.5);
  EXPECT_TRUE(j["conventions"].contains("axis"));
  EXPECT_TRUE(j["focimeter"]["found"].get<bool>());
  EXPECT_TRUE(j["progressive"].is_null());
  const pvrr::ImageRGB8 png = pvrr::readPng((dir / "out" / "cylinder.png").string());
  EXPECT_GT(png.width, 400);
  // Not blank: coloured cells (neither grey, white nor black) fill part of the picture.
  size_t coloured = 0;
  for (int y = 0; y < png.height; ++y)
    for (int x = 0; x < png.width; ++x) {
      const uint8_t* p = png.at(x, y);
      coloured += (std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]}) > 30) ? 1 : 0;
    }
  EXPECT_GT(coloured, size_t(png.width * png.height / 10));
  const std::string svg = slurp(dir / "out" / "power_error.svg");
  EXPECT_NE(svg.find("iso-lines every 0.25 D"), std::string::npos);
  fs::remove_all(dir);
}

TEST(LensmapCli, ProgressiveLensReportsItsReferencePoints) {
  const fs::path dir = pvrr::test::freshTestDir("lensmap-pal");
  const CliResult r = runPvrr("lensmap models/progressive-lens.json --grid 5 --out '" + dir.string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(dir / "lensmap.json"));
  ASSERT_TRUE(j["progressive"].is_object());
  for (const char* k : {"add_d", "far_point", "near_point", "corridor_length_mm", "corridor_width_mm"})
    EXPECT_TRUE(j["progressive"].contains(k)) << k;
  fs::remove_all(dir);
}


TEST(LensmapCli, ErrorsAreOneLineAndLeaveNothing) {
  const fs::path dir = pvrr::test::freshTestDir("lensmap-err");
  const std::string out = (dir / "out").string();
  expectOneLineError(runPvrr("lensmap models/spectacle-lens.json --element lens --out '" + out + "'"),
                     "models/spectacle-lens.json: elements: no element named \"lens\"");
  expectOneLineError(runPvrr("lensmap models/car-mirror.json --out '" + out + "'"),
                     "models/car-mirror.json: elements: no lens to map");
  expectOneLineError(runPvrr("lensmap models/car-mirror.json --element door-mirror --out '" + out + "'"),
                     "models/car-mirror.json: elements[0] (door-mirror): pvrr lensmap maps a lens, not a mirror");
  expectOneLineError(
      runPvrr("lensmap models/spectacle-lens.json --set 'elements[0].eye={\"rotation_centre\": -1}' --out '" + out +
              "'"),
      "elements[0].eye.rotation_centre");
  expectOneLineError(runPvrr("lensmap models/spectacle-lens.json --object-distance 0.01 --out '" + out + "'"),
                     "--object-distance");
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

TEST(LensmapPlot, IsoSegmentsOfAPlaneAreStraight) {
  // v = x on a 5 x 5 grid: the level 1.5 is the vertical line x = 1.5, one segment per row of cells.
  std::vector<double> v(25);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) v[size_t(y * 5 + x)] = x;
  const auto segs = pvrr::app::isoSegments(v, 5, 1.5);
  ASSERT_EQ(segs.size(), 4u);
  for (const auto& s : segs) {
    EXPECT_DOUBLE_EQ(s.first.x, 1.5);
    EXPECT_DOUBLE_EQ(s.second.x, 1.5);
  }
  v[12] = std::nan("");  // cells touching a missing value are skipped
  EXPECT_LT(pvrr::app::isoSegments(v, 5, 1.5).size(), 4u);
  EXPECT_EQ(pvrr::app::isoLevels(-0.6, 0.6, 0.25), (std::vector<double>{-0.5, -0.25, 0, 0.25, 0.5}));
}

}  // namespace
