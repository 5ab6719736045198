// The maps of pvrr lensmap, each as PNG and SVG: a colour map over the gaze field (as the wearer sees it:
// right is the wearer's right, up is up), iso-lines with labels, a colour bar with units, grey cells where no
// ray passes. The PNG is rasterised here (text by VTK's FreeType renderer, no GL); the SVG is written directly.
#pragma once
#include <string>
#include <vector>

#include "pvrr/analysis/lensmap.h"

namespace pvrr::app {

// Straight object lines as the eye sees them through the lens: polylines of gaze tangents (tan gx,
// tan gy / cos gx), each broken where no ray passes (an empty polyline between pieces is not needed: each
// piece is its own entry). `reference` holds the same lines without distortion (the paraxial mapping).
struct DistortionGrid {
  std::vector<std::vector<Vec2>> seen, reference;
};

// The iso-levels every `step` that fall strictly inside (lo, hi), at most `max_levels` (then every k-th).
std::vector<double> isoLevels(double lo, double hi, double step, size_t max_levels = 60);

// Marching squares on an n x n grid of values (NaN: no value; cells touching one are skipped): the segments
// of the iso-line at `level`, in grid coordinates (x = column, y = row).
std::vector<std::pair<Vec2, Vec2>> isoSegments(const std::vector<double>& values, int n, double level);

// Writes DIR/{power_error,cylinder,prism,lateral_colour,distortion}.{png,svg}; returns their paths.
std::vector<std::string> writeLensmapPlots(const std::string& dir, const LensmapResult& r,
                                           const DistortionGrid& distortion);

}  // namespace pvrr::app
