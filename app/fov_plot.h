// The plan view of pvrr fov (DIR/fov.png and .svg): the road behind the vehicle on the mirror's side, distance
// behind the ocular points compressed towards the horizon (d / (d + 20 m): 20 m at mid-width, the horizon at
// the right edge), lateral distance outward from the vehicle's outermost point linear; the zones filled green
// (pass) or red (fail), the footprint of each eye outlined, obstructed parts grey, the zone points no eye sees
// marked, and the verdict in the title.
#pragma once
#include <string>
#include <vector>

#include "pvrr/analysis/fov.h"

namespace pvrr::app {

struct FovPlotZone {
  const FovZone* zone;
  const ZoneResult* result;
};

std::vector<std::string> writeFovPlot(const std::string& dir, const std::string& title, const VehicleFrame& frame,
                                      bool driver_side, const std::vector<const EyeFootprint*>& eyes,
                                      const std::vector<FovPlotZone>& zones, const FovOptions& options);

// DIR/magnification.png and .svg: the magnification map (SurfaceFigures::magnification) over the mirror's
// parameter square (u to the right, v up), a colour bar with its range; grey where the eye sees the back.
std::vector<std::string> writeMagnificationPlot(const std::string& dir, const std::string& title,
                                                const SurfaceFigures& s);

// The plot's depth axis: metres behind the ocular points to [0, 1) (exposed for tests).
double fovDepthAxis(double behind_m);

}  // namespace pvrr::app
