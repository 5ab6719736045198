// Ambient occlusion as vertex values (issue 24's cost; docs/performance.md "Ambient occlusion"): the faces of
// faceted environment meshes that are rectangles (grounds, pavements, walls, box faces) are drawn, where a field
// counts for them (AoFields::receiver), as graded grids whose vertices hold the occlusion for the face's two
// sides (pvrr/method/ao_receiver_grid.h), uploaded as one more vertex attribute (location 3, two floats) and
// interpolated for free (shaders/ambient_occlusion.glsl AO_VALUES: no texture read per fragment). A grid is
// made on first use and kept while its mesh and every occluder stay where they are; when one moves it is made
// and uploaded again (its CPU cost falls in that frame). What cannot be tessellated so (a mesh that is not
// faceted, a face that is not a rectangle) keeps the per-fragment paths (the pass's occlusion image for a static
// receiver, the fields for a moving one): the stage note says which, and why. A mesh whose every face with
// occlusion has a grid is drawn from one buffer (merged(): its grids and its other faces, holding zeros), its
// triangles without occlusion first, drawn with the program without ambient occlusion.
#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "pvrr/gl/gl_objects.h"
#include "pvrr/method/ao_receiver_grid.h"

namespace pvrr::gl {

// Occlusion below this at a triangle's three vertices (both sides) is left out of its fragments: the program
// without ambient occlusion draws the triangle (issue 24's cost: an interpolated value costs llvmpipe per
// fragment). kAoNegligible's bound (which already leaves whole meshes and faces out): it darkens a pixel by at
// most albedo * ambient * 2/255.
inline constexpr float kAoValueNegligible = float(kAoNegligible);

class AoVertexReceivers {
 public:
  AoVertexReceivers(const Scene& scene, const std::vector<AoField>& fields) : scene_(scene), fields_(fields) {}
  ~AoVertexReceivers();
  AoVertexReceivers(const AoVertexReceivers&) = delete;
  AoVertexReceivers& operator=(const AoVertexReceivers&) = delete;

  // The grid of face g of environment mesh m (its triangles `triangles`, its normal as uploaded), current for
  // where the mesh and the occluders are now, or null when the face cannot be tessellated.
  const MeshBuffers* grid(size_t m, size_t g, const std::vector<uint32_t>& triangles, const Vec3& normal);
  // A mesh's faces in one vertex buffer, so that the mesh is one draw (issue 24's cost, fourth round): face g's
  // grid where faces[g].grid, else its own triangles with occlusion 0 on both sides (a face no field counts
  // for), face after face in order, with the layout of grid()'s buffers (position, normal, texture coordinates,
  // the two occlusions: kAoStride floats a vertex). Made when first asked for with these faces and kept while
  // the mesh and every occluder stay where they are (as the grids, which it copies).
  static constexpr int kAoStride = 10;
  struct Face {
    const std::vector<uint32_t>* triangles = nullptr;  // the mesh's triangles of the face
    Vec3 normal{0};                                    // as uploaded
    bool grid = false;                                 // drawn as its grid (grid() must give one)
  };
  struct Merged {
    std::vector<Mat4> key;
    MeshBuffers buffers;
    std::vector<float> data;        // as uploaded: kAoStride floats a vertex
    std::vector<uint32_t> indices;  // as uploaded
    std::vector<int> face;          // per triangle: its face
    std::vector<int> source;        // per triangle: its index among its face's grid's (or the face's) triangles
    int grids = 0;                  // faces drawn as grids
    // The triangles whose three vertices hold less than kAoValueNegligible on both sides come first, indices
    // [0, plain): drawn with the program without ambient occlusion (no value interpolated per fragment), the
    // rest, [plain, size), with the vertex values.
    int plain = 0;
  };
  const Merged* merged(size_t m, const std::vector<Face>& faces);
  // The data grid() uploaded for face g of mesh m (kAoStride floats a vertex) and its indices; null if none.
  const std::vector<float>* gridData(size_t m, size_t g) const;
  const std::vector<uint32_t>* gridIndices(size_t m, size_t g) const;
  // Mesh m is drawn without grids: why (kept per mesh for the note).
  void fallback(size_t m, const std::string& why);
  // The grids made, their size and the time they took; the meshes and faces without, and why.
  std::string note() const;

 private:
  struct Entry {
    std::vector<Mat4> key;  // the mesh's motion and the occluders', when it was made
    MeshBuffers buffers;
    std::string why;        // not empty: no grid
    int vertices = 0, triangles = 0;
    std::vector<float> data;  // as uploaded, for the merged buffers
    std::vector<uint32_t> indices;
  };
  std::vector<Mat4> key(size_t m) const;

  const Scene& scene_;
  const std::vector<AoField>& fields_;
  std::map<std::pair<size_t, size_t>, Entry> entries_;
  std::map<std::pair<size_t, uint32_t>, Merged> merged_;  // per mesh and mask of the faces drawn as grids
  std::map<size_t, std::string> fallbacks_;
  int builds_ = 0;
  double build_ms_ = 0, last_build_ms_ = 0;
  int merges_ = 0;
};

}  // namespace pvrr::gl
