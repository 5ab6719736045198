// The virtual viewpoint of a mirror or lens patch (paper 3.2): the point e that is as close as possible to
// every reflected/refracted ray LINE of the patch's vertices, from which the 1st-pass reflection map is
// rendered. No Ceres or Eigen types here; the solvers live in viewpoint.cpp.
//
// Units and frames: world space, metres, radians. Ray directions are unit vectors (re-normalised on input).
//
// Method (see fitViewpoint):
//  1. Closed form: minimise the sum of squared point-to-line distances,
//       A e = b,  A = sum_i (I - d_i d_i^T),  b = sum_i (I - d_i d_i^T) o_i,
//     solved through the eigen-decomposition of the symmetric 3x3 A. condition_number = lambda_max/lambda_min
//     of A (scale-free: A's eigenvalues are sums of sin^2 of the ray angles, trace A = 2N). For a bundle of
//     angular spread phi, cond ~ 1/phi^2. A plane mirror gives lines that all pass through the mirror image
//     of the real eye: exact, and well conditioned unless the mirror is tiny or seen from far away.
//  2. Refinement of the angular (image) objective, which is what the reflection map shows: the angle at e
//     between the line from e to the hit point h_i and the ray's line (o_i, d_i),
//       r_i(e) = (a_i . u_i, b_i . u_i),  u_i = (h_i - e)/|h_i - e|,  (a_i, b_i, d_i) orthonormal,
//     |r_i| = sin(theta_i), theta_i = the line angle in [0, pi/2] (the angle between h_i - e and d_i, or
//     -d_i when h_i lies behind e: zooming-region hits are seen looking back, see view_volume.h).
//     objective F(e) = 1/2 sum_i rho(|r_i|^2) + 1/2 |r_p|^2   [rad^2, Ceres' convention],
//     rho = Cauchy loss, rho(x) = s^2 log(1 + x/s^2) (rho(x) ~ x for x << s^2), with the scale s of
//     ViewpointFit::robust_scale_rad (from the options and the median residual, see ViewpointOptions),
//     r_p = the prior (fallback only, below). Far hit points (escaping rays) constrain e only weakly, as
//     they should: a displacement delta of e changes the image angle by about delta/|h_i - e|.
//     Default solver (kAuto): our own Levenberg-damped Newton-type iteration on the 3x3 system (IRLS weights
//     rho' plus the clamped second-order term of the loss along each residual, which takes 6-11 iterations
//     where plain IRLS, and Ceres, need 16-24), one pass over the rays per step. Ceres (autodiff, DENSE_QR)
//     runs only when the quick solve fails a check (below), or always with ViewpointSolver::kCeres.
//     Ceres costs about ten times the default per ray, over the vertex stages' budget, hence not the default
//     (measured: tests/bench/viewpoint.cpp; figures in docs/method.md "Measurements behind the design").
//  3. Conditioning fallback: when cond(A) > max_condition_number (nearly parallel lines: a nearly flat
//     mirror seen from afar) or the closed-form point is farther than max_eye_distance_m from the patch
//     centroid, the eye is placed at the nominal point
//       e_nom = c - D m,   c = centroid of the origins, m = normalised mean direction,
//       D = clamp(r / tan(phi), min_fallback_distance_m, max_fallback_distance_m),
//     r = the largest distance of an origin from the axis (c, m), phi = the largest angle between a d_i and m
//     (the distance at which the patch subtends the rays' spread; +inf -> the upper clamp). The closed form
//     keeps e_nom's components along A's ill-conditioned eigenvectors (lambda_k < lambda_max /
//     max_condition_number; along m when the point was too far) and solves the others; the refinement adds
//     the weak Tikhonov prior r_p = sqrt(prior_weight * N) (e - e_nom) / D, i.e. the prior carries
//     prior_weight of the data's total weight. Along the ill-conditioned direction the angular objective
//     pulls e weakly (towards infinity for parallel rays); the prior holds it within about
//     r^2 D^2 / ((t + D)^3 prior_weight) of e_nom (t: typical hit distance): 5-8 mm at D = 100 m in the
//     tests. `fallback` says what was done and why; fallback_distance_m = D.
//  4. Nothing from a solver is accepted unchecked (Ceres reports CONVERGENCE on degenerate problems,
//     platform.md b): the result must be finite, the solver must report convergence, and F(final) must not
//     exceed F(start), with F evaluated by our own code. kAuto tries Ceres when the quick solve fails. If no
//     refinement passes, the best finite point that lowered F (else the closed-form start) is kept,
//     accepted = false, and `fallback` says why.
#pragma once
#include <string>
#include <vector>

#include "pvrr/scene/render_desc.h"
#include "pvrr/base/math.h"

namespace pvrr {

// One vertex of a mirror/lens patch: the outgoing (reflected or refracted) ray and its scene hit point.
struct ViewpointRay {
  Vec3 origin;     // the vertex on the optical surface (m, world)
  Vec3 direction;  // unit direction of the outgoing ray into the scene
  Vec3 hit;        // origin + t * direction, t > 0: the first scene hit, or a far point for escaping rays
};

// ViewpointSolver: the scene's render.viewpoint_solver (pvrr/scene/render_desc.h, with its name table).

struct ViewpointOptions {
  // Cauchy loss scale of the angular residual (rad); <= 0 disables the robust loss (plain least squares on
  // the sines of the angles). Residuals well below it count quadratically, those well above are
  // down-weighted as outliers (e.g. escaped rays with wrong far points). 3 arcminutes (0.87 mrad): the angle
  // a 1 cm offset of e subtends at a hit 11 m away; a few texels of a 1k map spanning 30 deg.
  double robust_scale_rad = 3.0 / 60.0 * kPi / 180.0;
  // The scale used is max(robust_scale_rad, robust_median_factor * the median line angle at the closed-form
  // start): the ordinary aberration of a strongly curved patch is not an outlier (3 x median ~ 2 sigma of a
  // Gaussian). With the scale below the typical residual, Gauss-Newton (ours and Ceres') needs tens of
  // iterations instead of a few.
  double robust_median_factor = 3.0;
  // Fallback prior weight as a fraction of the data's total weight (N rays): weak by design.
  double prior_weight = 1e-2;
  double max_condition_number = 1e8;    // cond(A) above this -> fallback (angular spread below ~0.006 deg)
  double max_eye_distance_m = 1e4;      // closed-form eye farther than this from the centroid -> fallback
  double min_fallback_distance_m = 0.1; // clamp of the nominal distance D behind the patch centroid
  double max_fallback_distance_m = 100.0;
  ViewpointSolver solver = ViewpointSolver::kAuto;
  int max_iterations = 50;
  // Convergence: relative change of F per step, and step length relative to (|e - c| + patch radius).
  double function_tolerance = 1e-12;
  double step_tolerance = 1e-12;
};

struct ViewpointFit {
  Vec3 eye{0};
  Vec3 closed_form_eye{0};      // the closed-form (or fallback) start of the refinement
  double condition_number = 0;  // lambda_max / lambda_min of A = sum (I - d d^T); +inf when singular
  // lambda_max / lambda_min of the angular Gauss-Newton matrix J^T J = sum_i P_u P_d P_u / |h_i - e|^2 at the
  // final eye (data only: no robust weights, no prior); +inf when singular.
  double condition_number_solution = 0;
  double robust_scale_rad = 0;  // the Cauchy scale used (see ViewpointOptions); 0: no robust loss
  double cost_initial = 0;  // F at closed_form_eye (rad^2, definition above, prior included)
  double cost_final = 0;    // F at eye
  double rms_line_distance_m = 0;  // RMS distance from eye to the lines (o_i, d_i)
  // Image error of vertex i: the line angle theta_i at the eye between h_i - eye and the ray's line (the
  // angle to d_i, or to -d_i for hits behind the eye), in [0, pi/2]. RMS and max over all rays, no robust
  // weighting.
  double rms_angle_rad = 0;
  double max_angle_rad = 0;
  int hits_behind_eye = 0;  // rays with (h_i - eye) . d_i < 0 (zooming region, see view_volume.h)
  int iterations = 0;       // of the solver that produced `eye` (0 for kClosedForm)
  std::string solver_report;  // "<solver>: <termination>, <summary>"
  std::string fallback;       // "" when none; otherwise what was done and why
  double fallback_distance_m = 0;  // D of the nominal point when a fallback was used, else 0
  bool accepted = false;  // eye finite, solver converged, F(final) <= F(start)
};

// Throws pvrr::Error when rays is empty or a ray has a non-finite or zero direction or a non-finite point.
ViewpointFit fitViewpoint(const std::vector<ViewpointRay>& rays, const ViewpointOptions& options = {});

// The angular objective F (rad^2, definition above) without the prior: for tests and benchmarks.
double viewpointAngularCost(const std::vector<ViewpointRay>& rays, const Vec3& eye, double robust_scale_rad);
// The same F with the refinement's gradient g (exact, 1/m) and Newton-type matrix H (1/m^2; see
// pvrr/method/viewpoint.cpp): what each Gauss-Newton step solves, for tests.
struct ViewpointCostDerivatives {
  double cost = 0;
  Vec3 gradient{0};
  Mat3 normal_matrix{0.0};
};
ViewpointCostDerivatives viewpointAngularCostDerivatives(const std::vector<ViewpointRay>& rays, const Vec3& eye,
                                                         double robust_scale_rad);

}  // namespace pvrr
