// Eye positions for pvrr fov (issue 21): the two ocular points, or samples of an eye ellipse (--eyes ellipse).
//
// EYE ELLIPSE (vehicle.eye_ellipse, after SAE J941's description): one ellipsoid per eye, centred on that eye's
// ocular point, with full axis lengths (a_x, a_y, a_z) along the vehicle's x (forward), y (left) and z (up), the x
// axis turned by tilt_deg about y (its forward end down for tilt > 0). Sampled, per eye, at 15 points: the centre,
// the 6 ends of the axes, and the 8 points (+-1, +-1, +-1) / sqrt(3) of the unit sphere mapped onto the surface.
// Samples closer than 1e-12 m to an earlier sample of the same eye are dropped (a zero-size ellipse is its centre:
// the ocular point).
#pragma once
#include <string>
#include <vector>

#include "pvrr/analysis/fov.h"

namespace pvrr {

struct EyeSample {
  std::string eye;  // "left" | "right"
  Vec3 world{0};    // the eye position
  Vec3 unit{0};     // the sample's position on the unit sphere (the centre: 0)
};

// The samples of both eyes' ellipsoids (EYE ELLIPSE), the left eye's first; `scale` multiplies the axes.
std::vector<EyeSample> eyeEllipseSamples(const VehicleFrame& frame, const VehicleDesc::EyeEllipse& e, double scale = 1);

// The union of simple counter-clockwise polygons, merged one at a time (polygonUnion); loops below 1e-5 of a step's
// largest are dropped (slivers where two footprints' horizon arcs nearly coincide, 1 km away); empty when a step
// still gives more than one loop (a hole, or disjoint parts), which this union does not represent.
std::vector<Vec2> unionOfPolygons(const std::vector<std::vector<Vec2>>& polys);

// The signed area of a polygon (> 0 counter-clockwise).
double signedArea(const std::vector<Vec2>& p);

}  // namespace pvrr
