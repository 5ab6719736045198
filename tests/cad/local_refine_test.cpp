// Local refinement of a grid (cad/local_refine.h): conformity (no T-junctions, no cracks), vertices exactly on
// the surface, winding, the grid's identity where nothing is refined, the 2:1 balance, the vertex count, and
// grid patches over the appended vertices.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "pvrr/base/error.h"
#include "cad/local_refine.h"
#include "cad/sag.h"
#include "cad/tessellate.h"
#include "support/surfaces.h"

namespace pvrr::cad {
namespace {

using test::FlippedPlane;

// Boundary vertices lie on the outline's circle: fromSquare maps the square's edge onto it within round-off.
constexpr double kOnOutline_m = 1e-12;

struct Case {
  Outline disc = Outline::circle(0.08);
  SagSurfacePtr s = makeToric(0.05, -50, 0.3, disc);
  Tessellation grid = tessellateGrid(*s, 9, 11, &disc, {true});
};

// Quad (i, j) of a 9 x 11 grid.
size_t q(int i, int j) { return size_t(i) * 10 + size_t(j); }

std::vector<uint8_t> someLevels() {
  std::vector<uint8_t> l(8 * 10, 0);
  l[q(3, 4)] = 3;  // an interior hot spot
  l[q(0, 0)] = 2;  // a corner of the outline
  l[q(7, 9)] = 1;
  l[q(5, 0)] = 2;  // on the boundary
  return l;
}

// Each edge used by two triangles, or by one with both ends on the outline: a hanging vertex (T-junction) or
// a crack would leave an interior edge used once.
void expectConforming(const Tessellation& t) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (const Triangle& tri : t.triangles) {
    const uint32_t v[3] = {tri.x, tri.y, tri.z};
    for (int e = 0; e < 3; ++e) ++uses[{std::min(v[e], v[(e + 1) % 3]), std::max(v[e], v[(e + 1) % 3])}];
  }
  for (const auto& [edge, n] : uses) {
    EXPECT_LE(n, 2);
    if (n == 1) {
      EXPECT_NEAR(glm::length(t.params[edge.first]), 0.04, kOnOutline_m) << edge.first;
      EXPECT_NEAR(glm::length(t.params[edge.second]), 0.04, kOnOutline_m) << edge.second;
    }
  }
  // Every vertex is used (none dangling inside another triangle's edge unseen).
  std::set<uint32_t> used;
  for (const Triangle& tri : t.triangles) used.insert({tri.x, tri.y, tri.z});
  EXPECT_EQ(used.size(), t.vertexCount());
}

void expectCounterClockwise(const Tessellation& t) {
  for (const Triangle& tri : t.triangles) {
    const Vec3 g = glm::cross(t.positions[tri.y] - t.positions[tri.x], t.positions[tri.z] - t.positions[tri.x]);
    ASSERT_GT(glm::length(g), 0.0);
    for (uint32_t k : {tri.x, tri.y, tri.z}) EXPECT_GT(glm::dot(g, t.normals[k]), 0.0);
  }
}

TEST(LocalRefine, ZeroLevelsGiveTheGridItself) {
  const Case c;
  const Tessellation t = refineGridLocally(*c.s, c.grid, std::vector<uint8_t>(80, 0), &c.disc);
  EXPECT_EQ(t.positions, c.grid.positions);
  EXPECT_EQ(t.triangles, c.grid.triangles);
  EXPECT_EQ(t.grid_u, 9);
  EXPECT_EQ(t.grid_v, 11);
}

TEST(LocalRefine, ConformingOnTheSurfaceAndCounterClockwise) {
  const Case c;
  const Tessellation t = refineGridLocally(*c.s, c.grid, someLevels(), &c.disc);
  ASSERT_GT(t.vertexCount(), c.grid.vertexCount());
  ASSERT_EQ(t.curvatures.size(), t.vertexCount());
  ASSERT_EQ(t.triangle_quads.size(), t.triangles.size());
  // The grid's vertices first and unchanged.
  for (size_t k = 0; k < c.grid.vertexCount(); ++k) {
    EXPECT_EQ(t.positions[k], c.grid.positions[k]);
    EXPECT_EQ(t.normals[k], c.grid.normals[k]);
  }
  // New vertices: bit-identical to the surface's own evaluation at their parameters, inside the outline.
  for (size_t k = c.grid.vertexCount(); k < t.vertexCount(); ++k) {
    const Vec2 uv = t.params[k];
    EXPECT_EQ(t.positions[k], c.s->evaluate(uv.x, uv.y).p);
    EXPECT_EQ(t.normals[k], c.s->normal(uv.x, uv.y));
    EXPECT_LE(glm::length(uv), 0.04 + kOnOutline_m);
  }
  expectConforming(t);
  expectCounterClockwise(t);
  // The unrefined quads far from the refined ones keep their two triangles, as in the grid.
  size_t plain = 0;
  for (size_t k = 0; k < t.triangles.size(); ++k)
    if (t.triangle_quads[k] == q(2, 8)) ++plain;
  EXPECT_EQ(plain, 2u);
  // A level-3 quad holds 2 x 8 x 8 triangles.
  size_t hot = 0;
  for (uint32_t tq : t.triangle_quads) hot += tq == q(3, 4);
  EXPECT_EQ(hot, 128u);
}

TEST(LocalRefine, LevelsAreBalancedTwoToOne) {
  const std::vector<uint8_t> b = balanceQuadLevels(9, 11, someLevels());
  EXPECT_EQ(b[q(3, 4)], 3);
  EXPECT_EQ(b[q(2, 4)], 2);
  EXPECT_EQ(b[q(1, 4)], 1);
  EXPECT_EQ(b[q(0, 4)], 0);
  EXPECT_EQ(b[q(3, 6)], 1);
  EXPECT_EQ(b[q(2, 5)], 1);  // a diagonal neighbour: through its edge neighbours at 2
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 10; ++j) {
      if (i + 1 < 8) {
        EXPECT_LE(std::abs(b[q(i, j)] - b[q(i + 1, j)]), 1);
      }
      if (j + 1 < 10) {
        EXPECT_LE(std::abs(b[q(i, j)] - b[q(i, j + 1)]), 1);
      }
    }
}

TEST(LocalRefine, VertexCountWithoutEvaluating) {
  const Case c;
  const Tessellation t = refineGridLocally(*c.s, c.grid, someLevels(), &c.disc);
  EXPECT_EQ(locallyRefinedVertexCount(9, 11, someLevels()), t.vertexCount());
  EXPECT_EQ(locallyRefinedVertexCount(9, 11, std::vector<uint8_t>(80, 0)), 99u);
  // Every quad at level 1: the 17 x 21 grid's vertices.
  EXPECT_EQ(locallyRefinedVertexCount(9, 11, std::vector<uint8_t>(80, 1)), 17u * 21u);
}

// The whole grid at one level is the finer grid itself (the same vertices, on the same square coordinates).
TEST(LocalRefine, UniformLevelIsTheFinerGrid) {
  const Case c;
  const Tessellation t = refineGridLocally(*c.s, c.grid, std::vector<uint8_t>(80, 2), &c.disc);
  const Tessellation fine = tessellateGrid(*c.s, 33, 41, &c.disc, {true});
  ASSERT_EQ(t.vertexCount(), fine.vertexCount());
  std::set<std::pair<double, double>> a, b;
  for (const Vec2& p : t.params) a.insert({p.x, p.y});
  for (const Vec2& p : fine.params) b.insert({p.x, p.y});
  EXPECT_EQ(a, b);
  EXPECT_EQ(t.triangles.size(), fine.triangles.size());
}

TEST(LocalRefine, PatchesShareTheirBoundaryVertices) {
  const Case c;
  const Tessellation t = refineGridLocally(*c.s, c.grid, someLevels(), &c.disc);
  const std::vector<GridPatch> patches = splitGrid(t, 2, 3);
  std::multiset<std::array<uint32_t, 3>> from_patches, all;
  std::map<uint32_t, int> patches_of;
  for (const GridPatch& p : patches) {
    std::set<uint32_t> mine(p.vertices.begin(), p.vertices.end());
    EXPECT_EQ(mine.size(), p.vertices.size());
    for (uint32_t v : mine) ++patches_of[v];
    for (const Triangle& tri : p.triangles) {
      ASSERT_LT(std::max({tri.x, tri.y, tri.z}), p.vertices.size());
      from_patches.insert({p.vertices[tri.x], p.vertices[tri.y], p.vertices[tri.z]});
    }
  }
  for (const Triangle& tri : t.triangles) all.insert({tri.x, tri.y, tri.z});
  EXPECT_EQ(from_patches, all);
  // Quad (3, 4)'s level-3 refinement lies on the cut between patch rows (quads 0-3 | 4-7) and columns
  // (0-2 | 3-5 | 6-9): it puts 7 vertices on the edge it shares with (4, 4), used by the triangles of both.
  int shared_appended = 0;
  for (const auto& [v, n] : patches_of)
    if (v >= c.grid.vertexCount() && n > 1) ++shared_appended;
  EXPECT_GE(shared_appended, 3);
  // A plain grid's patches are unchanged by the local path: zero levels give the same split.
  const Tessellation same = refineGridLocally(*c.s, c.grid, std::vector<uint8_t>(80, 0), &c.disc);
  const std::vector<GridPatch> a = splitGrid(c.grid, 2, 3), b = splitGrid(same, 2, 3);
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].vertices, b[k].vertices);
    EXPECT_EQ(a[k].triangles, b[k].triangles);
  }
}

TEST(LocalRefine, WindingFollowsTheGrid) {
  const FlippedPlane p;
  const Tessellation g = tessellateGrid(p, 4, 5);
  std::vector<uint8_t> l(12, 0);
  l[4] = 2;
  const Tessellation t = refineGridLocally(p, g, l);
  expectCounterClockwise(t);
  // The parameter square's area is covered exactly once: the triangles' areas sum to 1.
  double area = 0;
  for (const Triangle& tri : t.triangles)
    area += 0.5 * glm::length(glm::cross(t.positions[tri.y] - t.positions[tri.x], t.positions[tri.z] - t.positions[tri.x]));
  EXPECT_NEAR(area, 1.0, 1e-12);
}

TEST(LocalRefine, BadInputThrows) {
  const Case c;
  EXPECT_THROW(refineGridLocally(*c.s, c.grid, std::vector<uint8_t>(79, 0), &c.disc), Error);
  EXPECT_THROW(refineGridLocally(*c.s, c.grid, std::vector<uint8_t>(80, kMaxLocalLevel + 1), &c.disc), Error);
  const Tessellation t = refineGridLocally(*c.s, c.grid, someLevels(), &c.disc);
  EXPECT_THROW(refineGridLocally(*c.s, t, someLevels(), &c.disc), Error);  // refine the base grid, not this
}

}  // namespace
}  // namespace pvrr::cad
