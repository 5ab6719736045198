// A mirror's field of view on the road (pvrr fov, issue 21): from each of the driver's ocular points, rays
// through a dense grid over the mirror surface, reflected exactly at the exact surface point (RayScene's exact
// element hit and normal, the reference tracer's reflection), continued to the road plane; the footprint per
// eye, and the share of each regulation zone it covers.
//
// CONVENTIONS (the only statement of them):
//  - Vehicle frame: origin on the road plane below the midpoint of the two ocular points, x forward
//    (vehicle.forward), y to the left, z up (vehicle.up). Metres.
//  - A ray's fate: Road (meets the road plane within horizon_m, measured horizontally from the mirror point),
//    Horizon (never meets the road, or beyond horizon_m), Obstructed (the sight line from the eye to the mirror
//    point, or the reflected ray before the road, is stopped first by one of vehicle.obstructions or by
//    another element), Back (the eye sees the mirror's back there: no reflection). A Road or Horizon ray's
//    road point is where it meets the road, or, beyond horizon_m, the point horizon_m from the mirror point
//    along the ray's horizontal direction: a map continuous over the mirror, whose boundary is the footprint.
//    Obstructed samples keep the road point the unobstructed ray would have.
//  - Zone coordinates (the regulation files, models/regulations/*.json): x metres forward of the ocular
//    points (behind < 0; -inf: the horizon), y metres outward from the outermost point of the vehicle on the
//    mirror's side (away from the vehicle > 0).
//  - Coverage: a zone point is seen by an eye when it lies in the image of a grid cell whose four corners are
//    Road or Horizon rays; obstructed when it lies only in images of cells with an obstructed corner. The zone
//    is sampled uniformly in lateral position and in the angle of depression from the ocular points' height
//    (so a share is a share of the zone as the driver sees it, not of its area), out to zone_horizon_m.
#pragma once
#include <string>
#include <vector>

#include "pvrr/base/math.h"
#include "pvrr/scene/scene_desc.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr {

class VehicleFrame {
 public:
  explicit VehicleFrame(const VehicleDesc& v);
  Vec3 toVehicle(const Vec3& world) const;
  Vec3 toVehicleDir(const Vec3& world) const;
  Vec3 toWorld(const Vec3& vehicle) const;
  const VehicleDesc& desc() const { return v_; }
  // The ocular points and the outermost points in the vehicle frame.
  Vec3 eye(bool left) const { return toVehicle(left ? v_.eye_left : v_.eye_right); }
  Vec3 outermost(bool left) const { return toVehicle(left ? v_.outermost_left : v_.outermost_right); }

 private:
  VehicleDesc v_;
  Vec3 origin_{0}, x_{0}, y_{0}, z_{0};
};

enum class RayFate { Road, Horizon, Obstructed, Back };

struct FovOptions {
  int samples = 121;            // grid samples along each side of the mirror's parameter square
  double horizon_m = 1000;      // the road reach of the map (see CONVENTIONS)
  double zone_horizon_m = 500;  // zones "to the horizon" are checked out to this far behind the ocular points
  int zone_samples_x = 80, zone_samples_y = 24;
};

// The surface parameters (u, v) of point s of the mirror's parameter square [-1, 1]^2: the outline's fromSquare, or
// the surface's domain mapped linearly where the element has no outline.
Vec2 mirrorParameters(const Element& el, Vec2 s);

// One eye's rays: samples x samples, row-major (v outer, u inner) over the mirror's parameter square
// [-1, 1]^2 (the outline's fromSquare, or the surface's domain without an outline).
struct EyeFootprint {
  std::string eye;  // "left" | "right"
  Vec3 eye_vehicle{0};
  int n = 0;
  std::vector<Vec2> road;  // vehicle-frame (x, y) of each sample (CONVENTIONS)
  std::vector<RayFate> fate;
  std::vector<Vec3> mirror_point;  // the exact surface point, world
  // The image of the mirror's boundary, counter-clockwise in (x, y): one point per boundary sample, and between two
  // whose road points lie more than 1 m and 5 % of their distance apart, points of the edge between them (halving
  // it, at most 10 times), so that the outline follows the edge out to the horizon instead of a chord across it.
  // The outline is then made simple (makeSimple): where the mirror's boundary runs above the horizon, its
  // clamped image (CONVENTIONS) runs along the horizon's arc and back again wherever the boundary's horizontal
  // direction turns back (near the corner where an edge meets the horizon, on the car mirror by about 2 m at
  // 1 km); such a fold is a sliver of zero area, 1 km away, whose sides (arcs about slightly different mirror
  // points) cross. outline_cut_area_m2 is the area of the loops cut off (0 when the traced outline was simple).
  std::vector<Vec2> outline;
  double outline_cut_area_m2 = 0;
  int count(RayFate f) const;
  // The farthest road reach behind the ocular points (m) of the Road rays, and whether any ray reaches the
  // horizon.
  double reach_m = 0;
  bool sees_horizon = false;
};

// Traces one eye's rays through mirror element `element` (world eye position `eye_world`).
EyeFootprint traceFootprint(const RayScene& rays, int element, const VehicleFrame& frame, const Vec3& eye_world,
                            const std::string& eye_name, const FovOptions& options = {});

struct FovZone {
  std::string regulation, name, source;
  bool verified = false;
  enum class Eyes { Either, Both, Left, Right } eyes = Eyes::Either;
  double allowed_obstructed_fraction = 0;
  bool driver_side = true;    // the zone lies on the driver's side (else the passenger's)
  std::vector<Vec2> polygon;  // zone coordinates (CONVENTIONS); x = -kInf: the horizon
};

struct ZoneResult {
  double covered_fraction = 0, obstructed_fraction = 0;
  bool pass = false;
  int samples = 0;
  std::vector<Vec2> polygon;  // the zone in the vehicle frame (zoneInVehicle)
  std::vector<Vec2> missed;   // vehicle-frame zone samples no eye of the zone's sees (for the plan view)
};

// The zone's polygon in the vehicle frame (the horizon at -zone_horizon_m).
std::vector<Vec2> zoneInVehicle(const FovZone& z, const VehicleFrame& frame, double zone_horizon_m);

// Coverage of one zone by the footprints of the eyes given (left and/or right; an eye the zone needs but not
// given counts as seeing nothing). Several footprints of one eye (an eye ellipse's samples, fov_eyes.h) act as
// one: a point is seen by that eye when any of them sees it.
ZoneResult evaluateZone(const FovZone& z, const VehicleFrame& frame, const std::vector<const EyeFootprint*>& eyes,
                        const FovOptions& options = {});

// The mirror surface's own figures over the same grid (FovOptions::samples) of its parameter square.
//  - Principal radii 1/k1, 1/k2 (cad/surface.h's sign: > 0 convex as seen from the front; +inf where flat).
//    mean_radius_m: the average over the samples of (r1 + r2) / 2, each sample's mean of its two principal
//    radii (after R46 Annex 7's r = (r_i + r'_i) / 2 at measuring points; here over every sample, not three
//    points: an engineering figure, not the type-approval measurement).
//  - Magnification of distant objects seen from `eye_world`, relative to a plane mirror at the same place: per
//    grid cell, M = D R^-1, with D the eye rays' and R the reflected rays' angular differences across the cell
//    (each in the plane perpendicular to the cell's mean ray). Its singular values are the principal
//    magnifications (1, 1 for a plane mirror; for a sphere of radius R seen from distance d at incidence i,
//    1 / (1 + 2 d / (R cos i)) and 1 / (1 + 2 d cos i / R), Coddington's equations). `magnification` holds
//    their geometric mean per cell, (n - 1) x (n - 1) row-major; NaN where a corner faces the eye with its back.
struct SurfaceFigures {
  int n = 0;
  double mean_radius_m = kInf, principal_radius_min_m = kInf, principal_radius_max_m = kInf;
  double magnification_min = 0, magnification_max = 0;  // the smallest and largest principal magnification
  std::vector<double> magnification;
  std::vector<Vec2> principal_magnifications;  // per cell: (larger, smaller) singular value
};
SurfaceFigures surfaceFigures(const RayScene& rays, int element, const Vec3& eye_world, const FovOptions& options = {});

// The union of two simple polygons as closed loops (no repeated last point), each counter-clockwise for an
// outer boundary: the edges of each split where they cross the other's, those outside the other kept and
// chained. Overlapping collinear edges are not handled (two eyes' footprints never share an edge).
std::vector<std::vector<Vec2>> polygonUnion(const std::vector<Vec2>& a, const std::vector<Vec2>& b);

// Whether the closed polygon p crosses itself: the first pair of non-adjacent edges (p[i], p[i + 1]) and
// (p[j], p[j + 1]), i < j, that meet (touching counts), and where; 0 when p is simple.
int firstSelfCrossing(const std::vector<Vec2>& p, size_t& i, size_t& j, Vec2& x);

// Makes a closed polygon simple: at each crossing (firstSelfCrossing) it splits into two loops and keeps the one of
// larger area, until none is left; counter-clockwise after. Returns the area cut off (the sum of the smaller
// loops' areas).
double makeSimple(std::vector<Vec2>& p);

// Inside test for a simple polygon (even-odd).
bool insidePolygon(const std::vector<Vec2>& poly, Vec2 p);

}  // namespace pvrr
