// Caustic receivers that are not one sheet over a plane (a box, a sphere, a cylinder over 180 deg, a closed
// solid) split into sheets (charts), each a receiver of its own (docs/caustics.md "Receivers in sheets"). GL-free.
//
// A caustic light map lies in a plane and holds one value per cell; the receiving surface must therefore be a
// height field over that plane (one surface point over each cell; pvrr/method/caustic_mesh.h). A mesh that is
// not is split: its triangles grouped by the nearest of the six axis directions (+-x, +-y, +-z, world frame) to
// their normals (as a cube map's faces), each group cut into connected pieces (triangles sharing a vertex
// position), and each piece kept when it is a height field over its own best-fit plane. A triangle belongs to
// exactly one sheet, so a photon deposits on the sheet its exact hit triangle belongs to (no light crosses a seam).
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "pvrr/base/math.h"
#include "pvrr/scene/scene.h"

namespace pvrr {

// A triangle faces a height field's plane when the cosine between their normals exceeds this.
inline constexpr double kMinHeightFieldCos = 1e-3;

// The plane a set of triangles is a height field over: the plane normal to the area-weighted mean of the
// triangles' unit normals (each oriented by its vertex normals), every triangle facing it (cos above
// kMinHeightFieldCos), and no triangle's centroid lying strictly over another triangle (one sheet). `centre`
// (world) lies in the middle of the triangles' bounding rectangle in the plane and of their heights over it;
// u x v = n. `planar`: every triangle's normal within 1e-9 (1 - cos) of the others' and the heights' spread
// within 1e-6 of the extent (float vertices: a few ulps).
struct HeightFieldPlane {
  Vec3 centre{0}, u{1, 0, 0}, v{0, 1, 0}, n{0, 0, 1};
  double width_m = 0, height_m = 0;
  bool planar = false;
};
// `triangles` null: the whole mesh (its bounds over all its vertices, the plane's u axis from its first
// triangle, as the whole-mesh receivers always had it); else the indices of a subset of mesh.triangles.
std::optional<HeightFieldPlane> heightFieldPlane(const EnvMesh& mesh, const std::vector<uint32_t>* triangles);

struct ReceiverSheets {
  std::vector<int> sheet_of_triangle;            // per mesh triangle: its sheet, or -1 (in no sheet)
  std::vector<std::vector<uint32_t>> triangles;  // per sheet: its triangles (indices into mesh.triangles)
  std::vector<HeightFieldPlane> planes;          // per sheet: the plane it is a height field over
  int unassigned = 0;                            // triangles in no sheet (degenerate, or a piece that folds)
};
// The mesh's sheets, ordered by their smallest triangle index. A mesh that is one sheet already gives one.
ReceiverSheets splitIntoSheets(const EnvMesh& mesh);

}  // namespace pvrr
