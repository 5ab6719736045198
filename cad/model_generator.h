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

// Progressive-lens-like object-side ("back") surface, in the lens frame of cad/lens.h (+z towards the eye,
// y up, x across), for a plano-distance lens with a +2.00 D add in CR-39.
// Design, as a sag Z (measured from the vertex away from +z, cad/sag.h) with the surface at z = -Z:
//   Z(x, y) = c r^2 / (1 + sqrt(1 - c^2 r^2)) + kappa (G(y) + S(y) x^2 / 2),
//   c = 1 / base_radius (base_radius = -124.5 mm: a +4.00 D object-side base curve, (n - 1) / 124.5 mm),
//   kappa = -add / (n - 1) (the change of sag curvature that adds `add` dioptres to this surface's power
//   F = -(n - 1) Z'' , n = n_d of CR-39),
//   S(y) = s(t) with t = (corridor_top - y) / corridor_length clamped to [0, 1] and s(t) = 6t^5 - 15t^4 + 10t^3
//   (C2 smooth step: 0 in the distance zone above the corridor, 1 in the near zone below it),
//   G'' = S, G = 0 above the corridor: G = L^2 (t^7/7 - t^6/2 + t^5/2) in it and continued quadratically below.
// Along the corridor line x = 0 the add term is umbilic (Z_xx = Z_yy = kappa S, Z_xy = 0): the mean power
// grows smoothly from 0 at y = corridor_top to `add` at corridor_top - corridor_length with no astigmatism,
// while astigmatism kappa |S'| |x| (Z_xy = kappa S' x) grows away from it on both sides, as Minkwitz's theorem
// requires of every real progressive surface. The fitting point (the lens axis, the origin) is at the top of
// the corridor, so the vertex region is the plain base sphere.
// Bicubic B-spline over the blank [-28, 28] x [-23, 23] mm (x(u) = u, y(v) = v), 11 x 19 poles, 1.5 mm knot
// spacing in y along the corridor and knots at both its ends (the design is C2 there); fitted by least squares; written untrimmed as IGES (the blank:
// the lens outline, an ellipse of 50 x 40 mm in models/progressive-lens.json, lies inside it with a 3 mm margin
// that carries the lens's rim rays). GeneratedSurface::trim is that ellipse: the region the fit is measured on.
struct ProgressiveBackDesign {
  static constexpr double n_d = 1.498;  // CR-39: the powers below hold at the d line
  static constexpr double base_radius_mm = -124.5, add_d = 2.0;
  static constexpr double corridor_top_mm = 0, corridor_length_mm = 12;
  static constexpr double blank_width_mm = 56, blank_height_mm = 46;
  static constexpr double lens_width_mm = 50, lens_height_mm = 40;
  // Surface z (mm) in the lens frame, z(0, 0) = 0 with tangent plane z = 0.
  static double z(double x_mm, double y_mm);
  // The add (dioptres) of the design along the corridor at height y: add_d S(y).
  static double addAt(double y_mm);
};
GeneratedSurface progressiveBackSurface();
void writeProgressiveBackIges(const std::string& path);

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
