// Scenes built in code for the ambient-occlusion tests (fields, receiver grids): a box car on a ground quad.
// Header-only.
#pragma once
#include <vector>

#include "pvrr/scene/scene.h"

namespace pvrr::test {

// Appends `mesh` as part of environment object `object`, occluder `occluder` (-1: none), material 0, not moving.
inline void addAoObject(Scene& s, EnvMesh mesh, size_t object, int occluder) {
  mesh.occluder = occluder;
  mesh.material = 0;
  s.meshes.push_back(mesh);
  s.mesh_object.push_back(object);
  s.placed_meshes.push_back(EnvMesh{});
  s.mesh_motion.push_back(Mat4(1.0));
}

// One material, ambient occlusion on, nothing else.
inline Scene aoBaseScene() {
  Scene s;
  s.materials.push_back(DiffuseMaterial{});
  s.render.ambient_occlusion.on = true;
  return s;
}

// A box car (body, cabin, four wheels: one occluder of six boxes) on a 60 m ground quad, moved rigidly by `motion`.
inline Scene boxCarScene(const Mat4& motion) {
  Scene s = aoBaseScene();
  addAoObject(s, makeQuadMesh(Vec3(0), Vec3(0, 1, 0), Vec3(0, 0, -1), 60, 60), 0, -1);
  std::vector<EnvMesh> parts = {makeBoxMesh(Vec3(0, 0.75, 0), Vec3(4.4, 0.8, 1.8), Mat3(1.0)),
                                makeBoxMesh(Vec3(-0.3, 1.45, 0), Vec3(2.4, 0.6, 1.6), Mat3(1.0))};
  for (const double wx : {-1.4, 1.4})
    for (const double wz : {-0.8, 0.8})
      parts.push_back(makeBoxMesh(Vec3(wx, 0.32, wz), Vec3(0.64, 0.64, 0.22), Mat3(1.0)));
  const Mat3 r(motion);
  for (EnvMesh& m : parts) {
    const EnvMesh placed = m;
    m.anchor = Vec3(motion * Vec4(placed.anchor, 1.0));
    for (size_t i = 0; i < m.positions.size(); ++i) m.positions[i] = glm::vec3(r * Vec3(placed.positions[i]));
    for (size_t i = 0; i < m.normals.size(); ++i) m.normals[i] = glm::vec3(r * Vec3(placed.normals[i]));
    addAoObject(s, m, 1, 0);
    s.placed_meshes.back() = placed;
    s.mesh_motion.back() = motion;
  }
  s.updateBounds();
  return s;
}

}  // namespace pvrr::test
