// The accuracy metric and the sweep CSV on constructed cases.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <filesystem>
#include <fstream>

#include "app/plot.h"
#include "app/report.h"
#include "cad/error.h"

namespace pvrr::app {
namespace {

// Seen points rotated about the surface point by a known angle give exactly that angle.
TEST(ErrorMetric, RotatedSeenPointsGiveTheRotationAngle) {
  RenderedFrame ref, mode;
  const int n = 101;
  ref.width = mode.width = n;
  ref.height = mode.height = 1;
  const Vec3 p(0.3, 1.2, -0.4);
  for (int i = 0; i < n; ++i) {
    const double angle_arcmin = 0.05 * i;  // 0 .. 5 arcmin
    const Vec3 axis = glm::normalize(Vec3(std::sin(i), std::cos(i), 0.3));
    const Vec3 to = glm::normalize(Vec3(1, 0.2 * i / n, -0.5)) * (2.0 + i);
    const Vec3 offset = Vec3(glm::rotate(Mat4(1.0), radians(angle_arcmin / 60.0), axis) * Vec4(to, 0));
    // Rotating about an axis not perpendicular to `to` turns it by less: compute the true angle independently.
    const double expected = arcminutes(std::acos(std::clamp(glm::dot(glm::normalize(to), glm::normalize(offset)), -1.0, 1.0)));
    ref.element.push_back(0);
    ref.element_point.push_back(p);
    ref.seen.push_back(p + to);
    ref.color.push_back(Vec3(0.5));
    mode.element.push_back(0);
    mode.element_point.push_back(p);
    mode.seen.push_back(p + offset);
    mode.color.push_back(Vec3(0.5));
    EXPECT_NEAR(arcminutes(seenAngle(p, p + to, p + offset)), expected, 1e-6);
  }
  std::vector<double> per_pixel;
  const ErrorStats s = compareToReference(ref, mode, &per_pixel);
  EXPECT_EQ(s.pixels, size_t(n));
  EXPECT_GT(s.max_arcmin, 0);
  EXPECT_LE(s.max_arcmin, 5.0 + 1e-9);
  EXPECT_LE(s.median_arcmin, s.p95_arcmin);
  EXPECT_GE(s.psnr_db, 98.0);  // identical colours
}

TEST(ErrorMetric, PureRotationAboutAPerpendicularAxisIsExact) {
  RenderedFrame ref, mode;
  ref.width = mode.width = 1;
  ref.height = mode.height = 1;
  const Vec3 p(1, 2, 3), to(0, 0, -5);
  const double a = radians(1.5 / 60.0);  // 1.5 arcmin about +x, perpendicular to `to`
  ref.element = mode.element = {0};
  ref.element_point = mode.element_point = {p};
  ref.seen = {p + to};
  mode.seen = {p + Vec3(glm::rotate(Mat4(1.0), a, Vec3(1, 0, 0)) * Vec4(to, 0))};
  ref.color = mode.color = {Vec3(0.2)};
  EXPECT_NEAR(compareToReference(ref, mode, nullptr).median_arcmin, 1.5, 1e-9);
}

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
