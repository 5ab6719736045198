// What can move in a scene between two frames (issue 24): the elements' poses (Element::local_to_world: a
// spectacle lens with the head, an animated element) and the animated environment meshes' motions
// (Scene::mesh_motion). The passes that keep what they drew across frames (pvrr/gl/cube_pass.h,
// pvrr/gl/shadow_pass.h) record the poses they drew with and ask here, in one place, what has moved since.
#pragma once
#include <string>
#include <vector>

#include "pvrr/scene/scene.h"

namespace pvrr {

struct ScenePoses {
  std::vector<Mat4> elements;  // per element, local_to_world
  std::vector<Mat4> meshes;    // per environment mesh, Scene::meshMotion
  bool operator==(const ScenePoses& o) const { return elements == o.elements && meshes == o.meshes; }
};

ScenePoses posesOf(const Scene& scene);

// The first element whose pose differs between `then` and the scene now, as a reason ("element \"lens\" moved
// (attached to the observer)"), or "" when none did (or the element count changed: "the elements changed").
std::string elementMoved(const Scene& scene, const ScenePoses& then);

// The environment meshes whose motion differs between `then` and the scene now (every mesh when the mesh
// count changed).
std::vector<size_t> meshesMoved(const Scene& scene, const ScenePoses& then);

// "mesh \"overtaker-body\" moved" for one, "N environment meshes moved (\"a\", ...)" for several (at most
// three named).
std::string meshesMovedReason(const Scene& scene, const std::vector<size_t>& moved);

}  // namespace pvrr
