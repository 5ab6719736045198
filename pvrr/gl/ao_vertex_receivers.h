// Ambient occlusion as vertex values (issue 24's cost; docs/performance.md "Ambient occlusion"): the faces of
// faceted environment meshes that are rectangles (grounds, pavements, walls, box faces) are drawn, where a field
// counts for them (AoFields::receiver), as graded grids whose vertices hold the occlusion for the face's two
// sides (pvrr/method/ao_receiver_grid.h), uploaded as one more vertex attribute (location 3, two floats) and
// interpolated for free (shaders/ambient_occlusion.glsl AO_VALUES: no texture read per fragment). A grid is
// made on first use and kept while its mesh and every occluder stay where they are; when one moves it is made
// and uploaded again (its CPU cost falls in that frame). What cannot be tessellated so (a mesh that is not
// faceted, a face that is not a rectangle) keeps the per-fragment paths (the pass's occlusion image for a static
// receiver, the fields for a moving one): the stage note says which, and why.
#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "pvrr/gl/gl_objects.h"
#include "pvrr/method/ao_receiver_grid.h"

namespace pvrr::gl {

class AoVertexReceivers {
 public:
  AoVertexReceivers(const Scene& scene, const std::vector<AoField>& fields) : scene_(scene), fields_(fields) {}
  ~AoVertexReceivers();
  AoVertexReceivers(const AoVertexReceivers&) = delete;
  AoVertexReceivers& operator=(const AoVertexReceivers&) = delete;

  // The grid of face g of environment mesh m (its triangles `triangles`, its normal as uploaded), current for
  // where the mesh and the occluders are now, or null when the face cannot be tessellated.
  const MeshBuffers* grid(size_t m, size_t g, const std::vector<uint32_t>& triangles, const Vec3& normal);
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
  };
  std::vector<Mat4> key(size_t m) const;

  const Scene& scene_;
  const std::vector<AoField>& fields_;
  std::map<std::pair<size_t, size_t>, Entry> entries_;
  std::map<size_t, std::string> fallbacks_;
  int builds_ = 0;
  double build_ms_ = 0, last_build_ms_ = 0;
};

}  // namespace pvrr::gl
