#include "pvrr/analysis/fov_aim.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "pvrr/base/error.h"
#include "pvrr/base/format.h"
#include "pvrr/optics/optics.h"

namespace pvrr {

namespace {

constexpr double kDeg = kPi / 180;
// The smooth objective's temperature: margins are in units of the parameter square's half width; 0.05 (2.5 % of
// the mirror's width) makes the soft minimum follow the smallest margin without flattening the others away.
constexpr double kSoftMinScale = 0.05;
// Edge points per zone edge for the smooth objective.
constexpr int kEdgePoints = 6;
// Newton on the mirror's parameter square: stop when the angular residual is below this (radians).
constexpr double kInverseTol_rad = 1e-12;
constexpr int kInverseIterations = 40;
// Finite-difference step on the parameter square for the inverse's Jacobian (the surface is smooth on a much
// larger scale; the step's truncation error, ~1e-12, is below the residual's significance).
constexpr double kSquareStep = 1e-6;

// Rodrigues' rotation about unit axis k by angle a.
Mat3 rotation(const Vec3& k, double a) {
  const double c = std::cos(a), s = std::sin(a);
  const Mat3 K(0, k.z, -k.y, -k.z, 0, k.x, k.y, -k.x, 0);  // column-major: K v = k x v
  return Mat3(1.0) + s * K + (1 - c) * (K * K);
}

double zoneScore(const FovZone& z, const ZoneResult& r) {
  return r.covered_fraction + std::min(r.obstructed_fraction, z.allowed_obstructed_fraction);
}

struct Searcher {
  const Scene& scene;
  int element;
  const VehicleFrame& frame;
  const std::vector<FovZone>& zones;
  const AimOptions& options;
  Mat4 base;
  Vec3 pivot, yaw_axis, pitch_axis;
  Scene work;                        // the scene with the element turned
  std::unique_ptr<RayScene> tracer;  // on `work`: one Embree scene, the element moved in it per evaluation
  int evaluations = 0;
  std::vector<EyeSample> eyes;  // aimEyes

  AimScore evaluate(AimAngles a) {
    ++evaluations;
    Element& el = work.elements[size_t(element)];
    el.local_to_world = aimedPose(base, pivot, yaw_axis, pitch_axis, a);
    el.world_to_local = glm::inverse(el.local_to_world);
    if (!tracer)
      tracer = std::make_unique<RayScene>(work);
    else
      tracer->updateElementPoses();
    const RayScene& rays = *tracer;
    std::vector<EyeFootprint> feet;
    for (const EyeSample& e : eyes) feet.push_back(traceFootprint(rays, element, frame, e.world, e.eye, options.fov));
    std::vector<const EyeFootprint*> eyes;
    for (const EyeFootprint& f : feet) eyes.push_back(&f);
    AimScore s;
    s.score = 1;
    s.pass = true;
    for (const FovZone& z : zones) {
      s.zones.push_back(evaluateZone(z, frame, eyes, options.fov));
      s.score = std::min(s.score, zoneScore(z, s.zones.back()));
      s.pass = s.pass && s.zones.back().pass;
    }
    return s;
  }

  struct Cell {
    AimAngles a;
    AimScore s;
    int depth = 0;  // passing: Chebyshev distance in cells to the nearest failing or unsearched cell
  };

  // A (2 m + 1)^2 grid of step `step_rad` centred on `c`; returns the best cell (METHOD 2).
  Cell grid(AimAngles c, double step_rad, int m) {
    const int n = 2 * m + 1;
    std::vector<Cell> cells(size_t(n) * size_t(n));
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        Cell& cell = cells[size_t(j) * size_t(n) + size_t(i)];
        cell.a = {c.yaw_rad + (i - m) * step_rad, c.pitch_rad + (j - m) * step_rad};
        cell.s = evaluate(cell.a);
      }
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        Cell& cell = cells[size_t(j) * size_t(n) + size_t(i)];
        if (!cell.s.pass) continue;
        int d = std::min({i, j, n - 1 - i, n - 1 - j}) + 1;  // the unsearched outside counts as failing
        for (int jj = 0; jj < n; ++jj)
          for (int ii = 0; ii < n; ++ii)
            if (!cells[size_t(jj) * size_t(n) + size_t(ii)].s.pass)
              d = std::min(d, std::max(std::abs(ii - i), std::abs(jj - j)));
        cell.depth = d;
      }
    const Cell* best = &cells[0];
    auto dist = [](const AimAngles& a) { return std::hypot(a.yaw_rad, a.pitch_rad); };
    for (const Cell& cell : cells) {
      if (cell.s.score != best->s.score ? cell.s.score > best->s.score
          : cell.depth != best->depth   ? cell.depth > best->depth
                                        : dist(cell.a) < dist(best->a))
        best = &cell;
    }
    return *best;
  }
};

}  // namespace

// The smooth objective (METHOD 3): the zones' edge points located on the mirror's parameter square.
AimMargins::AimMargins(const Scene& scene, int element, const VehicleFrame& frame, const std::vector<FovZone>& zones,
                       const AimOptions& options, const Mat4& base, const Vec3& pivot, const Vec3& yaw_axis,
                       const Vec3& pitch_axis)
    : el_(scene.elements[size_t(element)]),
      frame_(frame),
      eyes_(aimEyes(options, frame)),
      base_(base),
      pivot_(pivot),
      yaw_axis_(yaw_axis),
      pitch_axis_(pitch_axis) {
  const double h = 0.5 * (frame.eye(true).z + frame.eye(false).z);
  for (const FovZone& z : zones) {
    const std::vector<Vec2> poly = zoneInVehicle(z, frame, options.fov.zone_horizon_m);
    Vec2 lo(kInf), hi(-kInf);
    for (const Vec2& p : poly) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    const double a0 = std::atan2(h, std::max(-hi.x, 1e-3)), a1 = std::atan2(h, -lo.x);
    for (int k = 0; k < kEdgePoints; ++k) {
      const double x = -h / std::tan(a0 + (a1 - a0) * k / (kEdgePoints - 1));
      for (const double y : {lo.y, hi.y})
        points_.push_back({frame.toWorld(Vec3(x, y, 0)), z.eyes, std::vector<Vec2>(eyes_.size(), Vec2(0))});
    }
  }
}

void AimMargins::seedAt(const double* angles_deg) {
  const Mat4 pose = aimedPose(base_, pivot_, yaw_axis_, pitch_axis_, {angles_deg[0] * kDeg, angles_deg[1] * kDeg});
  for (Point& p : points_)
    for (size_t e = 0; e < eyes_.size(); ++e) p.seed[e] = solve(pose, eyes_[e].world, p.q, p.seed[e]).s;
}

std::vector<double> AimMargins::margins(const double* angles_deg) const {
  const Mat4 pose = aimedPose(base_, pivot_, yaw_axis_, pitch_axis_, {angles_deg[0] * kDeg, angles_deg[1] * kDeg});
  std::vector<double> out;
  for (const Point& p : points_) {
    double ml = -kInf, mr = -kInf;
    for (size_t e = 0; e < eyes_.size(); ++e) {
      double& m = eyes_[e].eye == "left" ? ml : mr;
      m = std::max(m, solve(pose, eyes_[e].world, p.q, p.seed[e]).margin);
    }
    // An eye not searched for sees nothing (margin -1, a whole square's width outside).
    if (ml == -kInf) ml = -1;
    if (mr == -kInf) mr = -1;
    switch (p.eyes) {
      case FovZone::Eyes::Either:
        out.push_back(std::max(ml, mr));
        break;
      case FovZone::Eyes::Both:
        out.push_back(std::min(ml, mr));
        break;
      case FovZone::Eyes::Left:
        out.push_back(ml);
        break;
      case FovZone::Eyes::Right:
        out.push_back(mr);
        break;
    }
  }
  return out;
}

// The residual angle vector between the reflected ray at square point s and the way to q.
Vec2 AimMargins::residual(const Mat4& pose, const Vec3& eye, const Vec3& q, Vec2 s) const {
  const Vec2 uv = mirrorParameters(el_, s);
  const cad::SurfacePoint sp = el_.frontSurface().sample(uv.x, uv.y, false);
  const Vec3 p = Vec3(pose * Vec4(sp.p, 1.0)), n = glm::normalize(Vec3(pose * Vec4(sp.n, 0.0)));
  const Vec3 r = reflect(glm::normalize(p - eye), n), w = glm::normalize(q - p);
  const Vec3 e1 = glm::normalize(glm::cross(r, std::abs(r.y) < 0.9 ? Vec3(0, 1, 0) : Vec3(1, 0, 0)));
  const Vec3 e2 = glm::cross(r, e1);
  return Vec2(glm::dot(w, e1), glm::dot(w, e2));
}

// Newton on the square from `seed`, clamped to it: inside, 1 - max(|s_x|, |s_y|); held at the edge, minus the
// remaining angle over the angle one square unit spans there (continuous through 0 at the edge). A function of its
// arguments only (no state is kept between calls: Ceres' central differences see one function).
AimMargins::Solve AimMargins::solve(const Mat4& pose, const Vec3& eye, const Vec3& q, Vec2 seed) const {
  Vec2 s = seed;
  if (glm::length(residual(pose, eye, q, s)) > 0.2) {  // a poor start: the best of a coarse grid
    double best = kInf;
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 5; ++i) {
        const Vec2 c(-1 + 0.5 * i, -1 + 0.5 * j);
        const double e = glm::length(residual(pose, eye, q, c));
        if (e < best) {
          best = e;
          s = c;
        }
      }
  }
  double scale = 1;
  Vec2 f = residual(pose, eye, q, s);
  for (int it = 0; it < kInverseIterations && glm::length(f) > kInverseTol_rad; ++it) {
    const Vec2 fu = (residual(pose, eye, q, s + Vec2(kSquareStep, 0)) - f) / kSquareStep;
    const Vec2 fv = (residual(pose, eye, q, s + Vec2(0, kSquareStep)) - f) / kSquareStep;
    const double det = fu.x * fv.y - fv.x * fu.y;
    scale = std::sqrt(std::abs(det));
    if (!(std::abs(det) > 1e-300)) break;
    const Vec2 step(-(fv.y * f.x - fv.x * f.y) / det, -(-fu.y * f.x + fu.x * f.y) / det);
    const Vec2 next = glm::clamp(s + step, Vec2(-1), Vec2(1));
    if (next == s) break;  // held at the edge
    s = next;
    f = residual(pose, eye, q, s);
  }
  const double inside = 1 - std::max(std::abs(s.x), std::abs(s.y));
  const double miss = glm::length(f);
  return {s, miss <= 1e-9 || scale <= 0 ? inside : inside - miss / scale};
}

namespace {

struct SoftMinResidual {
  const AimMargins* m;
  bool operator()(const double* angles_deg, double* residuals) const {
    const std::vector<double> g = m->margins(angles_deg);
    for (size_t i = 0; i < g.size(); ++i) residuals[i] = std::exp(-g[i] / kSoftMinScale);
    return true;
  }
};

}  // namespace

std::vector<EyeSample> aimEyes(const AimOptions& options, const VehicleFrame& frame) {
  if (!options.eye_samples.empty()) return options.eye_samples;
  std::vector<EyeSample> e;
  if (options.left_eye) e.push_back({"left", frame.desc().eye_left, Vec3(0)});
  if (options.right_eye) e.push_back({"right", frame.desc().eye_right, Vec3(0)});
  return e;
}

Mat4 aimedPose(const Mat4& local_to_world, const Vec3& pivot, const Vec3& yaw_axis, const Vec3& pitch_axis,
               AimAngles a) {
  const Mat3 R = rotation(yaw_axis, a.yaw_rad) * rotation(pitch_axis, a.pitch_rad);
  Mat4 M(R);
  M[3] = Vec4(pivot - R * pivot, 1.0);
  return M * local_to_world;
}

AimResult aimMirror(const Scene& scene, int element, const VehicleFrame& frame, const std::vector<FovZone>& zones,
                    const AimOptions& options) {
  PVRR_CHECK(!zones.empty());
  const std::vector<EyeSample> eyes = aimEyes(options, frame);
  PVRR_CHECK(!eyes.empty());
  PVRR_CHECK(options.coarse_step_deg > 0 && options.fine_step_deg > 0 && options.range_deg >= options.coarse_step_deg);
  const Element& el = scene.elements[size_t(element)];
  AimResult res;
  res.pivot = options.pivot ? *options.pivot : el.toWorldPoint(Vec3(0));
  res.yaw_axis = frame.toWorld(Vec3(0, 0, 1)) - frame.toWorld(Vec3(0));
  const Vec3 n = glm::normalize(el.toWorldDir(Vec3(0, 0, 1)));
  const Vec3 h = glm::cross(res.yaw_axis, n);
  if (glm::length(h) < 1e-6) throw Error(el.name + ": pvrr fov --aim: the mirror faces straight up or down");
  res.pitch_axis = glm::normalize(h);

  Searcher s{scene,     element,      frame,          zones, options, el.local_to_world,
             res.pivot, res.yaw_axis, res.pitch_axis, scene, nullptr, 0, eyes};
  res.before = s.evaluate({});
  const int mc = int(std::floor(options.range_deg / options.coarse_step_deg + 1e-9));
  const Searcher::Cell coarse = s.grid({}, options.coarse_step_deg * kDeg, mc);
  const int mf = std::max(1, int(std::floor(options.coarse_step_deg / options.fine_step_deg + 1e-9)));
  Searcher::Cell best = s.grid(coarse.a, options.fine_step_deg * kDeg, mf);
  res.angles = best.a;
  res.after = best.s;
  res.margin_deg = best.s.pass ? best.depth * options.fine_step_deg : 0;

  if (options.polish) {
    AimMargins m(scene, element, frame, zones, options, el.local_to_world, res.pivot, res.yaw_axis, res.pitch_axis);
    double x[2] = {best.a.yaw_rad / kDeg, best.a.pitch_rad / kDeg};
    m.seedAt(x);  // the seeds are fixed before Ceres starts: its objective is then a pure function of the angles
    ceres::NumericDiffOptions nd;
    nd.relative_step_size = 1e-4;  // degrees: x is O(1), the inverse's residual 1e-12 rad
    auto* cost = new ceres::NumericDiffCostFunction<SoftMinResidual, ceres::CENTRAL, ceres::DYNAMIC, 2>(
        new SoftMinResidual{&m}, ceres::TAKE_OWNERSHIP, int(m.size()), nd);
    ceres::Problem problem;
    problem.AddResidualBlock(cost, nullptr, x);
    for (int i = 0; i < 2; ++i) {
      problem.SetParameterLowerBound(x, i, x[i] - options.coarse_step_deg);
      problem.SetParameterUpperBound(x, i, x[i] + options.coarse_step_deg);
    }
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = 50;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    const AimAngles polished{x[0] * kDeg, x[1] * kDeg};
    std::string why;
    if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || summary.termination_type == ceres::FAILURE) {
      why = "not kept: the solver failed";
    } else {
      const AimScore ps = s.evaluate(polished);
      if (ps.score < best.s.score || (best.s.pass && !ps.pass)) {
        why =
            "not kept: its exact score " + fmt("%.4f", ps.score) + " is below the grid's " + fmt("%.4f", best.s.score);
      } else {
        res.angles = polished;
        res.after = ps;
        res.polished = true;
        why = "kept (exact score " + fmt("%.4f", ps.score) + ")";
      }
    }
    res.polish_report = std::string("ceres: ") + ceres::TerminationTypeToString(summary.termination_type) + ", " +
                        std::to_string(summary.iterations.size()) + " iterations; " + why;
  }
  res.evaluations = s.evaluations;
  res.local_to_world = aimedPose(el.local_to_world, res.pivot, res.yaw_axis, res.pitch_axis, res.angles);
  return res;
}

}  // namespace pvrr
