// Aiming a mirror (pvrr fov --aim, issue 21): the rotation about its pivot (yaw about the vehicle's up axis, pitch
// about the horizontal axis in the mirror's plane) that meets the regulation zones with the largest margin.
//
// METHOD
//  1. Score of an adjustment: the footprints traced exactly (traceFootprint, obstructions included) with the
//     element turned, each zone evaluated (evaluateZone); a zone's score is its covered fraction plus its
//     obstructed fraction up to the allowance (1 exactly when the zone passes), the adjustment's score the
//     smallest over the zones. Piecewise constant in the angles, so searched, not differentiated:
//  2. a coarse grid over +-range_deg in both angles, then a fine grid around the best coarse cell. The best
//     cell has the highest score; among cells that pass, the one deepest inside the passing region (its
//     Chebyshev distance in cells to the nearest failing or unsearched cell), then the one nearest the current
//     adjustment.
//  3. Polish with Ceres on a smooth objective: each zone's edge points (inner and outer edge, from the near end to
//     the horizon end, uniform in the angle of depression) located on the mirror's parameter square by inverting
//     the reflection (Newton on the exact surface), their margin 1 - max(|s_x|, |s_y|) inside the square, the
//     residuals exp(-margin / 0.05) (a soft minimum of the margins: centres the zones in the mirror). Ceres' result
//     is kept only if its exact score (step 1) is no worse than the grid's and it passes whenever the grid's did:
//     its "converged" is never taken on trust.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "pvrr/analysis/fov.h"
#include "pvrr/analysis/fov_eyes.h"

namespace pvrr {

struct AimOptions {
  FovOptions fov;  // the sampling of the search's evaluations (the caller re-checks its answer with its own)
  double range_deg = 10;
  double coarse_step_deg = 2, fine_step_deg = 0.5;
  bool polish = true;
  std::optional<Vec3> pivot;  // world; default the element's pose position (its vertex)
  bool left_eye = true, right_eye = true;
  // The eye positions searched for, each seeing for its eye ("left" / "right") as evaluateZone counts them: an eye
  // ellipse's samples (fov_eyes.h; a point is seen by an eye when any of its samples sees it). Empty: the ocular
  // points chosen by left_eye / right_eye.
  std::vector<EyeSample> eye_samples;
};

// The eye positions of a search: options.eye_samples, else the ocular points left_eye / right_eye choose.
std::vector<EyeSample> aimEyes(const AimOptions& options, const VehicleFrame& frame);

struct AimAngles {
  double yaw_rad = 0, pitch_rad = 0;
};

struct AimScore {
  double score = 0;  // the smallest zone score (1: every zone passes)
  bool pass = false;
  std::vector<ZoneResult> zones;
};

struct AimResult {
  Vec3 pivot{0}, yaw_axis{0}, pitch_axis{0};  // world
  AimAngles angles;                           // the answer
  AimScore before, after;                     // at the search's sampling
  Mat4 local_to_world{1.0};                   // the element's aimed pose
  double margin_deg = 0;  // passing: the distance to the nearest failing or unsearched fine-grid cell
  int evaluations = 0;
  bool polished = false;  // Ceres' result kept
  std::string polish_report;
};

// The element's pose `local_to_world` turned about `pivot` by R = Rot(yaw_axis, yaw) Rot(pitch_axis, pitch) (unit
// axes, world): x -> pivot + R (x - pivot) after the pose.
Mat4 aimedPose(const Mat4& local_to_world, const Vec3& pivot, const Vec3& yaw_axis, const Vec3& pitch_axis,
               AimAngles a);

// The polish's smooth objective (METHOD 3), exposed for its tests: each zone edge point's margin on the mirror's
// parameter square at angles (yaw, pitch) in degrees; an eye's margin is the largest over its eye positions
// (aimEyes), a zone point's the eyes' combination its zone asks for (either: the larger, both: the smaller). Newton starts from seeds fixed by seedAt (once, before the
// solver runs), so margins() is a pure function of the angles: the same angles give the same bits whatever was
// evaluated before (Ceres' central differences compare two evaluations of one function).
class AimMargins {
 public:
  AimMargins(const Scene& scene, int element, const VehicleFrame& frame, const std::vector<FovZone>& zones,
             const AimOptions& options, const Mat4& base, const Vec3& pivot, const Vec3& yaw_axis,
             const Vec3& pitch_axis);
  void seedAt(const double* angles_deg);
  std::vector<double> margins(const double* angles_deg) const;
  size_t size() const { return points_.size(); }

 private:
  struct Point {
    Vec3 q;  // world, on the road
    FovZone::Eyes eyes;
    std::vector<Vec2> seed;  // per eye position (eyes_)
  };
  struct Solve {
    Vec2 s;
    double margin;
  };
  Vec2 residual(const Mat4& pose, const Vec3& eye, const Vec3& q, Vec2 s) const;
  Solve solve(const Mat4& pose, const Vec3& eye, const Vec3& q, Vec2 seed) const;

  const Element& el_;
  const VehicleFrame& frame_;
  std::vector<EyeSample> eyes_;
  Mat4 base_;
  Vec3 pivot_, yaw_axis_, pitch_axis_;
  std::vector<Point> points_;
};

// Searches the adjustment of mirror `element` of `scene` for `zones` (none: an error of the caller's).
AimResult aimMirror(const Scene& scene, int element, const VehicleFrame& frame, const std::vector<FovZone>& zones,
                    const AimOptions& options = {});

}  // namespace pvrr
