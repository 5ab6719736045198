// Receivers split into sheets (pvrr/method/receiver_sheets.h): a box into its six faces, a sphere and a cylinder
// over 180 deg into pieces that are each a height field over their own plane, every triangle in exactly one sheet;
// meshes that are one sheet stay one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <ctime>

#include "pvrr/method/caustic_mesh.h"
#include "pvrr/method/receiver_sheets.h"
#include "support/height_field.h"

namespace pvrr {
namespace {

// Every triangle in exactly one sheet, each sheet's triangles facing its plane.
void expectPartition(const EnvMesh& mesh, const ReceiverSheets& s) {
  ASSERT_EQ(s.sheet_of_triangle.size(), mesh.triangles.size());
  EXPECT_EQ(s.unassigned, 0);
  ASSERT_EQ(s.triangles.size(), s.planes.size());
  size_t total = 0;
  for (size_t k = 0; k < s.triangles.size(); ++k) {
    total += s.triangles[k].size();
    for (uint32_t t : s.triangles[k]) EXPECT_EQ(s.sheet_of_triangle[t], int(k));
    // Each sheet is a height field over its plane on its own.
    EXPECT_TRUE(heightFieldPlane(mesh, &s.triangles[k])) << k;
  }
  EXPECT_EQ(total, mesh.triangles.size());
}

// An open cylinder about +y through `centre`, radius r, from angle 0 to `span_rad`, normals outwards.
EnvMesh cylinderMesh(double r, double span_rad, int segments) {
  EnvMesh m;
  for (int i = 0; i <= segments; ++i) {
    const double a = span_rad * i / segments;
    const Vec3 n(std::cos(a), 0, std::sin(a));
    for (double y : {-0.05, 0.05}) {
      m.positions.push_back(glm::vec3(r * n + Vec3(0, y, 0)));
      m.normals.push_back(glm::vec3(n));
      m.uvs.push_back(glm::vec2(0));
    }
  }
  for (uint32_t i = 0; i < uint32_t(segments); ++i) {
    const uint32_t a = 2 * i, b = a + 1, c = a + 3, d = a + 2;
    m.triangles.push_back({a, b, c});
    m.triangles.push_back({a, c, d});
  }
  return m;
}

TEST(ReceiverSheets, ABoxSplitsIntoItsSixPlanarFaces) {
  const EnvMesh box = makeBoxMesh(Vec3(0.1, 0.2, 0.3), Vec3(0.02, 0.03, 0.04), Mat3(1.0));
  EXPECT_FALSE(heightFieldPlane(box, nullptr));  // not one sheet over a plane
  const ReceiverSheets s = splitIntoSheets(box);
  expectPartition(box, s);
  ASSERT_EQ(s.triangles.size(), 6u);
  for (size_t k = 0; k < 6; ++k) {
    EXPECT_EQ(s.triangles[k].size(), 2u);
    EXPECT_TRUE(s.planes[k].planar) << k;
    // The plane is the face's own: its normal along an axis, its centre on the face.
    const Vec3 n = s.planes[k].n;
    EXPECT_NEAR(std::max({std::abs(n.x), std::abs(n.y), std::abs(n.z)}), 1, 1e-12) << k;
  }
  // The first face (makeBoxMesh's first quad, -x): 0.03 (y) by 0.04 (z), centred at x = 0.09.
  EXPECT_NEAR(s.planes[0].centre.x, 0.09, 1e-7);
  EXPECT_NEAR(s.planes[0].width_m * s.planes[0].height_m, 0.03 * 0.04, 1e-9);
}

TEST(ReceiverSheets, ASphereSplitsIntoHeightFieldSheets) {
  const EnvMesh sphere = makeSphereMesh(Vec3(0), 0.05, 48, 24);
  EXPECT_FALSE(heightFieldPlane(sphere, nullptr));
  const ReceiverSheets s = splitIntoSheets(sphere);
  expectPartition(sphere, s);
  // One sheet per axis direction (the seam's duplicated vertices are welded: no extra pieces).
  EXPECT_EQ(s.triangles.size(), 6u);
  for (const HeightFieldPlane& p : s.planes) EXPECT_FALSE(p.planar);
}

// A fine sphere (65,024 triangles) splits the same way; its CPU time is printed for docs/performance.md
// "Caustics" (not asserted).
TEST(ReceiverSheets, AFineSphereSplitsIntoSixSheets) {
  const EnvMesh sphere = makeSphereMesh(Vec3(0.3, 0, 0), 0.05, 256, 128);
  const std::clock_t start = std::clock();
  const ReceiverSheets s = splitIntoSheets(sphere);
  const double ms = 1e3 * double(std::clock() - start) / CLOCKS_PER_SEC;
  expectPartition(sphere, s);
  EXPECT_EQ(s.triangles.size(), 6u);
  std::printf("[ sheets ] sphere of %zu triangles: %zu sheets in %.1f ms CPU\n", sphere.triangles.size(),
              s.triangles.size(), ms);
}

TEST(ReceiverSheets, ACylinderOver180DegreesSplits) {
  const EnvMesh c270 = cylinderMesh(0.05, 1.5 * kPi, 48);
  EXPECT_FALSE(heightFieldPlane(c270, nullptr));
  const ReceiverSheets s = splitIntoSheets(c270);
  expectPartition(c270, s);
  EXPECT_GE(s.triangles.size(), 3u);
  // Under 180 deg it is one sheet already.
  EXPECT_TRUE(heightFieldPlane(cylinderMesh(0.05, 0.9 * kPi, 48), nullptr));
}

TEST(ReceiverSheets, SheetReceiversOnlyForMeshesThatAreNotOneSheet) {
  Scene s;
  s.meshes.push_back(makeQuadMesh(Vec3(0), Vec3(0, 1, 0), Vec3(0, 0, 1), 1, 1));
  s.meshes.push_back(test::heightFieldMesh(test::sphericalBowl(Vec3(0), Vec3(0, 0, 1), Vec3(1, 0, 0), 0.1, 0.02),
                                           16, 16, "bowl"));
  s.meshes.push_back(makeBoxMesh(Vec3(0.5, 0, 0), Vec3(0.1, 0.1, 0.1), Mat3(1.0)));
  const std::vector<CausticReceiver> r = sheetReceivers(s);
  ASSERT_EQ(r.size(), 6u);
  for (size_t k = 0; k < r.size(); ++k) {
    EXPECT_EQ(r[k].mesh, 2);
    EXPECT_EQ(r[k].sheet.index, int(k));
    EXPECT_FALSE(r[k].curved);  // the faces are planar
    EXPECT_TRUE(r[k].sheet.holds(int(2 * k)) && r[k].sheet.holds(int(2 * k + 1)));
    EXPECT_FALSE(r[k].sheet.holds(int((2 * k + 2) % 12)));
  }
  // The whole-mesh receivers are what they were.
  EXPECT_EQ(planarReceivers(s).size(), 1u);
  EXPECT_EQ(heightFieldReceivers(s).size(), 1u);
}

}  // namespace
}  // namespace pvrr
