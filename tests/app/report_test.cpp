// The sweep CSV, mesh files and sweep plots on constructed cases (the accuracy metric: tests/pvrr/analysis/accuracy_test.cpp).
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <filesystem>
#include <fstream>
#include <set>

#include "app/plot.h"
#include "app/report.h"
#include "pvrr/base/error.h"

namespace pvrr::app {
namespace {

TEST(SweepCsv, RoundTripsAndNamesBadLines) {
  SweepRow r;
  r.mode = "pvrr";
  r.tessellation = 15;
  r.map_size = 1024;
  r.vertices = 225;
  r.frame_ms = 12.5;
  r.median_arcmin = 0.7919;
  r.p95_arcmin = 16.5;
  r.max_arcmin = 8794;
  r.psnr_db = 28.79;
  r.reference_ms = 60;
  const auto dir = std::filesystem::temp_directory_path() / ("pvrr-sweep-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "sweep.csv").string();
  std::ofstream(path) << sweepCsv({r, r});
  const auto rows = readSweepCsv(path);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].mode, "pvrr");
  EXPECT_EQ(rows[0].vertices, 225);
  EXPECT_DOUBLE_EQ(rows[0].median_arcmin, 0.7919);
  std::ofstream(path, std::ios::app) << "pvrr,x,1,1,1,1,1,1,1,1,\n";
  try {
    readSweepCsv(path);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sweep.csv:4"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pvrr::app

namespace pvrr::app {
namespace {

// Environment meshes: OBJ and PLY through VTK, triangulated, with their positions intact.
TEST(MeshFiles, ObjAndPlyAreReadWithVtk) {
  const auto dir = std::filesystem::temp_directory_path() / ("pvrr-mesh-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string obj = (dir / "quad.obj").string(), ply = (dir / "tri.ply").string();
  std::ofstream(obj) << "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n";
  std::ofstream(ply) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 3 0\n3 0 1 2\n";
  const MeshData q = readMeshFile(obj);
  EXPECT_EQ(q.positions.size(), 4u);
  EXPECT_EQ(q.triangles.size(), 2u);  // the quad, triangulated
  EXPECT_EQ(q.positions[2], Vec3(2, 1, 0));
  const MeshData t = readMeshFile(ply);
  EXPECT_EQ(t.triangles.size(), 1u);
  EXPECT_EQ(t.positions[2], Vec3(0, 3, 0));
  EXPECT_THROW(readMeshFile((dir / "missing.obj").string()), Error);
  EXPECT_THROW(readMeshFile((dir / "quad.stl").string()), Error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pvrr::app

namespace pvrr::app {
namespace {

// The rows of `pvrr sweep --modes pvrr,envmap --tessellation 7,15 --map-size 256,1024` in sweep order, with
// the figures of the run where envmap at 1024 went missing from the PNG: the slowest and least accurate
// group, i.e. the top-right corner of the chart, where the legend used to sit and the axis ended.
std::vector<SweepRow> sweepRows() {
  std::vector<SweepRow> rows;
  for (int n : {7, 15})
    for (int map : {256, 1024})
      for (const char* mode : {"pvrr", "envmap"}) {
        SweepRow r;
        r.mode = mode;
        r.tessellation = n;
        r.map_size = map;
        r.vertices = n * n;
        const bool env = r.mode == "envmap";
        r.frame_ms = (env ? 57.0 : 20.0) * (map == 1024 ? (env ? 12.0 : 6.0) : 1.0) + n * 0.1;
        r.median_arcmin = env ? 11.0 + 0.01 * map / n : 0.8 * (15.0 / n) * (15.0 / n);
        r.p95_arcmin = 10 * r.median_arcmin;
        r.reference_ms = 10.3;
        rows.push_back(r);
      }
  return rows;
}

TEST(SweepPlot, EveryModeAndMapSizeGroupGetsOneSeries) {
  const std::vector<SweepRow> rows = sweepRows();
  const std::vector<PlotSeries> series = errorVsTimeSeries(rows);
  ASSERT_EQ(series.size(), 4u);
  std::set<std::pair<int, int>> styles;
  for (const char* mode : {"pvrr", "envmap"})
    for (int map : {256, 1024}) {
      const std::string name = std::string(mode) + " map " + std::to_string(map);
      const auto it = std::find_if(series.begin(), series.end(), [&](const PlotSeries& s) { return s.name == name; });
      ASSERT_NE(it, series.end()) << name;
      ASSERT_EQ(it->x.size(), 2u) << name;  // tessellations 7 and 15
      ASSERT_EQ(it->labels.size(), 2u) << name;
      EXPECT_EQ(it->labels[0], "7/" + std::to_string(map));
      EXPECT_EQ(it->labels[1], "15/" + std::to_string(map));
      EXPECT_FALSE(it->line);
      styles.insert({it->colour, it->marker});
    }
  EXPECT_EQ(styles.size(), 4u);  // no two series drawn alike

  // Every point lies strictly inside the axes, away from the borders (the envmap-1024 points were the
  // extremes of both axes).
  std::vector<double> xs = {rows.front().reference_ms}, ys;
  for (const PlotSeries& s : series) {
    xs.insert(xs.end(), s.x.begin(), s.x.end());
    ys.insert(ys.end(), s.y.begin(), s.y.end());
  }
  const auto xr = paddedRange(xs, false), yr = paddedRange(ys, true);
  for (double x : xs) {  // at least 1.5 % of the width (~11 px, more than a marker's radius) from either border
    EXPECT_GT(x - xr.first, 0.015 * (xr.second - xr.first)) << x;
    EXPECT_GT(xr.second - x, 0.015 * (xr.second - xr.first)) << x;
  }
  for (double y : ys) {
    EXPECT_GT(std::log(y / yr.first), 0.1 * std::log(yr.second / yr.first));
    EXPECT_GT(std::log(yr.second / y), 0.1 * std::log(yr.second / yr.first));
  }
}

TEST(SweepPlot, ManyGroupsKeepDistinctStylesAndVaryMakesItsOwnGroup) {
  std::vector<SweepRow> rows;
  for (int k = 0; k < 12; ++k) {
    SweepRow r;
    r.mode = k % 2 ? "pvrr" : "envmap";
    r.map_size = 64 << (k / 2);  // 6 map sizes x 2 modes
    r.tessellation = 5;
    r.frame_ms = 1 + k;
    r.median_arcmin = 0;  // a zero error still gets a point on the log axis
    rows.push_back(r);
  }
  SweepRow v = rows.front();
  v.vary = "render.max_depth=2";
  rows.push_back(v);
  const auto series = errorVsTimeSeries(rows);
  ASSERT_EQ(series.size(), 13u);
  std::set<std::pair<int, int>> styles;
  for (const auto& s : series) {
    styles.insert({s.colour, s.marker});
    for (double y : s.y) EXPECT_GT(y, 0);
  }
  EXPECT_EQ(styles.size(), 13u);
  EXPECT_EQ(series.back().name, "envmap map 64 render.max_depth=2");
}

TEST(SweepPlot, PaddedRangeIgnoresBadValuesAndRejectsNone) {
  const auto lin = paddedRange({5, 10, std::nan("")}, false);
  EXPECT_NEAR(lin.first, 5 - 0.4, 1e-12);
  EXPECT_NEAR(lin.second, 10 + 0.4, 1e-12);
  const auto from0 = paddedRange({2, 100}, false);
  EXPECT_EQ(from0.first, 0.0);  // the padding (7.84) would cross zero, and 2 stays more than 1.96 away from it
  const auto below0 = paddedRange({0.1, 100}, false);
  EXPECT_NEAR(below0.first, 0.1 - 0.08 * 99.9, 1e-12);  // 0.1 would sit on the border at 0
  const auto one = paddedRange({3, 3}, false);
  EXPECT_LT(one.first, 3);
  EXPECT_GT(one.second, 3);
  const auto lg = paddedRange({-1, 0, 0.5, 8}, true);  // non-positive values are ignored on a log axis
  EXPECT_NEAR(lg.first, 0.5 / 1.6, 1e-12);
  EXPECT_NEAR(lg.second, 8 * 1.6, 1e-12);
  EXPECT_THROW(paddedRange({0, -2}, true), Error);
  EXPECT_THROW(paddedRange({}, false), Error);
}

}  // namespace
}  // namespace pvrr::app
