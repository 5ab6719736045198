// Regulation zones as data (models/regulations/*.json, docs/fov.md): the fields of view a regulation demands of
// a mirror, each number with its source paragraph and whether it was confirmed in the primary text.
#pragma once
#include <string>
#include <vector>

#include "pvrr/analysis/fov.h"

namespace pvrr::app {

// One of the mirror's own requirements (e.g. the minimum mean radius of curvature), reported, not yet checked.
struct MirrorRequirement {
  std::string name, meaning, source, note;
  double value = 0;
  bool verified = false;
};

struct Regulation {
  std::string id, title, document, path;
  bool driver_side = true;
  std::vector<FovZone> zones;  // FovZone::verified: every value of the zone confirmed
  std::vector<MirrorRequirement> mirror;
  bool verified = false;  // every value in the file confirmed
};

// The regulation `id`: a path ending in .json, or the name of a file `id`.json in `folders` (searched in order).
// Errors: "pvrr fov: unknown regulation ..." listing the known ones, or "FILE: json.path: message".
Regulation loadRegulation(const std::string& id, const std::vector<std::string>& folders);

}  // namespace pvrr::app
