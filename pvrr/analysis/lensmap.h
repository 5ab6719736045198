// Lens maps: what the eye gets through a spectacle lens as it turns behind it (issue 27). Per gaze direction,
// the chief ray through the eye's centre of rotation traced exactly through both lens surfaces (RayScene's
// exact element intersections, vector Snell), then the local wavefront from the object by a small ray bundle
// (central differences of the exact rays) on the vertex sphere: power, astigmatism, prism, distortion and
// lateral colour.
//
// CONVENTIONS (the only statement of them; docs/lensmap.md and lensmap.json repeat them for users):
//  - Lens frame: the element's local frame (cad/lens.h): +z towards the eye, the eye-side ("front") vertex at
//    the origin, +y up (pose.up), +x = y x z, which is the WEARER'S RIGHT for a lens posed like the shipped
//    spectacle lens (normal towards the eye, up = up).
//  - Rotation centre: on the lens axis, rotation_centre_m behind the eye-side vertex: local (0, 0, +r).
//    The vertex sphere is the sphere about it through the eye-side vertex (radius r).
//  - Gaze as Fick angles: gaze_x turns the eye towards the wearer's right about the vertical (local y) axis,
//    then gaze_y turns it up about the turned horizontal axis. The eye looks along
//      g = (cos gy sin gx, sin gy, -cos gy cos gx)  (lens frame),
//    with its own frame e_x = (cos gx, 0, sin gx) (the eye's right) and e_y = (-sin gy sin gx, cos gy,
//    sin gy cos gx) (the eye's up).
//  - Powers in dioptres, positive converging. The vergence matrix V of the wavefront reaching the eye is taken
//    where the chief ray crosses the vertex sphere, in (e_x, e_y); power = V - V_object, with V_object = 0 for
//    an object at infinity and -1 / (M - r) for an object M from the rotation centre (the vergence the
//    object's own wavefront would have there without the lens).
//  - Sphere / cylinder / axis in minus-cylinder form (cylinder <= 0): the sphere acts along the axis meridian.
//    Axis in the TABO convention of prescriptions: 0 to 180 deg, counter-clockwise as seen by someone facing
//    the wearer, 0 at the wearer's left. A meridian at angle phi counter-clockwise from the eye's right, as the
//    wearer sees it, has TABO angle 180 - phi (mod 180).
//  - Prism in the eye's own frame, in prism dioptres (100 x tangent of the deviation): with the object-side
//    direction of the chief ray o (from the lens towards the object), prism_h = 100 (o . e_x) / (o . g) and
//    prism_v = 100 (o . e_y) / (o . g). Base right and base up are positive: the base is the side the lens
//    bends the light towards (a minus lens seen through right of its centre is base right).
//  - Power error and unwanted cylinder against the prescription P (the centre's power matrix): with
//    D = V - P (each in its gaze's eye frame), power error = mean of D's eigenvalues, unwanted cylinder =
//    their difference, >= 0 (the magnitude iso-cylinder maps show).
//  - Tangential and sagittal power: V along the meridian through the lens axis (the projection of the lens
//    axis onto the eye's frame; e_x at the centre) and across it.
//  - Prentice's rule beside it: prism = decentration (cm) x power, with the decentration of the chief ray's
//    point on the eye-side surface from the lens axis d (lens frame, m) and the centre's power matrix V0:
//    (prentice_h, prentice_v) = -100 V0 d, signed like the traced prism. An approximation: it ignores the lens form,
//    thickness and the oblique path.
//  - Distortion: the object's direction seen from the rotation centre (the object-side chief ray's direction
//    for an object at infinity, the object point for a near one) as tangents t_obj in the lens frame, against
//    the gaze's tangents t_gaze = (g.x, g.y) / (-g.z) = (tan gx, tan gy / cos gx) (the image the eye sees):
//    distortion_pct = 100 (|t_gaze| / |J0^-1 (t_obj - t_obj0)| - 1), the image against its paraxial position,
//    with J0 the derivative of t_obj by t_gaze straight ahead (the inverse of the paraxial angular
//    magnification) and t_obj0 the straight-ahead object direction. Negative: barrel (a minus lens),
//    positive: pincushion (a plus lens).
//  - Lateral colour: the angle (arcmin, >= 0) between the object-side chief ray directions at the F and C
//    lines (486.13, 656.27 nm) for the same gaze.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "pvrr/base/math.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr {

struct LensmapOptions {
  double rotation_centre_m = 0.0255;  // from the eye-side vertex (12 mm vertex distance + 13.5 mm)
  double object_distance_m = kInf;    // from the rotation centre; infinity: a distant object
  int grid = 41;                      // grid x grid gazes, each angle from -gaze_max_deg to +gaze_max_deg
  double gaze_max_deg = 40;
  // Half-spacing of the ray bundle in object space (a lateral offset in m, or for a near object that offset
  // divided by the object's distance as an angle): small enough that the wavefront's higher orders leave
  // the central differences' power below 1e-5 D, large enough that the exact rays' rounding (~1e-14 m)
  // stays below 1e-8 D (measured: docs/lensmap.md).
  double bundle_offset_m = 1e-4;
};

// The local wavefront and ray data at one gaze. `valid` false: a ray of the bundle missed a surface (outside
// the outline) or was totally reflected; `reason` says which.
struct LensmapPoint {
  double gaze_x_deg = 0, gaze_y_deg = 0;
  bool valid = false;
  std::string reason;
  double lens_x_mm = 0, lens_y_mm = 0;                // the chief ray on the eye-side surface, lens frame
  double vxx = 0, vxy = 0, vyy = 0;                   // power matrix (dioptres) in (e_x, e_y), V - V_object
  double sphere_d = 0, cylinder_d = 0, axis_deg = 0;  // minus cylinder, TABO
  double mean_power_d = 0;                            // sphere + cylinder / 2
  double tangential_d = 0, sagittal_d = 0;            // power in the meridian through the lens axis and across it
  double power_error_d = 0;                           // mean power minus the prescription's
  double unwanted_cylinder_d = 0;                     // |cylinder| (>= 0) of the power matrix minus the prescription's
  double prism_h = 0, prism_v = 0;                    // prism dioptres, base right / base up positive
  double prentice_h = 0, prentice_v = 0;              // Prentice's rule, same signs
  double object_x_deg = 0, object_y_deg = 0;          // the object's direction from the rotation centre (Fick angles)
  double distortion_pct = 0;
  double lateral_colour_arcmin = 0;
  double asymmetry_d = 0;  // |V_xy - V_yx| of the fitted matrix: a check of the bundle (~0)
};

// The eigen-decomposition of a symmetric power matrix (vxx, vxy, vyy in the eye's frame) in minus-cylinder
// form with the axis in TABO (conventions above).
struct SphCylAxis {
  double sphere_d = 0, cylinder_d = 0, axis_deg = 0;
};
SphCylAxis sphCylAxis(double vxx, double vxy, double vyy);

struct LensmapResult {
  std::string element;
  LensmapOptions options;
  double n_d = 0, abbe = 0;
  LensmapPoint centre;               // gaze (0, 0): the prescription the errors are taken against
  std::vector<LensmapPoint> points;  // grid x grid, rows from gaze_y = -max up, x from -max right
  int empty = 0;                     // invalid points (miss or TIR)
  int empty_miss = 0, empty_tir = 0;
  // Focimeter: the optical centre (where the chief ray leaves undeviated: zero prism), found by Newton
  // iterations on the gaze; the back vertex power there, measured with a parallel beam on the eye-side
  // surface. Absent when the search does not converge (the reason is kept).
  struct Focimeter {
    bool found = false;
    std::string reason;
    double gaze_x_deg = 0, gaze_y_deg = 0, lens_x_mm = 0, lens_y_mm = 0;
    double sphere_d = 0, cylinder_d = 0, axis_deg = 0;
    int iterations = 0;
    double residual_prism = 0;
  } focimeter;
  // A progressive lens (the mean power along the vertical meridian gaze_x = 0 rises by at least
  // kProgressiveMinAdd_d below the straight-ahead gaze): its reference points and corridor, searched along that
  // meridian (a corridor without inset) in steps of kProgressiveStep_deg.
  struct Progressive {
    bool detected = false;
    double add_d = 0;  // highest mean power along the meridian minus the far point's
    // Far point: the straight-ahead gaze (the prescription). Near point: the first gaze down the meridian
    // where the power reaches 95 % of the add.
    double far_gaze_y_deg = 0, far_lens_y_mm = 0, far_mean_d = 0;
    double near_gaze_y_deg = 0, near_lens_y_mm = 0, near_mean_d = 0;
    // Corridor length: from the far point down to where the power reaches 85 % of the add (lens mm on the
    // eye-side surface). Width: where the power reaches 50 % of the add, the horizontal extent (lens mm) of
    // the gazes whose unwanted cylinder stays below 0.5 D.
    double corridor_length_mm = 0;
    double corridor_mid_gaze_y_deg = 0, corridor_width_mm = 0;
  } progressive;
  double elapsed_ms = 0;
};
constexpr double kProgressiveMinAdd_d = 0.5;
constexpr double kProgressiveStep_deg = 0.25;
constexpr double kCorridorCylinder_d = 0.5;

class Lensmap {
 public:
  // `element` indexes a lens of rays.scene(). Throws pvrr::Error for a mirror or an index out of range.
  Lensmap(const RayScene& rays, int element, LensmapOptions options);

  // One gaze, with the errors against `prescription` (null: none; the errors are then zero).
  LensmapPoint evaluate(double gaze_x_deg, double gaze_y_deg, const LensmapPoint* prescription = nullptr) const;
  // The whole map (multithreaded over gazes), its centre and the focimeter reading.
  LensmapResult run() const;
  LensmapResult::Focimeter focimeter() const;
  // The progressive lens's reference points and corridor against the prescription `rx` (run() calls it).
  LensmapResult::Progressive progressive(const LensmapPoint& rx) const;
  // The object's tangents (x, y) / (-z) seen from the rotation centre at gaze tangents t_gaze =
  // (tan gx, tan gy / cos gx), lens frame; false where the chief ray fails.
  bool objectTangents(const Vec2& t_gaze, Vec2& t_obj) const;
  // The inverse: the gaze tangents that see the object at tangents t_obj, by Newton iterations from the
  // paraxial guess (converged to 1e-12 in tangent, or nothing). Straight lines in object space through this
  // are the distortion map's curves.
  std::optional<Vec2> gazeForObject(const Vec2& t_obj) const;
  // The paraxial mapping: the object tangents t_obj0 + J0 t_gaze (NaN when J0 could not be measured).
  Vec2 paraxialObject(const Vec2& t_gaze) const;

  // The exact chief ray from the rotation centre along gaze g at `wavelength_nm` (lens frame). False with a
  // reason when it misses a surface or is totally reflected.
  struct Chief {
    bool ok = false;
    std::string reason;
    Vec3 front{0}, back{0};  // where it crosses the eye-side and object-side surfaces
    Vec3 out{0};             // unit direction from the lens towards the object
  };
  Chief chief(const Vec3& g_local, double wavelength_nm) const;

 private:
  // The bundle's power matrix at the plane through `at` normal to the chief ray (object-side direction `out`,
  // eye-side direction -g). False when a ray fails.
  bool bundle(const Chief& c, const Vec3& g, const Vec3& ex, const Vec3& ey, const Vec3& at, double v[4],
              std::string& reason) const;
  Vec3 objectDirection(const Chief& c) const;

  const RayScene& rays_;
  const Element& el_;
  int element_;
  LensmapOptions options_;
  double n_d_;
  Vec3 centre_local_;
  // Distortion's reference (straight ahead): the object's tangents and their derivatives by the gaze's.
  bool have_j0_ = false;
  Vec2 t_obj0_{0}, j0x_{0}, j0y_{0};
};

}  // namespace pvrr
