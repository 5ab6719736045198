// Local refinement of a grid tessellation (issue 26 item 2; the paper's future work "adaptive subdivision"):
// each base quad of the grid is subdivided 2^level x 2^level in the parameter square, with a conforming
// triangulation across level changes (a restricted quadtree: no T-junctions, no cracks).
#pragma once
#include <cstdint>
#include <vector>

#include "cad/tessellate.h"

namespace pvrr::cad {

// The finest level refineGridLocally accepts (64 x 64 sub-quads per base quad).
inline constexpr int kMaxLocalLevel = 6;

// The levels made 2:1 balanced: every quad's level raised to at least its edge neighbours' less one. Quad
// (i, j) of a grid_u x grid_v vertex grid is levels[i * (grid_v - 1) + j]. Throws pvrr::Error for a wrong
// size or a level above kMaxLocalLevel.
std::vector<uint8_t> balanceQuadLevels(int grid_u, int grid_v, std::vector<uint8_t> levels);

// The number of vertices refineGridLocally makes for these (balanced) levels, without evaluating the surface.
size_t locallyRefinedVertexCount(int grid_u, int grid_v, const std::vector<uint8_t>& levels);

// `grid` (tessellateGrid of s at grid.grid_u x grid.grid_v through `outline`) with each base quad subdivided
// to its level of balanceQuadLevels(levels). The result keeps grid_u, grid_v and the grid's vertices
// unchanged as its first grid_u * grid_v; the new ones are appended, evaluated exactly on the surface at
// their square coordinates through the outline's fromSquare() as tessellateGrid does (positions, normals,
// params, and curvatures when the grid has them). Triangles are rebuilt quad by quad in the grid's order and
// winding: a quad at level 0 whose neighbours are at level 0 keeps exactly its two triangles (the same
// diagonal), so all-zero levels give the grid's own triangles. Within a quad the sub-quads are split along
// the same diagonal; a sub-quad with one finer neighbour's vertex on its edges is a fan of three triangles
// from it, with more a fan from its centre. Degenerate triangles (coincident corners) are left out, as in the
// grid. Sets quad_levels and triangle_quads.
Tessellation refineGridLocally(const Surface& s, const Tessellation& grid, const std::vector<uint8_t>& levels,
                               const Outline* outline = nullptr);

}  // namespace pvrr::cad
