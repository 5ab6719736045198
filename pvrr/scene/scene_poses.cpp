#include "pvrr/scene/scene_poses.h"

namespace pvrr {

ScenePoses posesOf(const Scene& scene) {
  ScenePoses p;
  for (const Element& el : scene.elements) p.elements.push_back(el.local_to_world);
  for (size_t m = 0; m < scene.meshes.size(); ++m) p.meshes.push_back(scene.meshMotion(m));
  return p;
}

std::string elementMoved(const Scene& scene, const ScenePoses& then) {
  if (then.elements.size() != scene.elements.size()) return "the elements changed";
  for (size_t e = 0; e < scene.elements.size(); ++e)
    if (then.elements[e] != scene.elements[e].local_to_world)
      return "element \"" + scene.elements[e].name + "\" moved" +
             (scene.elements[e].attached_to_observer ? " (attached to the observer)" : "");
  return "";
}

std::vector<size_t> meshesMoved(const Scene& scene, const ScenePoses& then) {
  std::vector<size_t> moved;
  const bool all = then.meshes.size() != scene.meshes.size();
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    if (all || then.meshes[m] != scene.meshMotion(m)) moved.push_back(m);
  return moved;
}

std::string meshesMovedReason(const Scene& scene, const std::vector<size_t>& moved) {
  if (moved.empty()) return "";
  if (moved.size() == 1) return "mesh \"" + scene.meshes[moved[0]].name + "\" moved";
  std::string names;
  for (size_t i = 0; i < moved.size() && i < 3; ++i) names += (i ? ", \"" : "\"") + scene.meshes[moved[i]].name + "\"";
  return std::to_string(moved.size()) + " environment meshes moved (" + names + (moved.size() > 3 ? ", ...)" : ")");
}

}  // namespace pvrr
