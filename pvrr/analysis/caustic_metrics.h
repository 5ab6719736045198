// Irradiance over a receiver (pvrr/trace/irradiance_grid.h) measured and compared: where a caustic's peak is,
// how much power it holds, and how far a test map (a raster caustic, a coarser estimate) is from a reference
// map (the reference's light tracer) inside the caustic's spot. Every figure uses the scalar irradiance (the mean
// of the three channels). docs/caustics.md states the definitions with the measured figures.
#pragma once
#include "pvrr/trace/irradiance_grid.h"

namespace pvrr {

// The default spot: the cells at or above this fraction of the peak irradiance.
constexpr double kSpotFraction = 0.5;

struct SpotMetrics {
  bool found = false;  // false when the map holds no positive irradiance
  int peak_i = -1, peak_j = -1;
  double peak_irradiance = 0;  // the brightest cell's scalar irradiance
  // The peak to sub-cell precision, receiver coordinates (m): per axis, the vertex of the parabola through the
  // logarithms of the peak cell and its two neighbours (exact for a Gaussian spot); the cell's centre on an
  // axis where a neighbour is empty or off the grid.
  Vec2 peak_uv_m{0};
  Vec3 peak_world{0};
  Vec2 centroid_uv_m{0};  // the power-weighted centroid of the spot's cells
  int spot_cells = 0;     // cells at or above spot_fraction of the peak
  double spot_area_m2 = 0;
  double spot_power = 0;   // power in the spot's cells (scalar irradiance x cell area)
  double total_power = 0;  // power on the whole grid
};

// Throws pvrr::Error when the map's size does not match its cells or spot_fraction is not in (0, 1].
SpotMetrics spotMetrics(const IrradianceGrid& map, double spot_fraction = kSpotFraction);

struct IrradianceComparison {
  SpotMetrics test, reference;
  double peak_distance_m = 0;      // |test.peak_uv_m - reference.peak_uv_m|
  double centroid_distance_m = 0;  // between the spots' centroids
  // Inside the reference's spot: sum |E_test - E_ref| / sum E_ref over its cells.
  double relative_l1_in_spot = 0;
  double power_ratio = 0;  // test.total_power / reference.total_power
};

// Compares two maps on the same receiver cells (ReceiverRect::sameCells; else pvrr::Error). Throws pvrr::Error
// when the reference holds no positive irradiance.
IrradianceComparison compareIrradiance(const IrradianceGrid& test, const IrradianceGrid& reference,
                                       double spot_fraction = kSpotFraction);

}  // namespace pvrr
