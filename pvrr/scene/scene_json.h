// Scene files (JSON, docs/scene-format.md): parse -> apply --set overrides -> validate -> SceneDesc.
// Building the runtime scene from the description happens elsewhere.
//
// Every input problem throws pvrr::Error with a complete message:
//   "<file>:LINE:COL: syntax error: ..."                                  (JSON syntax)
//   "<file>: <json.path>: expected <what>, got <value>"                  (wrong type or value)
//   "<file>: <json.path>: unknown key; did you mean \"normal\"?"         (typos)
// with " (from --set PATH=VALUE)" appended when an override put the offending value there.
#pragma once
#include <string>
#include <vector>

#include "pvrr/scene/scene_desc.h"

namespace pvrr {

// Reads, overrides and validates the scene file at `path`. Relative file names inside it are resolved
// against the scene file's folder. Overrides are "json.path=value" (e.g. "render.map_size=512",
// "elements[0].tessellation=9", "observer.eye=[0,1.2,0]"): the value is parsed as JSON when it parses, else
// taken as a string; overrides are applied in order to the document before validation, so they are
// validated exactly like the file (in the file's units).
SceneDesc loadScene(const std::string& path, const std::vector<std::string>& set_overrides = {});

// The same from text: `name_for_messages` prefixes every message, `base_dir` resolves relative file names
// (empty: the current directory).
SceneDesc parseScene(const std::string& json_text, const std::string& name_for_messages,
                     const std::string& base_dir, const std::vector<std::string>& set_overrides = {});

// Edit distance (optimal string alignment: insertions, deletions, substitutions, adjacent
// transpositions), used for "did you mean" suggestions.
int editDistance(const std::string& a, const std::string& b);

}  // namespace pvrr
