// "Save view": the scene file as the viewer shows it, for `pvrr render` to reproduce.
#pragma once
#include <string>
#include <vector>

#include "pvrr/scene/scene.h"

namespace pvrr::app::view {

// Writes `out_path` (atomically): the scene file at `scene_path` with the --set overrides applied in order,
// the observer's eye, target, up and image size replaced by `ob`'s (in the file's units: `unit_m` metres per
// unit), and its relative file names ("file", "image") rewritten relative to the output's folder.
void saveView(const std::string& out_path, const std::string& scene_path, const std::vector<std::string>& overrides,
              const Observer& ob, double unit_m);

}  // namespace pvrr::app::view
