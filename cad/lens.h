// Lens solids: an eye-side ("front" in pvrr's per-vertex sense: the surface the eye ray meets first) and a
// far-side ("back") surface sharing one outline, both sag surfaces in the lens's local frame with +z
// towards the eye. The front vertex is at z = 0 and the back vertex at z = -centre_thickness.
#pragma once
#include "cad/sag.h"

namespace pvrr::cad {

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
