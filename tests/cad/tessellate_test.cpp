// Grid and adaptive tessellations: vertices on the exact surface, normals from the surface, winding,
// chordal tolerance checked against the exact surface, conformity, and grid patches.
#include <gtest/gtest.h>

#include <array>
#include <functional>
#include <map>
#include <set>

#include "pvrr/base/error.h"
#include "cad/nurbs.h"
#include "cad/sag.h"
#include "cad/tessellate.h"
#include "support/surfaces.h"

namespace pvrr::cad {
namespace {

using test::FlippedPlane;

// Distances of vertices from an analytic sphere: a few ulps of the radius.
constexpr double kOnSurfaceRel = 1e-14;
// Boundary vertices on the outline (the target).
constexpr double kOnOutline = 1e-12;

TEST(TessellateGrid, VerticesAndNormalsComeFromTheSurface) {
  const Outline disc = Outline::circle(0.08, Vec2(0.005, -0.002));
  const SagSurfacePtr s = makeSphere(-0.6, disc, 0.01);
  const Tessellation t = tessellateGrid(*s, 21, 17, &disc, {true});
  ASSERT_EQ(t.grid_u, 21);
  ASSERT_EQ(t.grid_v, 17);
  ASSERT_EQ(t.vertexCount(), 21u * 17u);
  ASSERT_EQ(t.curvatures.size(), t.vertexCount());
  const Vec3 centre(0, 0, 0.01 + 0.6);
  for (size_t k = 0; k < t.vertexCount(); ++k) {
    const Vec2 uv = t.params[k];
    // Bit-identical to the surface's own evaluation and normal (never averaged).
    EXPECT_EQ(t.positions[k], s->evaluate(uv.x, uv.y).p);
    EXPECT_EQ(t.normals[k], s->normal(uv.x, uv.y));
    EXPECT_NEAR(glm::length(t.positions[k] - centre), 0.6, kOnSurfaceRel * 0.6);
    EXPECT_NEAR(t.curvatures[k].k1 * -0.6, 1.0, 1e-12);
    EXPECT_TRUE(disc.contains(uv, kOnOutline));
  }
  // Vertex (i, j) at index i * grid_v + j; the grid's outer ring lies on the outline.
  for (int i = 0; i < 21; ++i)
    for (int j = 0; j < 17; ++j) {
      const bool ring = i == 0 || i == 20 || j == 0 || j == 16;
      const double r = glm::length(t.params[size_t(i * 17 + j)] - disc.centre());
      if (ring) {
        EXPECT_NEAR(r, 0.04, kOnOutline);
      } else {
        EXPECT_LT(r, 0.04 - 1e-4);
      }
    }
  EXPECT_EQ(t.triangles.size(), 2u * 20u * 16u);
  EXPECT_TRUE(tessellateGrid(*s, 3, 3, &disc).curvatures.empty());
}

// Every triangle counter-clockwise seen from the normal side: its geometric normal agrees with the surface
// normals at its vertices.
void expectCounterClockwise(const Tessellation& t) {
  for (const Triangle& tri : t.triangles) {
    const Vec3 g = glm::cross(t.positions[tri.y] - t.positions[tri.x], t.positions[tri.z] - t.positions[tri.x]);
    ASSERT_GT(glm::length(g), 0.0);
    for (uint32_t k : {tri.x, tri.y, tri.z}) EXPECT_GT(glm::dot(g, t.normals[k]), 0.0);
  }
}

TEST(TessellateGrid, NurbsCapWithPoleIsCounterClockwiseWithoutDegenerateTriangles) {
  const double R = 1.2;
  const NurbsSurface s = makeSphereCap(Vec3(0.1, 0.2, -0.3), R, radians(40));
  const Tessellation t = tessellateGrid(s, 12, 25);
  // The pole row (u = 0) collapses: one of the two triangles of each of its 24 quads is left out.
  EXPECT_EQ(t.triangles.size(), 2u * 11u * 24u - 24u);
  expectCounterClockwise(t);
  for (size_t k = 0; k < t.vertexCount(); ++k) {
    EXPECT_NEAR(glm::length(t.positions[k] - Vec3(0.1, 0.2, -0.3)), R, 1e-12 * R);
    EXPECT_EQ(t.positions[k], s.evaluate(t.params[k].x, t.params[k].y).p);
    EXPECT_EQ(t.normals[k], s.normal(t.params[k].x, t.params[k].y));
  }
  // The domain's corners are grid vertices exactly.
  EXPECT_EQ(t.params.front(), Vec2(0, 0));
  EXPECT_EQ(t.params.back(), Vec2(1, 1));
}

TEST(TessellateGrid, WindingFollowsTheNormals) {
  expectCounterClockwise(tessellateGrid(FlippedPlane(), 4, 5));
  const Outline disc = Outline::circle(0.05);
  expectCounterClockwise(tessellateGrid(*makeToric(0.3, -0.2, 0.4, disc), 9, 9, &disc));
}

TEST(TessellateGrid, InvalidSizesThrow) {
  const FlippedPlane p;
  EXPECT_THROW(tessellateGrid(p, 1, 5), Error);
  EXPECT_THROW(tessellateGrid(p, 5, 0), Error);
  const Outline disc = Outline::circle(0.05);
  // Sag undefined inside the outline: the error names the surface.
  try {
    tessellateGrid(*makeSphere(0.02, disc), 5, 5, &disc);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sphere R=0.02 m"), std::string::npos) << e.what();
  }
}

// Each edge used by two triangles, or by one on the boundary with both ends on the outline: no T-junctions
// (a hanging vertex would leave an interior edge used once).
void expectConforming(const Tessellation& t, const std::function<bool(Vec2)>& on_boundary) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (const Triangle& tri : t.triangles) {
    const uint32_t v[3] = {tri.x, tri.y, tri.z};
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = v[e], b = v[(e + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  for (const auto& [edge, n] : uses) {
    EXPECT_LE(n, 2);
    if (n == 1) {
      EXPECT_TRUE(on_boundary(t.params[edge.first])) << t.params[edge.first].x << " " << t.params[edge.first].y;
      EXPECT_TRUE(on_boundary(t.params[edge.second]));
    }
  }
}

TEST(TessellateAdaptive, AsphereMeetsChordalToleranceAtTriangleCentres) {
  const double tol = 2e-6, angle_tol = radians(3);
  const Outline rect = Outline::rectangle(0.09, 0.05, 0.01);
  const SagSurfacePtr s = makeAsphere(0.12, -0.8, {30.0}, rect, 0.002);
  const Tessellation t = tessellateAdaptive(*s, tol, angle_tol, &rect, {true});
  EXPECT_EQ(t.grid_u, 0);
  EXPECT_GT(t.triangles.size(), 500u);
  EXPECT_EQ(t.curvatures.size(), t.vertexCount());
  double worst = 0;
  for (const Triangle& tri : t.triangles) {
    const Vec3 a = t.positions[tri.x], b = t.positions[tri.y], c = t.positions[tri.z];
    // The triangle's z at its centroid's (x, y) against the exact surface there; likewise at edge midpoints.
    for (const Vec3& q : {(a + b + c) / 3.0, 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a)}) {
      const double z_surface = 0.002 - s->sag(q.x, q.y).z;
      worst = std::max(worst, std::abs(z_surface - q.z));
    }
    for (uint32_t i : {tri.x, tri.y, tri.z})
      for (uint32_t j : {tri.x, tri.y, tri.z}) EXPECT_LE(angleBetween(t.normals[i], t.normals[j]), angle_tol);
  }
  EXPECT_LE(worst, tol);
  // It is a real refinement: a coarser tolerance gives fewer triangles and a larger worst deviation.
  const Tessellation coarse = tessellateAdaptive(*s, 50 * tol, angle_tol, &rect);
  EXPECT_LT(coarse.triangles.size(), t.triangles.size());
  expectCounterClockwise(t);
  expectConforming(t, [&](Vec2 p) { return rect.contains(p, kOnOutline) && !rect.contains(p, -kOnOutline); });
}

TEST(TessellateAdaptive, ConformingAndBoundaryOnOutline) {
  const Outline disc = Outline::circle(0.06);
  const SagSurfacePtr s = makeToric(0.2, 0.08, 0.5, disc);
  const Tessellation t = tessellateAdaptive(*s, 1e-5, radians(5), &disc);
  expectCounterClockwise(t);
  expectConforming(t, [&](Vec2 p) { return std::abs(glm::length(p) - 0.03) <= kOnOutline; });
}

TEST(TessellateAdaptive, NurbsSphereCapWithinToleranceOfTheSphere) {
  const double R = 1.2, tol = 1e-4;
  const Vec3 centre(0.3, 0, 0);
  const NurbsSurface s = makeSphereCap(centre, R, radians(40));
  const Tessellation t = tessellateAdaptive(s, tol, radians(10));
  expectCounterClockwise(t);
  // The flat triangle lies inside the sphere; its distance to the sphere at the centroid is R - |c - centre|.
  for (const Triangle& tri : t.triangles) {
    const Vec3 c = (t.positions[tri.x] + t.positions[tri.y] + t.positions[tri.z]) / 3.0;
    EXPECT_LE(R - glm::length(c - centre), tol);
  }
  EXPECT_THROW(tessellateAdaptive(s, 0, 0.1), Error);
  EXPECT_THROW(tessellateAdaptive(s, 1e-3, -1), Error);
}

TEST(GridPatches, ShareBitIdenticalBoundaryVertices) {
  const Outline disc = Outline::circle(0.05);
  const SagSurfacePtr s = makeAsphere(0.3, -1, {5.0}, disc);
  const Tessellation g = tessellateGrid(*s, 23, 19, &disc);
  const std::vector<GridPatch> patches = splitGrid(g, 3, 4);
  ASSERT_EQ(patches.size(), 12u);
  size_t triangles = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 4; ++b) {
      const GridPatch& p = patches[size_t(a * 4 + b)];
      triangles += p.triangles.size();
      ASSERT_EQ(p.vertices.size(), size_t(p.i1 - p.i0 + 1) * size_t(p.j1 - p.j0 + 1));
      for (const Triangle& tri : p.triangles)
        for (uint32_t k : {tri.x, tri.y, tri.z}) ASSERT_LT(k, p.vertices.size());
      // Neighbour along u: its first row is this patch's last row, the same grid vertices.
      if (a + 1 < 3) {
        const GridPatch& q = patches[size_t((a + 1) * 4 + b)];
        ASSERT_EQ(q.i0, p.i1);
        ASSERT_EQ(q.j0, p.j0);
        const int w = p.j1 - p.j0 + 1;
        for (int j = 0; j < w; ++j) {
          const uint32_t vp = p.vertices[size_t((p.i1 - p.i0) * w + j)], vq = q.vertices[size_t(j)];
          EXPECT_EQ(vp, vq);
          EXPECT_EQ(g.positions[vp], g.positions[vq]);
          EXPECT_EQ(g.normals[vp], g.normals[vq]);
        }
      }
      if (b + 1 < 4) {
        const GridPatch& q = patches[size_t(a * 4 + b + 1)];
        ASSERT_EQ(q.j0, p.j1);
        const int wp = p.j1 - p.j0 + 1, wq = q.j1 - q.j0 + 1;
        for (int i = 0; i <= p.i1 - p.i0; ++i) EXPECT_EQ(p.vertices[size_t(i * wp + wp - 1)], q.vertices[size_t(i * wq)]);
      }
    }
  EXPECT_EQ(triangles, g.triangles.size());
  // The patches' triangles, mapped back to grid indices, are exactly the grid's.
  std::multiset<std::array<uint32_t, 3>> from_patches, from_grid;
  for (const GridPatch& p : patches)
    for (const Triangle& tri : p.triangles) from_patches.insert({p.vertices[tri.x], p.vertices[tri.y], p.vertices[tri.z]});
  for (const Triangle& tri : g.triangles) from_grid.insert({tri.x, tri.y, tri.z});
  EXPECT_EQ(from_patches, from_grid);

  const GridPatch whole = wholeGrid(g);
  EXPECT_EQ(whole.vertices.size(), g.vertexCount());
  EXPECT_EQ(whole.triangles.size(), g.triangles.size());
  EXPECT_EQ(whole.i1, 22);
  EXPECT_EQ(whole.j1, 18);
}

TEST(GridPatches, TooManyPatchesThrow) {
  const FlippedPlane p;
  const Tessellation g = tessellateGrid(p, 4, 6);
  EXPECT_NO_THROW(splitGrid(g, 3, 5));
  EXPECT_THROW(splitGrid(g, 4, 1), Error);
  EXPECT_THROW(splitGrid(g, 1, 6), Error);
  EXPECT_THROW(splitGrid(g, 0, 1), Error);
  Tessellation adaptive;
  EXPECT_THROW(wholeGrid(adaptive), Error);
  // A triangle that refers past the grid's vertices.
  Tessellation bad = g;
  bad.triangles.back().z = uint32_t(g.vertexCount());
  EXPECT_THROW(splitGrid(bad, 1, 1), Error);
}

}  // namespace
}  // namespace pvrr::cad
