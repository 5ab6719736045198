// Ambient occlusion as vertex values (issue 24's cost, docs/performance.md "Ambient occlusion"): a flat
// rectangular receiver (a ground, a pavement, a box's face) re-tessellated as a graded grid that is fine only
// where the occluders' fields reach and their occlusion varies, each vertex holding the occlusion the fields'
// volumes cast there (pvrr/method/ao_field.h volumeOcclusion, in double) for the face's normal and for its
// opposite. A raster pass interpolates the value across the triangles instead of reading the fields or an
// occlusion image per fragment (shaders/ambient_occlusion.glsl AO_VALUES). No GL here.
//
// The grid: a rectangle of W x H split into root cells of at most kAoGridRootCell, refined as a quadtree whose
// cells stay about square (a level splits an axis only where the cell is not already much narrower along it,
// so that a 0.15 m kerb strip is split along its length alone), down to AoGridOptions::min_cell_m:
// - forced, where a field reaches (AoField::reach) and the cell is larger than kAoGridNear times its distance
//   from the field's centre (at least the field's radius): the occlusion varies on the scale of that distance;
// - where the occlusion at the cell's edge midpoints or centre differs from the two triangles' interpolation of
//   its corners by more than AoGridOptions::tolerance (either side).
// Neighbouring leaves differ by at most one level (balanced), and a leaf beside finer ones is triangulated as a
// fan from the midpoint of an edge it shares with them through the rest of its outline: no T-junction, so no crack.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pvrr/method/ao_field.h"
#include "pvrr/scene/scene.h"

namespace pvrr {

inline constexpr double kAoGridRootCell = 8.0;  // m: the largest cell, where no field reaches
inline constexpr double kAoGridNear = 2.0;      // forced cell size over distance from a field's centre

struct AoGridOptions {
  double tolerance = 0.04;  // occlusion: the interpolation's largest error where a cell is left unsplit
  double min_cell_m = 0.5;   // the smallest cell's larger side
  double near = kAoGridNear;  // forced cell size over distance from a field's centre
};

// A planar rectangle in the coordinates of its mesh (relative to the mesh's anchor): origin + s u + t v for s in
// [0, width], t in [0, height]; u, v unit, n = cross(u, v) the face's normal as uploaded or its opposite
// (normal_sign), the triangles' winding (ccw: counter-clockwise seen from n), and the texture coordinates,
// affine over it: uv0 + s uv_s + t uv_t.
struct AoRectangle {
  Vec3 origin{0}, u{1, 0, 0}, v{0, 1, 0}, normal{0, 0, 1};  // normal: the face's normal as uploaded
  double width = 0, height = 0;
  bool ccw = true;  // the triangles turn counter-clockwise about `normal`
  Vec2 uv0{0}, uv_s{0}, uv_t{0};
};

// The rectangle that triangles `triangles` of mesh `mesh` (all with the face normal `normal`) tile exactly, or
// nothing with `why` saying why not (not a rectangle; texture coordinates not affine over it).
std::optional<AoRectangle> aoRectangleOf(const EnvMesh& mesh, const std::vector<uint32_t>& triangles,
                                         const Vec3& normal, std::string& why);

struct AoReceiverGrid {
  std::vector<Vec3> positions;                  // relative to the mesh's anchor, as its vertices
  std::vector<Vec2> uvs;
  std::vector<std::array<float, 2>> occlusion;  // for the rectangle's normal, and for its opposite (0..1)
  std::vector<uint32_t> indices;                // triangles, wound as the rectangle's
  int leaves = 0;
  int evaluations = 0;  // points whose occlusion was evaluated (vertices and refinement samples)
};

// The occlusion (0..1, the fields' sum clamped) the volumes of every field but `receiver`'s own cast at world
// point x for normal n and -n, each field's object where it is now (occluderMotion).
std::array<double, 2> aoTwoSided(const std::vector<AoField>& fields, const Scene& scene, int receiver, const Vec3& x,
                                 const Vec3& n);

// The graded grid of rectangle r of mesh `mesh` (anchor: its world position) under `fields` (every one but the
// mesh's own occluder's), each field's object where it is now.
AoReceiverGrid buildAoReceiverGrid(const AoRectangle& r, const Vec3& anchor, int receiver,
                                   const std::vector<AoField>& fields, const Scene& scene,
                                   const AoGridOptions& options = {});

}  // namespace pvrr
