// pvrr compare for light (issue 23 item 4): where a scene has caustics on (a light's "caustics"), the raster
// caustic maps (pvrr/gl/caustic_pass.h; the same in every raster mode) against the reference's light tracer
// (pvrr/trace/light_tracer.h) on the same receiver cells: the focus position, the peak and the relative L1
// error inside the reference's spot (pvrr/analysis/caustic_metrics.h), and a heat map per receiver.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "app/report.h"

namespace pvrr::app {

// Null when no light has caustics on. Otherwise per receiver the comparison (JSON) and the heat map
// OUT_DIR/caustic-RECEIVER.png (reference | raster | |raster - reference| x 10, on the reference's peak scale).
nlohmann::json compareCaustics(LoadedScene& ls, const std::string& gl_name, const std::string& out_dir);

}  // namespace pvrr::app
