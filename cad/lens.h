// Lens solids: an eye-side ("front" in pvrr's per-vertex sense: the surface the eye ray meets first) and a
// far-side ("back") surface sharing one outline, both sag surfaces in the lens's local frame with +z
// towards the eye. The front vertex is at z = 0 and the back vertex at z = -centre_thickness. A surface
// from a CAD file (a NURBS face) becomes a sag surface through makeNurbsSag below.
#pragma once
#include <memory>
#include <optional>
#include <string>

#include "cad/nurbs.h"
#include "cad/sag.h"

namespace pvrr::cad {

// A lens surface from a NURBS surface (a CAD face, already scaled to metres) that is a graph over the lens's
// local xy plane: the file's x and y are the lens's local x and y, its z runs along the lens axis (+z
// towards the eye). The surface is only translated along z, so that its point over the local origin becomes
// the vertex at z_vertex; the orientation of its (u, v) parametrisation does not matter (the sag graph's
// normal points to +z, cad/sag.h).
//
// sag(x, y) finds the (u, v) over (x, y) by Newton iterations (from an affine guess, then from the nearest
// of a 33 x 33 table) and differentiates the graph implicitly: position, normal and curvature are the NURBS
// surface's own, exact to rounding.
// defined(x, y): the surface lies over (x, y) inside its parameter domain, inside its trim loop (when
// given, with the tolerance trim_tolerance_uv in (u, v)) and is at most kNurbsSagMaxSlope_deg steep there.
// Elsewhere sag() does not throw: it continues the surface by its second-order Taylor expansion at the
// boundary point where the inversion stops (continuous with a continuous gradient). That continuation is
// the "analytic extension" a lens's rim rays use (pvrr/method/vertex_stage.cpp); within the parameter domain
// (a CAD blank is usually larger than the edged lens) it is the NURBS surface itself.
// Throws pvrr::Error, prefixed by `what`, when the surface does not lie over the local origin.
constexpr double kNurbsSagMaxSlope_deg = 75;
SagSurfacePtr makeNurbsSag(std::shared_ptr<const NurbsSurface> surface, const Outline& outline,
                           std::optional<Outline> trim_uv, double trim_tolerance_uv, const std::string& what,
                           double z_vertex = 0);

struct LensSolid {
  SagSurfacePtr front;  // z_vertex = 0
  SagSurfacePtr back;   // z_vertex = -centre_thickness
  Outline outline;
  double centre_thickness = 0;
  // Thickness front - back at an outline point (x, y).
  double thicknessAt(double x, double y) const;
  // Minimum thickness over the outline (sampled densely over the region and its boundary).
  double minimumThickness() const;
  double edgeThicknessMin() const;  // minimum over the boundary only
};

// Builds and validates: throws pvrr::Error (prefixed by `what`) when the surfaces cross or touch inside the
// outline, or a sag is undefined there. With min_edge_thickness > 0 the centre thickness is raised so that
// the thinnest point of the edge has that thickness (minus lenses are specified this way).
LensSolid makeLens(SagSurfacePtr front_shape_at_zero, SagSurfacePtr back_shape_at_zero, Outline outline,
                   double centre_thickness, double min_edge_thickness, const std::string& what);

}  // namespace pvrr::cad
