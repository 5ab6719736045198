// Virtual viewpoint fit (paper 3.2): closed form, conditioning fallback, angular refinement (own
// Gauss-Newton or Ceres), and the acceptance checks. The only translation unit with Ceres autodiff.
#include "pvrr/method/viewpoint.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include <Eigen/Dense>
#include <ceres/ceres.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>

#include "pvrr/base/error.h"
#include "pvrr/base/format.h"

namespace pvrr {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

Vector3d toEigen(const Vec3& v) { return {v.x, v.y, v.z}; }
Vec3 toGlm(const Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// Rays per lane group of the vectorised evaluation (evaluateRange).
constexpr size_t kLanes = 8;

// The rays, re-centred on the origins' centroid c, so that large world coordinates do not cost precision in
// the 3x3 algebra.
struct Data {
  Vector3d centroid{0, 0, 0};
  Vector3d mean_dir{0, 0, 1};  // normalised mean of the directions
  std::vector<Vector3d> o, d, h;  // o and h relative to centroid, d unit
  // h and d again, one array per coordinate, for the vectorised evaluation (evaluateRange), padded with
  // kLanes repeats of the first ray, read (and given weight 0) by a range's last lane group.
  std::vector<double> hx, hy, hz, dx, dy, dz;
  double patch_radius_m = 0;   // max distance of an origin from the axis (centroid, mean_dir)
  double spread_rad = 0;       // max angle between a direction and mean_dir
  size_t size() const { return d.size(); }
};

// Any unit vector perpendicular to unit n, and a third completing a right-handed frame (Duff et al. 2017).
void orthonormalBasis(const Vector3d& n, Vector3d& a, Vector3d& b) {
  const double sign = std::copysign(1.0, n.z());
  const double p = -1.0 / (sign + n.z());
  const double q = n.x() * n.y() * p;
  a = Vector3d(1.0 + sign * n.x() * n.x() * p, sign * q, -sign * n.x());
  b = Vector3d(q, sign + n.y() * n.y() * p, -n.y());
}

Data prepare(const std::vector<ViewpointRay>& rays) {
  if (rays.empty()) throw Error("fitViewpoint: no rays given; expected at least one vertex ray of the patch");
  Data D;
  const size_t n = rays.size();
  Vector3d sum_o(0, 0, 0), sum_d(0, 0, 0);
  D.o.resize(n), D.d.resize(n), D.h.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const ViewpointRay& r = rays[i];
    const double len = glm::length(r.direction);
    if (!isFinite(r.origin) || !isFinite(r.hit) || !std::isfinite(len) || !(len > 0))
      throw Error("fitViewpoint: ray " + std::to_string(i) +
                  ": expected a finite origin and hit point and a non-zero finite direction");
    D.d[i] = toEigen(r.direction) / len;
    sum_o += toEigen(r.origin);
    sum_d += D.d[i];
  }
  D.centroid = sum_o / double(n);
  const double mean_len = sum_d.norm();
  D.mean_dir = mean_len > 1e-9 * double(n) ? Vector3d(sum_d / mean_len) : D.d[0];
  // The largest angle to the mean: key = sin^2 below 90 deg, 2 - sin^2 above (monotonic in the angle and
  // precise for tiny angles, unlike 1 - cos), then one atan2.
  double radius2 = 0, key_max = -1;
  size_t widest = 0;
  for (size_t i = 0; i < n; ++i) {
    D.o[i] = toEigen(rays[i].origin) - D.centroid;
    D.h[i] = toEigen(rays[i].hit) - D.centroid;
    const double along = D.o[i].dot(D.mean_dir);
    radius2 = std::max(radius2, D.o[i].squaredNorm() - along * along);
    const double sin2 = D.d[i].cross(D.mean_dir).squaredNorm();
    const double key = D.d[i].dot(D.mean_dir) >= 0 ? sin2 : 2.0 - sin2;
    if (key > key_max) key_max = key, widest = i;
  }
  D.patch_radius_m = std::sqrt(radius2);
  const size_t padded = n + kLanes;
  for (auto* a : {&D.hx, &D.hy, &D.hz, &D.dx, &D.dy, &D.dz}) a->resize(padded);
  for (size_t i = 0; i < padded; ++i) {
    const size_t j = i < n ? i : 0;  // the padding repeats the first ray, with weight 0
    D.hx[i] = D.h[j].x(), D.hy[i] = D.h[j].y(), D.hz[i] = D.h[j].z();
    D.dx[i] = D.d[j].x(), D.dy[i] = D.d[j].y(), D.dz[i] = D.d[j].z();
  }
  D.spread_rad = std::atan2(D.d[widest].cross(D.mean_dir).norm(), D.d[widest].dot(D.mean_dir));
  return D;
}

// The weak Tikhonov prior of the fallback: r_p = k (e - e_nom), k = sqrt(prior_weight * N) / D.
struct Prior {
  bool active = false;
  Vector3d nominal{0, 0, 0};  // relative to the centroid
  double k = 0;
};

// F(e) = 1/2 sum rho(|P_d u|^2) + 1/2 |r_p|^2 (e relative to the centroid), and optionally the Newton-type
// matrix H and the exact gradient g of F:
//   r_i = P_d u,  J_i = -P_d P_u / n,  J_i^T J_i = (I - u u^T - q q^T) / n^2 with q = P_u d,
//   J_i^T r_i = -(p - s u) / n with p = P_d u, s = |p|^2 (= u . p),
//   H = sum rho'(s) J^T J + (c - rho'(s)) (J^T r)(J^T r)^T / s,  c = max(rho' + 2 rho'' s, 0):
// the curvature of rho(|r|^2)/2 along r is rho' + 2 rho'' s, negative beyond the Cauchy scale, clamped at 0
// so that H stays positive semi-definite. Plain IRLS (rho' J^T J only; also what Ceres does, its corrector
// skipping rho'' <= 0) overestimates that curvature and converges linearly: 16-24 iterations against 6-11 on
// the test's convex caps.
// Cauchy: rho(s) = b log(1 + s/b), rho' = 1/(1 + s/b), rho'' = -1/(b (1 + s/b)^2), b = scale^2; b = 0: rho(s) = s.
struct Eval {
  double F = 0;
  Matrix3d H = Matrix3d::Zero();
  Vector3d g{0, 0, 0};
};

// Partial sums of one block of rays: the data term of F, the symmetric H in 6 scalars and g.
struct Partial {
  double sum = 0, hxx = 0, hxy = 0, hxz = 0, hyy = 0, hyz = 0, hzz = 0, gx = 0, gy = 0, gz = 0;
  void add(const Partial& o) {
    sum += o.sum, hxx += o.hxx, hxy += o.hxy, hxz += o.hxz, hyy += o.hyy, hyz += o.hyz, hzz += o.hzz;
    gx += o.gx, gy += o.gy, gz += o.gz;
  }
  Matrix3d hessian() const {
    Matrix3d H;
    H << hxx, hxy, hxz, hxy, hyy, hyz, hxz, hyz, hzz;
    return H;
  }
};

// The terms of one ray in evaluateRange: the data cost, then H's six entries and g's three.
constexpr int kTerms = 10;

// x86-64 with glibc (ifunc): an AVX2 clone of evaluateRange besides the baseline one, chosen at run time.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__) && defined(__GLIBC__)
#define PVRR_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define PVRR_VECTOR_CLONES
#endif

// log(1 + x) for x in [0, 0.5): the series 2 (z + z^3/3 + ... + z^21/21), z = x / (2 + x) < 0.2, truncation
// < z^22/23 ~ 2e-17 relative; evaluateRange takes std::log1p from x = 0.5 on. std::log1p for every ray was a
// third of the solver's time (perf): with the robust scale at a multiple of the median residual, about half
// the residuals have x above 0.1, so the series reaches to 0.5.
inline double log1pSeries(double x) {
  const double z = x / (2.0 + x), z2 = z * z;
  double series = 1.0 / 21;
  for (int k = 19; k >= 1; k -= 2) series = 1.0 / k + z2 * series;
  return 2.0 * z * series;
}

// The partial sums of rays [begin, end), kLanes at a time: each lane's terms computed branch-free and summed
// into its own accumulator, the lanes added in a fixed order at the end; where the Cauchy argument x reaches
// 0.5, std::log1p in place of the series, lane by lane. The AVX2 clone vectorises the lane loop (the baseline
// SSE2 one only the sums); both do the same IEEE operations in the same order (no FMA: viewpoint.cpp is built
// with -ffp-contract=off), so their results are bit-identical.
PVRR_VECTOR_CLONES
Partial evaluateRange(const Data& D, const Vector3d& e, double b, bool derivatives, size_t begin, size_t end) {
  const double inv_b = b > 0 ? 1.0 / b : 0.0, ex = e.x(), ey = e.y(), ez = e.z();
  const double* hx = D.hx.data(), *hy = D.hy.data(), *hz = D.hz.data();
  const double* dx = D.dx.data(), *dy = D.dy.data(), *dz = D.dz.data();
  double acc[kTerms][kLanes] = {};
  for (size_t base = begin; base < end; base += kLanes) {  // lanes past `end` get weight 0
    double t[kTerms][kLanes], xs[kLanes];
    for (size_t l = 0; l < kLanes; ++l) {
      const size_t i = base + l;
      const double vx = hx[i] - ex, vy = hy[i] - ey, vz = hz[i] - ez;
      const double n2 = vx * vx + vy * vy + vz * vz;
      // A hit point exactly at the eye has no direction, and lanes past `end` have weight 0: inv_n = 0 zeroes
      // every term (for a finite eye and scale).
      const double inv_n = (n2 > 0 && i < end ? 1.0 : 0.0) / std::sqrt(n2 > 0 ? n2 : 1.0);
      const double ux = vx * inv_n, uy = vy * inv_n, uz = vz * inv_n;
      const double du = ux * dx[i] + uy * dy[i] + uz * dz[i];
      const double px = ux - du * dx[i], py = uy - du * dy[i], pz = uz - du * dz[i];
      const double s = px * px + py * py + pz * pz;
      const double x = s * inv_b;
      xs[l] = x;
      t[0][l] = b > 0 ? b * log1pSeries(std::min(x, 0.5)) : s;
      const double w = 1.0 / (1.0 + x);  // rho'
      const double qx = dx[i] - du * ux, qy = dy[i] - du * uy, qz = dz[i] - du * uz;
      const double jx = -(px - s * ux) * inv_n, jy = -(py - s * uy) * inv_n, jz = -(pz - s * uz) * inv_n;  // J^T r
      const double c = w * inv_n * inv_n;
      // coefficient of (J^T r)(J^T r)^T
      const double k = (b > 0 && s > 0 ? 1.0 : 0.0) * ((std::max(w - 2.0 * x * w * w, 0.0) - w) / (s > 0 ? s : 1.0));
      t[1][l] = c * (1 - ux * ux - qx * qx) + k * jx * jx;
      t[2][l] = c * (-ux * uy - qx * qy) + k * jx * jy;
      t[3][l] = c * (-ux * uz - qx * qz) + k * jx * jz;
      t[4][l] = c * (1 - uy * uy - qy * qy) + k * jy * jy;
      t[5][l] = c * (-uy * uz - qy * qz) + k * jy * jz;
      t[6][l] = c * (1 - uz * uz - qz * qz) + k * jz * jz;
      t[7][l] = w * jx, t[8][l] = w * jy, t[9][l] = w * jz;
    }
    if (b > 0)
      for (size_t l = 0; l < kLanes; ++l)
        if (!(xs[l] < 0.5)) t[0][l] = b * std::log1p(xs[l]);
    const int terms = derivatives ? kTerms : 1;
    for (int j = 0; j < terms; ++j)
      for (size_t l = 0; l < kLanes; ++l) acc[j][l] += t[j][l];
  }
  double sum[kTerms] = {};
  for (int j = 0; j < kTerms; ++j)
    for (size_t l = 0; l < kLanes; ++l) sum[j] += acc[j][l];
  Partial P;
  P.sum = sum[0];
  P.hxx = sum[1], P.hxy = sum[2], P.hxz = sum[3], P.hyy = sum[4], P.hyz = sum[5], P.hzz = sum[6];
  P.gx = sum[7], P.gy = sum[8], P.gz = sum[9];
  return P;
}

// Rays per block of the parallel evaluation. Blocks are fixed and summed in a fixed tree
// (parallel_deterministic_reduce with a simple partitioner), so F, H and g, and hence the fitted eye, are
// bit-identical whatever the number of threads. Below two blocks the loop runs serially.
constexpr size_t kEvalBlock = 512;

// range(begin, end) -> T over [0, n) in kEvalBlock blocks, summed with T::add in the fixed tree.
template <class T, class RangeFn>
T reduceBlocks(size_t n, const RangeFn& range) {
  if (n < 2 * kEvalBlock) return range(size_t(0), n);
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<size_t>(0, n, kEvalBlock), T{},
      [&](const tbb::blocked_range<size_t>& r, T acc) {
        acc.add(range(r.begin(), r.end()));
        return acc;
      },
      [](T a, const T& c) {
        a.add(c);
        return a;
      },
      tbb::simple_partitioner());
}

Eval evaluate(const Data& D, const Vector3d& e, double b, const Prior& prior, bool derivatives) {
  const Partial P = reduceBlocks<Partial>(
      D.size(), [&](size_t begin, size_t end) { return evaluateRange(D, e, b, derivatives, begin, end); });
  Eval E;
  E.F = 0.5 * P.sum;
  if (prior.active) E.F += 0.5 * prior.k * prior.k * (e - prior.nominal).squaredNorm();
  if (derivatives) {
    E.H = P.hessian();
    E.g = Vector3d(P.gx, P.gy, P.gz);
    if (prior.active) {
      E.H.diagonal().array() += prior.k * prior.k;
      E.g += prior.k * prior.k * (e - prior.nominal);
    }
  }
  return E;
}

// The fit's metrics at the final eye over one block of rays, and the data-only Gauss-Newton partial sums.
struct Metrics {
  Partial gn;
  double sum_dist2 = 0, sum_ang2 = 0, max_ang = 0;
  int behind = 0;
  void add(const Metrics& o) {
    gn.add(o.gn);
    sum_dist2 += o.sum_dist2, sum_ang2 += o.sum_ang2, max_ang = std::max(max_ang, o.max_ang), behind += o.behind;
  }
};

Metrics metricsRange(const Data& D, const Vector3d& e, size_t begin, size_t end) {
  Metrics m;
  m.gn = evaluateRange(D, e, 0.0, true, begin, end);
  for (size_t i = begin; i < end; ++i) {
    const Vector3d w = e - D.o[i];
    m.sum_dist2 += (w - w.dot(D.d[i]) * D.d[i]).squaredNorm();
    const Vector3d v = D.h[i] - e;
    const double len = v.norm();
    if (v.dot(D.d[i]) < 0) ++m.behind;
    if (!(len > 0)) continue;
    const double du = v.dot(D.d[i]) / len;
    const double sin_a = (v / len - du * D.d[i]).norm();
    // theta = atan2(sin, |cos|); below 1e-3 rad the series theta = sin (1 + sin^2/6) is exact to 1e-13
    // relative and spares the atan2 (a third of this loop's time).
    const double ang = sin_a < 1e-3 && du > 0 ? sin_a * (1.0 + sin_a * sin_a / 6.0)
                                              : std::atan2(sin_a, std::abs(du));
    m.sum_ang2 += ang * ang;
    m.max_ang = std::max(m.max_ang, ang);
  }
  return m;
}

double objective(const Data& D, const Vector3d& e, double b, const Prior& prior) {
  return evaluate(D, e, b, prior, false).F;
}

double conditionOf(const Matrix3d& M) {
  Eigen::SelfAdjointEigenSolver<Matrix3d> es(M, Eigen::EigenvaluesOnly);
  const double lo = es.eigenvalues()(0), hi = es.eigenvalues()(2);
  return lo > 0 ? hi / lo : kInf;
}

struct Refined {
  Vector3d e{0, 0, 0};
  double F = 0;  // our own evaluation of F at e
  bool converged = false;
  int iterations = 0;
  std::string report;
};

// Levenberg-damped Newton-type iteration on the 3x3 system of evaluate(). Monotone: a step is taken only
// when F does not increase. One pass over the rays per trial step (F, H and g together).
// `start`: evaluate(D, e0, b, prior, true), which the caller has (its F is the start cost).
Refined gaussNewton(const Data& D, const Vector3d& e0, const Eval& start, double b, const Prior& prior,
                    const ViewpointOptions& opt, double length_scale_m) {
  Refined R;
  R.e = e0;
  Eval cur = start;
  const double F0 = cur.F;
  double mu = 1e-8;  // damping relative to trace(H)/3
  std::string why = "max_iterations";
  bool done = false;
  int it = 0;
  for (; it < opt.max_iterations && !done; ++it) {
    const double scale = cur.H.trace() / 3.0;
    if (!(scale > 0) || !std::isfinite(scale)) {
      why = "zero normal matrix";
      break;
    }
    bool accepted = false;
    for (int tries = 0; tries < 30; ++tries) {
      Matrix3d Hd = cur.H;
      Hd.diagonal().array() += mu * scale;
      const Vector3d delta = -Hd.ldlt().solve(cur.g);
      if (!delta.allFinite()) {
        mu *= 10;
        continue;
      }
      const bool tiny = delta.norm() <= opt.step_tolerance * length_scale_m;
      // The quadratic model's predicted decrease already below the tolerance: converged, without spending
      // a pass over the rays on the step.
      const double predicted = -(cur.g.dot(delta) + 0.5 * delta.dot(cur.H * delta));
      if (tries == 0 && predicted >= 0 && predicted <= 0.1 * opt.function_tolerance * cur.F) {
        why = "predicted decrease";
        done = accepted = true;
        break;
      }
      Eval next = evaluate(D, R.e + delta, b, prior, true);
      if (std::isfinite(next.F) && next.F <= cur.F) {
        const double dF = cur.F - next.F;
        R.e += delta;
        cur = next;
        mu = std::max(mu / 3.0, 1e-12);
        accepted = true;
        if (tiny) {
          why = "step_tolerance";
          done = true;
        } else if (dF <= opt.function_tolerance * cur.F) {
          why = "function_tolerance";
          done = true;
        }
        break;
      }
      // A step that does not decrease F and is already tiny: at the minimum to working precision.
      if (tiny) {
        why = "step_tolerance";
        done = accepted = true;
        break;
      }
      mu *= 10;
    }
    if (!accepted) {
      why = "no decreasing step";
      break;
    }
  }
  R.F = cur.F;
  R.iterations = it;
  R.converged = done && R.e.allFinite();
  std::ostringstream os;
  os << "gauss-newton: " << (R.converged ? "CONVERGENCE" : (R.e.allFinite() ? "NO_CONVERGENCE" : "FAILURE"))
     << " (" << why << "), " << it << " iterations, cost " << fmt("%.6g", F0) << " -> " << fmt("%.6g", R.F);
  R.report = os.str();
  return R;
}

// Ceres residuals. AngularResidual: r = ((a . v)/|v|, (b . v)/|v|), v = h - e (the 2-vector form of P_d u).
struct AngularResidual {
  Vector3d h, a, b;
  template <class T>
  bool operator()(const T* e, T* r) const {
    const T v[3] = {T(h.x()) - e[0], T(h.y()) - e[1], T(h.z()) - e[2]};
    const T n = ceres::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    r[0] = (T(a.x()) * v[0] + T(a.y()) * v[1] + T(a.z()) * v[2]) / n;
    r[1] = (T(b.x()) * v[0] + T(b.y()) * v[1] + T(b.z()) * v[2]) / n;
    return true;
  }
};
struct PriorResidual {
  Vector3d nominal;
  double k;
  template <class T>
  bool operator()(const T* e, T* r) const {
    for (int j = 0; j < 3; ++j) r[j] = T(k) * (e[j] - T(nominal[j]));
    return true;
  }
};

Refined ceresSolve(const Data& D, const Vector3d& e0, double b, const Prior& prior, const ViewpointOptions& opt) {
  Refined R;
  double e[3] = {e0.x(), e0.y(), e0.z()};
  ceres::Problem::Options popt;
  popt.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(popt);
  std::unique_ptr<ceres::LossFunction> loss;
  if (b > 0) loss = std::make_unique<ceres::CauchyLoss>(std::sqrt(b));
  for (size_t i = 0; i < D.size(); ++i) {
    if (!((D.h[i] - e0).norm() > 0)) continue;
    Vector3d a, b;
    orthonormalBasis(D.d[i], a, b);
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<AngularResidual, 2, 3>(new AngularResidual{D.h[i], a, b}), loss.get(), e);
  }
  if (prior.active)
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PriorResidual, 3, 3>(new PriorResidual{prior.nominal, prior.k}), nullptr,
        e);
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = opt.max_iterations;
  so.function_tolerance = opt.function_tolerance;
  so.parameter_tolerance = opt.step_tolerance;
  so.gradient_tolerance = 1e-16;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  R.e = Vector3d(e[0], e[1], e[2]);
  R.F = objective(D, R.e, b, prior);  // ours, not Ceres' report
  R.converged = summary.termination_type == ceres::CONVERGENCE && R.e.allFinite();
  R.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  R.report = std::string("ceres: ") + ceres::TerminationTypeToString(summary.termination_type) + ", " +
             summary.BriefReport();
  return R;
}

}  // namespace

double viewpointAngularCost(const std::vector<ViewpointRay>& rays, const Vec3& eye, double robust_scale_rad) {
  const Data D = prepare(rays);
  const double b = robust_scale_rad > 0 ? robust_scale_rad * robust_scale_rad : 0.0;
  return objective(D, toEigen(eye) - D.centroid, b, Prior{});
}

ViewpointCostDerivatives viewpointAngularCostDerivatives(const std::vector<ViewpointRay>& rays, const Vec3& eye,
                                                         double robust_scale_rad) {
  const Data D = prepare(rays);
  const double b = robust_scale_rad > 0 ? robust_scale_rad * robust_scale_rad : 0.0;
  const Eval E = evaluate(D, toEigen(eye) - D.centroid, b, Prior{}, true);
  ViewpointCostDerivatives out;
  out.cost = E.F;
  out.gradient = toGlm(E.g);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.normal_matrix[c][r] = E.H(r, c);
  return out;
}

static void validateOptions(const ViewpointOptions& opt) {
  auto bad = [](const std::string& what) { throw Error("fitViewpoint: ViewpointOptions." + what); };
  if (!std::isfinite(opt.robust_scale_rad)) bad("robust_scale_rad: expected a finite number (<= 0: no loss)");
  if (!(opt.robust_median_factor >= 0)) bad("robust_median_factor: expected a number >= 0");
  if (!(opt.prior_weight >= 0) || !std::isfinite(opt.prior_weight)) bad("prior_weight: expected a finite number >= 0");
  if (!(opt.max_condition_number > 1)) bad("max_condition_number: expected a number > 1");
  if (!(opt.max_eye_distance_m > 0)) bad("max_eye_distance_m: expected a distance > 0 m");
  if (!(opt.min_fallback_distance_m > 0) || !(opt.max_fallback_distance_m >= opt.min_fallback_distance_m) ||
      !std::isfinite(opt.max_fallback_distance_m))
    bad("min/max_fallback_distance_m: expected 0 < min <= max < inf");
  if (opt.max_iterations < 1) bad("max_iterations: expected >= 1");
  if (!(opt.function_tolerance >= 0) || !(opt.step_tolerance >= 0)) bad("*_tolerance: expected >= 0");
}

ViewpointFit fitViewpoint(const std::vector<ViewpointRay>& rays, const ViewpointOptions& opt) {
  validateOptions(opt);
  const Data D = prepare(rays);
  const size_t n = D.size();
  ViewpointFit fit;

  // 1. Closed form (relative to the centroid): A x = y, A = sum P_d, y = sum P_d o.
  // Summed as A = N I - sum d d^T and y = sum o - sum d (d . o): no 3x3 matrix per ray.
  Matrix3d ddt = Matrix3d::Zero();
  Vector3d sum_o(0, 0, 0), sum_dd_o(0, 0, 0);
  for (size_t i = 0; i < n; ++i) {
    ddt.noalias() += D.d[i] * D.d[i].transpose();
    sum_o += D.o[i];
    sum_dd_o += D.d[i] * D.d[i].dot(D.o[i]);
  }
  const Matrix3d A = double(n) * Matrix3d::Identity() - ddt;
  const Vector3d y = sum_o - sum_dd_o;
  Eigen::SelfAdjointEigenSolver<Matrix3d> es(A);
  const Vector3d lambda = es.eigenvalues();  // ascending
  const Matrix3d V = es.eigenvectors();
  fit.condition_number = lambda(0) > 0 ? lambda(2) / lambda(0) : kInf;
  const double lambda_cut = lambda(2) / opt.max_condition_number;

  Vector3d x(0, 0, 0);
  int ill_directions = 0;
  for (int k = 0; k < 3; ++k) {
    if (lambda(k) > 0 && lambda(k) >= lambda_cut)
      x += V.col(k) * (V.col(k).dot(y) / lambda(k));
    else
      ++ill_directions;
  }

  // 3. Conditioning fallback.
  const bool ill = ill_directions > 0;
  const bool far = !ill && !(x.norm() <= opt.max_eye_distance_m);
  Prior prior;
  if (ill || far) {
    const double tan_spread = std::tan(std::min(D.spread_rad, 0.5 * kPi - 1e-9));
    double dist = D.patch_radius_m / tan_spread;
    if (!std::isfinite(dist)) dist = opt.max_fallback_distance_m;  // parallel rays (0/0 or r/0)
    dist = std::clamp(dist, opt.min_fallback_distance_m, opt.max_fallback_distance_m);
    const Vector3d nominal = -dist * D.mean_dir;
    std::ostringstream os;
    if (ill) {
      for (int k = 0; k < 3; ++k)
        if (!(lambda(k) > 0 && lambda(k) >= lambda_cut)) x += V.col(k) * V.col(k).dot(nominal);
      os << "nearly parallel rays (cond " << fmt("%.2g", fit.condition_number) << " > "
         << fmt("%.2g", opt.max_condition_number) << "): " << ill_directions
         << " ill-conditioned direction(s) of the closed form kept at the nominal point";
    } else {
      os << "closed-form viewpoint " << fmt("%.3g", x.norm()) << " m from the patch centroid (> "
         << fmt("%.3g", opt.max_eye_distance_m) << " m): its component along the mean ray direction replaced "
         << "by the nominal point's";
      x = x - x.dot(D.mean_dir) * D.mean_dir + nominal.dot(D.mean_dir) * D.mean_dir;
    }
    os << " (on the mean ray direction through the patch centroid, " << fmt("%.4g", dist)
       << " m behind it: patch radius "
       << fmt("%.3g", D.patch_radius_m) << " m / tan(spread " << fmt("%.3g", degrees(D.spread_rad))
       << " deg), clamped to [" << fmt("%.3g", opt.min_fallback_distance_m) << ", "
       << fmt("%.3g", opt.max_fallback_distance_m) << "] m)";
    if (opt.solver != ViewpointSolver::kClosedForm && opt.prior_weight > 0) {
      prior.active = true;
      prior.nominal = nominal;
      prior.k = std::sqrt(opt.prior_weight * double(n)) / dist;
      os << "; weak prior (weight " << fmt("%.3g", opt.prior_weight) << " of the data) in the refinement";
    }
    fit.fallback = os.str();
    fit.fallback_distance_m = dist;
  }
  const Vector3d e0 = x;
  fit.closed_form_eye = toGlm(e0 + D.centroid);

  // Robust scale: the option, raised to robust_median_factor x the median line angle at the start, so that
  // the ordinary aberration of a curved patch stays in the loss's quadratic range (a Cauchy loss whose
  // scale is below the typical residual converges slowly: tens of iterations) while gross errors are still
  // down-weighted.
  double b = 0;
  if (opt.robust_scale_rad > 0) {
    std::vector<double> sines(n);
    for (size_t i = 0; i < n; ++i) {
      const Vector3d v = D.h[i] - e0;
      const double len = v.norm();
      sines[i] = len > 0 ? (v / len - (v / len).dot(D.d[i]) * D.d[i]).norm() : 0.0;
    }
    std::nth_element(sines.begin(), sines.begin() + std::ptrdiff_t(n / 2), sines.end());
    const double scale = std::max(opt.robust_scale_rad, opt.robust_median_factor * sines[n / 2]);
    b = scale * scale;
  }
  fit.robust_scale_rad = std::sqrt(b);
  // The start: F0, and for Gauss-Newton its derivatives too (one pass over the rays for both).
  const bool newton = opt.solver != ViewpointSolver::kClosedForm && opt.solver != ViewpointSolver::kCeres;
  const Eval start = evaluate(D, e0, b, prior, newton);
  const double F0 = start.F;
  fit.cost_initial = F0;

  // 2./4. Refinement and acceptance. A refinement is usable when finite, converged and not worse than e0.
  const double length_scale = e0.norm() + D.patch_radius_m + 1e-300;
  auto usable = [&](const Refined& R) {
    const double slack = 1e-12 * F0 + 1e-30;  // rounding of F at the same point; F is in rad^2
    return R.converged && R.e.allFinite() && std::isfinite(R.F) && R.F <= F0 + slack;
  };
  Vector3d e = e0;
  double F_final = F0;
  std::string report;
  bool accepted = false;
  int iterations = 0;
  if (opt.solver == ViewpointSolver::kClosedForm) {
    report = "closed form only";
    accepted = e0.allFinite();
  } else {
    std::vector<Refined> tried;
    bool found = false;
    if (opt.solver != ViewpointSolver::kCeres) {
      tried.push_back(gaussNewton(D, e0, start, b, prior, opt, length_scale));
      found = usable(tried.back());
    }
    if (!found && opt.solver != ViewpointSolver::kGaussNewton) {
      tried.push_back(ceresSolve(D, e0, b, prior, opt));
      found = usable(tried.back());
    }
    for (size_t t = 0; t < tried.size(); ++t) report += (t ? "; " : "") + tried[t].report;
    if (found) {
      e = tried.back().e;
      F_final = tried.back().F;
      iterations = tried.back().iterations;
      accepted = true;
    } else {
      // Keep the best finite result that did not make F worse, else the closed form.
      double best = F0;
      for (const Refined& R : tried)
        if (R.e.allFinite() && std::isfinite(R.F) && R.F < best)
          best = R.F, e = R.e, F_final = R.F, iterations = R.iterations;
      std::string what = e == e0 ? "kept the closed-form start: the refinement did not converge or made the "
                                   "angular cost worse"
                                 : "refinement did not report convergence; kept its best point (cost " +
                                       fmt("%.6g", best) + " < start " + fmt("%.6g", F0) + ")";
      fit.fallback += (fit.fallback.empty() ? "" : "; ") + what;
    }
  }
  if (!e.allFinite()) {  // cannot happen with a finite e0; guarded because the eye must never be NaN
    e = Vector3d(0, 0, 0);
    F_final = objective(D, e, b, prior);
    accepted = false;
    fit.fallback += (fit.fallback.empty() ? "" : "; ") + std::string("non-finite eye replaced by the centroid");
  }

  // Metrics at the final eye.
  fit.eye = toGlm(e + D.centroid);
  fit.cost_final = F_final;
  fit.iterations = iterations;
  fit.solver_report = report + (b > 0 ? "; Cauchy scale " + fmt("%.3g", arcminutes(std::sqrt(b))) + " arcmin"
                                       : std::string("; no robust loss"));
  fit.accepted = accepted;
  // With the data-only Gauss-Newton matrix (no robust weights, no prior: b = 0) in the same blocks.
  const Metrics M = reduceBlocks<Metrics>(n, [&](size_t begin, size_t end) { return metricsRange(D, e, begin, end); });
  fit.hits_behind_eye = M.behind;
  fit.rms_line_distance_m = std::sqrt(M.sum_dist2 / double(n));
  fit.rms_angle_rad = std::sqrt(M.sum_ang2 / double(n));
  fit.max_angle_rad = M.max_ang;
  fit.condition_number_solution = conditionOf(M.gn.hessian());
  return fit;
}

ViewpointSolver parseViewpointSolver(const std::string& name) {
  for (ViewpointSolver s :
       {ViewpointSolver::kAuto, ViewpointSolver::kGaussNewton, ViewpointSolver::kCeres, ViewpointSolver::kClosedForm})
    if (name == toString(s)) return s;
  throw Error("viewpoint solver: expected auto, gauss-newton, ceres or closed-form, got \"" + name + "\"");
}

const char* toString(ViewpointSolver s) {
  switch (s) {
    case ViewpointSolver::kAuto:
      return "auto";
    case ViewpointSolver::kGaussNewton:
      return "gauss-newton";
    case ViewpointSolver::kCeres:
      return "ceres";
    case ViewpointSolver::kClosedForm:
      return "closed-form";
  }
  return "?";
}

}  // namespace pvrr
