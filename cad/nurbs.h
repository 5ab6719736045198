// Rational B-spline (NURBS) surfaces of any degree with non-uniform knots.
#pragma once
#include <vector>

#include "cad/surface.h"

namespace pvrr::cad {

struct NurbsDefinition {
  int degree_u = 3, degree_v = 3;
  int count_u = 0, count_v = 0;        // number of control points in u and v
  std::vector<double> knots_u;         // full knot vector: count_u + degree_u + 1 values, non-decreasing
  std::vector<double> knots_v;
  std::vector<Vec3> points;            // count_u * count_v, index [i * count_v + j] (i along u, j along v)
  std::vector<double> weights;         // same layout; empty means all 1 (non-rational)
};

class NurbsSurface : public Surface {
 public:
  // Validates and throws pvrr::Error naming what is wrong (decreasing knots, wrong counts, weights <= 0,
  // NaN or Inf, degree < 1, ...). `what` prefixes the message (e.g. the file name).
  explicit NurbsSurface(NurbsDefinition def, const std::string& what = "NURBS surface");

  const NurbsDefinition& definition() const { return def_; }
  ParamDomain domain() const override;
  SurfaceDerivs evaluate(double u, double v) const override;  // (u, v) outside domain() is clamped to it
  std::string describe() const override;
  // One evaluation for position, normal and curvature (the defaults of Surface, bit-identical).
  SurfacePoint sample(double u, double v, bool with_curvature) const override;

 private:
  NurbsDefinition def_;
};

// Exact rational patches, used by tests and by scenes that ask for a NURBS form of an analytic surface.
// A sphere patch of radius r about `centre` spanning polar angles [0, theta_max] (a cap about +z, with a
// pole at u = 0; outward normal), built from rational quadratic arcs.
NurbsSurface makeSphereCap(Vec3 centre, double radius, double theta_max);
// Part of a cylinder of radius r about the z axis: angle [0, angle] (<= pi/2), height [0, h]; outward normal.
NurbsSurface makeCylinderPatch(double radius, double angle, double height);
// Part of a torus about the z axis (major radius R, minor r): both angles in [0, pi/2]; outward normal.
NurbsSurface makeTorusPatch(double major_radius, double minor_radius);

}  // namespace pvrr::cad
