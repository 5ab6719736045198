// The shipped scenes (models/*.json), loaded for tests. Header-only.
#pragma once

#include <string>
#include <vector>

#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr::test {

// models/NAME.json with the given --set overrides.
inline Scene shippedScene(const std::string& name, const std::vector<std::string>& sets = {}) {
  return buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/" + name + ".json", sets));
}

}  // namespace pvrr::test
