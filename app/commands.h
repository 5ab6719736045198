// The pvrr subcommands and what they share: loading and building a scene, writing outputs atomically,
// metrics against the reference.
#pragma once
#include <string>
#include <vector>

#include "pvrr/base/atomic_file.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_desc.h"
#include "pvrr/trace/tracer.h"

namespace pvrr::app {

class Args;

// The element a command works on: the one --element names (of any type: the caller checks it), else the scene's
// one element of `type`. Refuses an unknown name (naming the nearest), a scene without such an element (`none`,
// e.g. "no mirror") and several of them left to choose (`plural`, e.g. "mirrors"), each naming the scene file.
int chooseElement(const Scene& scene, const Args& a, const std::string& scene_path, ElementType type,
                  const std::string& none, const std::string& plural);

int cmdRender(const std::vector<std::string>& args);
int cmdGlInfo(const std::vector<std::string>& args);
int cmdTrace(const std::vector<std::string>& args);
int cmdVertices(const std::vector<std::string>& args);
int cmdCompare(const std::vector<std::string>& args);
int cmdMesh(const std::vector<std::string>& args);
int cmdSweep(const std::vector<std::string>& args);
int cmdPlot(const std::vector<std::string>& args);
int cmdLensmap(const std::vector<std::string>& args);
int cmdFov(const std::vector<std::string>& args);
int cmdCaustic(const std::vector<std::string>& args);

// The default scene of `pvrr render` with no scene argument.
constexpr const char* kDefaultScene = "models/car-mirror.json";

struct LoadedScene {
  SceneDesc desc;
  Scene scene;
};
// Loads, validates (with --set overrides) and builds. `size` overrides the observer's image size.
LoadedScene loadScene(const std::string& path, const std::vector<std::string>& overrides, int width = 0,
                      int height = 0);
// Reads OBJ and PLY meshes with VTK (the scene builder's mesh loader).
MeshData readMeshFile(const std::string& path);
// Linear RGB -> sRGB8 PNG, atomically. Non-finite values are written as black and counted (returned).
size_t writeLinearPng(const std::string& path, int width, int height, const std::vector<Vec3>& linear);

}  // namespace pvrr::app
