// Analytic optical surfaces given by their sag, in the element's local frame.
//
// Local frame: the surface vertex is at (0, 0, z_vertex); the optical axis is z; the normal at the vertex is
// +z (towards the observer for a mirror, towards the eye for a lens). A point of the surface is
//   (x, y, z_vertex - Z(x, y)),
// with the sag Z measured from the vertex *away* from the +z side.
// Radius sign: R > 0 puts the centre of curvature behind the surface (at z_vertex - R): convex as seen from
// +z (a convex rear-view mirror, a lens surface bulging towards the eye). R < 0 is concave. 0 or infinity is
// a plane. Curvature (cad/surface.h) of a sphere of radius R is +1/R at every point.
// The parameters are (u, v) = (x, y) in metres; the domain is the outline's bounding box.
#pragma once
#include <vector>

#include "cad/outline.h"
#include "cad/surface.h"

namespace pvrr::cad {

struct SagDerivs {
  double z = 0, zx = 0, zy = 0, zxx = 0, zxy = 0, zyy = 0;
};

class SagSurface : public Surface {
 public:
  SagSurface(Outline outline, double z_vertex) : outline_(outline), z_vertex_(z_vertex) {}
  // Sag Z and its derivatives at local (x, y). Throws pvrr::Error where the sag is undefined (outside a
  // sphere's radius), naming the surface.
  virtual SagDerivs sag(double x, double y) const = 0;
  // True where the sag is defined (e.g. r < |R| for a sphere).
  virtual bool defined(double x, double y) const { return true; }

  // The same shape with its vertex moved to z_vertex (lens back surfaces are built this way).
  virtual std::shared_ptr<const SagSurface> withVertex(double z_vertex) const = 0;
  // A sphere's (or a plane's) curvature c = 1/R (0: a plane), for ray intersections in closed form:
  // c (x^2 + y^2 + Z^2) = 2 Z; false for any other shape.
  virtual bool sphereCurvature(double* c) const { return false; }

  const Outline& outline() const { return outline_; }
  double zVertex() const { return z_vertex_; }
  ParamDomain domain() const override;
  SurfaceDerivs evaluate(double u, double v) const override;
  Vec3 normal(double u, double v) const override;  // exact, from the sag gradient
  // From the fundamental forms with the exact normal (a sag graph has no poles).
  Curvature curvature(double u, double v) const override;
  // One sag evaluation for position, normal and curvature (bit-identical to the separate calls).
  SurfacePoint sample(double u, double v, bool with_curvature) const override;

 private:
  Outline outline_;
  double z_vertex_ = 0;
};

using SagSurfacePtr = std::shared_ptr<const SagSurface>;

SagSurfacePtr makePlane(Outline outline, double z_vertex = 0);
SagSurfacePtr makeSphere(double radius, Outline outline, double z_vertex = 0);
// Even asphere: Z = c r^2 / (1 + sqrt(1 - (1 + k) c^2 r^2)) + sum_i a[i] r^(2i + 4), c = 1/R (a[0] is A4).
SagSurfacePtr makeAsphere(double radius, double conic, std::vector<double> coefficients, Outline outline,
                          double z_vertex = 0);
// Toric: principal radii radius_a along the direction at axis_rad from +x, radius_b perpendicular to it.
// Exact torus sag (the b-section is a circle swept along the a-section). A cylinder is radius_a = infinity.
SagSurfacePtr makeToric(double radius_a, double radius_b, double axis_rad, Outline outline,
                        double z_vertex = 0);
SagSurfacePtr makeCylinder(double radius, double axis_rad, Outline outline, double z_vertex = 0);

}  // namespace pvrr::cad
