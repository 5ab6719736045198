// Writes the project's shipped CAD models (models/) deterministically, and exposes their design so that
// tests can check the files against it. All lengths in millimetres.
#pragma once
#include <string>

#include "cad/nurbs.h"
#include "cad/outline.h"

namespace pvrr::cad {

// A surface fitted to a design, its trim in (u, v), and how well it fits (over the trimmed region).
struct GeneratedSurface {
  NurbsSurface surface;
  Outline trim;
  double fit_rms_mm = 0;  // RMS of z(surface) - z(design) over a grid inside the trim
  double fit_max_mm = 0;  // largest |z(surface) - z(design)| there
};

// Driver's-side convex door mirror glass, 200 x 150 mm (x = width, y = height), rounded rectangle with 30 mm
// corner radius. Design: a sphere of R = 1400 mm (vertex at the origin, tangent plane z = 0, centre at
// (0, 0, -1400)), with an outer band 40 mm wide on the +x side (x > 60 mm) whose curvature along x is raised
// to that of R = 600 mm (sag added: (1/600 - 1/1400) (x - 60)^2 / 2), the aspheric zone of real mirrors.
// The glass faces +z (towards the driver) and is convex towards it, so z <= 0.
struct CarMirrorDesign {
  static constexpr double width_mm = 200, height_mm = 150, corner_radius_mm = 30;
  static constexpr double main_radius_mm = 1400, band_radius_mm = 600, band_width_mm = 40;
  static double z(double x_mm, double y_mm);
};
// Non-rational bicubic B-spline, 6 x 5 poles, x(u) = u and y(v) = v exactly (poles at the Greville
// abscissae), a double knot at the band edge x = 60 mm (curvature may jump there, as the design's does),
// z fitted by least squares and then shifted so that z(0,0) = 0 and the tangent plane there is z = 0
// exactly. du × dv points to +z.
GeneratedSurface carMirrorSurface();
void writeCarMirrorStep(const std::string& path);

// Lens front surface: a sphere of R = 200 mm, convex towards +z (its normal side, the lens's front), vertex at
// the origin, over a circle of 60 mm diameter. Bicubic B-spline, 8 x 8 poles over [-32, 32]^2 mm, x(u) = u,
// y(v) = v, z fitted by least squares (and shifted to z(0,0) = 0 with tangent plane z = 0).
struct LensFrontDesign {
  static constexpr double radius_mm = 200, diameter_mm = 60;
  static double z(double x_mm, double y_mm);
};
GeneratedSurface lensFrontSurface();
void writeLensIges(const std::string& path);

// Catmull-Clark cage of a gently saddle-shaped freeform mirror: 7 x 6 vertices over 300 x 200 mm
// (x in [-150, 150] step 50, y in [-100, 100] step 40), z = x^2/(2*1500) - y^2/(2*900), quads wound
// counter-clockwise seen from +z (normal +z). Written as OBJ with a comment header (units mm).
struct FreeformCageDesign {
  static constexpr int nx = 7, ny = 6;
  static constexpr double width_mm = 300, height_mm = 200, radius_x_mm = 1500, radius_y_mm = 900;
  static double z(double x_mm, double y_mm);
};
void writeFreeformCageObj(const std::string& path);

}  // namespace pvrr::cad
