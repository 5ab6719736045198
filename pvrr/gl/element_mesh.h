// Element meshes as the element programs read them (shaders/element.vert), the pool of their buffers that a
// frame fills, and the material uniforms every element draw sets.
#pragma once
#include <vector>

#include "pvrr/gl/gl_objects.h"
#include "pvrr/gl/program.h"
#include "pvrr/scene/scene.h"
#include "pvrr/method/vertex_stage.h"

namespace pvrr::gl {

// Element vertices (shaders/element.vert): position, normal, three texture-coordinate sets, three weights,
// the seen point's coordinates, the traced colour of totally reflected vertices (rgb, and 1 where the seen
// channel's is) and their traced seen point.
inline const std::vector<int> kElementLayout = {3, 3, 3, 3, 3, 3, 3, 3, 3, 4, 3};
constexpr size_t kElementFloats = 34;

// The element meshes of a frame: per (element, patch) in pvrr mode, per element otherwise, and the elements
// drawn into other elements' cubes. The buffers are kept from frame to frame and refilled.
class MeshPool {
 public:
  MeshPool() = default;
  ~MeshPool();
  MeshPool(const MeshPool&) = delete;
  MeshPool& operator=(const MeshPool&) = delete;
  void rewind() { next_ = 0; }  // a new frame
  size_t next() const { return next_; }  // the index the next slot() returns
  MeshBuffers& slot();
  MeshBuffers& at(size_t i) { return meshes_[i]; }

 private:
  std::vector<MeshBuffers> meshes_;
  size_t next_ = 0;
};

// Whole-element mesh (plain, envmap and impostor modes, and elements drawn dark at the depth limit):
// position relative to the element's origin, normal; for an envmap lens the exact exit direction of each
// vertex's ray in a_st0 and its Fresnel transmittance in a_w0 (the "refraction vectors" baseline); the
// vertex's surface parameters (u, v), normalised to the surface's domain, in a_st1 (the impostor mirror's
// start on its surface maps).
void uploadElementGrid(MeshBuffers& mb, const Scene& scene, const ElementFrame& f, const Vec3& anchor);

void setElementMaterial(const Program& p, const Element& el, int index);

}  // namespace pvrr::gl
