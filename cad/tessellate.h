// Tessellation with vertices on the exact surface and normals from the surface derivatives (never averaged
// from faces).
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "cad/outline.h"
#include "cad/surface.h"

namespace pvrr::cad {

using Triangle = glm::u32vec3;

struct Tessellation {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;        // unit, oriented as the surface normal
  std::vector<Vec2> params;         // (u, v) of each vertex
  std::vector<Curvature> curvatures;  // filled only when asked for
  std::vector<Triangle> triangles;  // counter-clockwise seen from the normal side
  // Grid tessellations: vertex (i, j), i along u (0..grid_u-1), j along v, is at index i * grid_v + j.
  int grid_u = 0, grid_v = 0;
  // A grid refined locally (cad/local_refine.h): the first grid_u * grid_v vertices are the grid's, the
  // others appended. quad_levels: each base quad's subdivision level ((grid_u - 1) x (grid_v - 1), quad
  // (i, j) at i * (grid_v - 1) + j); triangle_quads: the base quad of each triangle. Both empty for a plain
  // grid.
  std::vector<uint8_t> quad_levels;
  std::vector<uint32_t> triangle_quads;
  size_t vertexCount() const { return positions.size(); }
  bool locallyRefined() const { return !triangle_quads.empty(); }
  // The base quad of a triangle whose corners are all grid vertices (indices below grid_u * grid_v).
  size_t gridQuadOf(uint32_t a, uint32_t b, uint32_t c) const {
    const uint32_t gv = uint32_t(grid_v);
    return size_t(std::min({a / gv, b / gv, c / gv})) * size_t(grid_v - 1) + std::min({a % gv, b % gv, c % gv});
  }
};

struct TessellationOptions {
  bool curvatures = false;
};

// A grid of n_u x n_v vertices (n >= 2). Without an outline the grid spans the whole parameter domain;
// with one, the grid is the outline's fromSquare() image, so boundary vertices lie exactly on the outline.
// Each quad is split along its (i, j)-(i+1, j+1) diagonal; a triangle with two coincident vertices (at a
// pole or collapsed edge) is left out, so triangles.size() can be below 2 (n_u - 1)(n_v - 1).
Tessellation tessellateGrid(const Surface& s, int n_u, int n_v, const Outline* outline = nullptr,
                            TessellationOptions opt = {});

// Adaptive: refines until every triangle's chordal deviation (surface vs. the flat triangle, sampled at
// edge midpoints and centroid) is below chordal_tol and the normals of its vertices differ by less than
// angle_tol_rad. Crack-free. Not a grid (grid_u = grid_v = 0).
// The deviation at a point of the flat triangle is its distance to its projection onto the surface: along z
// for a SagSurface (so the z gap at that (x, y) is bounded), the closest point for other surfaces. Triangles
// with two coincident vertices (at a pole) are left out. A periodic seam (e.g. a full-turn NURBS) is two
// boundaries in (u, v), refined independently.
Tessellation tessellateAdaptive(const Surface& s, double chordal_tol, double angle_tol_rad,
                                const Outline* outline = nullptr, TessellationOptions opt = {});

// A block of a grid tessellation. Adjacent patches share their boundary vertices: the same indices into the
// grid, hence bit-identical positions and normals. A locally refined grid's block holds the triangles of its
// base quads and, after the block's grid vertices (in their order), the appended vertices they use (ascending);
// an appended vertex on a patch boundary belongs to both patches.
struct GridPatch {
  int i0 = 0, i1 = 0, j0 = 0, j1 = 0;  // inclusive vertex ranges in the grid
  std::vector<uint32_t> vertices;      // indices into the grid tessellation
  std::vector<Triangle> triangles;     // indices into `vertices`
};
std::vector<GridPatch> splitGrid(const Tessellation& grid, int patches_u, int patches_v);
// The whole grid as one patch.
GridPatch wholeGrid(const Tessellation& grid);

}  // namespace pvrr::cad
