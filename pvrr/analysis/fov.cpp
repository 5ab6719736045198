#include "pvrr/analysis/fov.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "pvrr/base/error.h"
#include "pvrr/optics/optics.h"

namespace pvrr {

namespace {

// A sight line's end counts as the sampled mirror point when the exact hit lies this close to it: the exact
// hit is refined to double rounding (pvrr/trace/ray_scene.h), far below this; a different point of the same
// mirror (the mirror hiding itself at grazing incidence) lies much further away.
constexpr double kSamePoint_m = 1e-6;
// At most this many non-obstructing objects (a following car, a building, the road's own ground quads) are
// passed through on one ray before it reaches the road.
constexpr int kMaxPassThrough = 64;
// The footprint's outline is refined between boundary samples whose road points lie further apart than this (m),
// or this share of their distance from the origin, halving the mirror's edge at most kOutlineDepth times.
constexpr double kOutlineStep_m = 1.0, kOutlineRelStep = 0.05;
constexpr int kOutlineDepth = 10;

// Whether o + t d meets an obstruction (an element or a mesh of `obstructs`) first for t in (t_min, t_max).
bool obstructed(const RayScene& rays, const std::vector<bool>& obstructs, const Vec3& o, const Vec3& d, double t_min,
                double t_max) {
  for (int i = 0; i < kMaxPassThrough && t_min < t_max; ++i) {
    const RayHit h = rays.intersect(o, d, t_min, t_max);
    if (!h.hit()) return false;
    if (h.kind == HitKind::Element || obstructs[size_t(h.mesh)]) return true;
    t_min = h.t + rays.epsilon();
  }
  return false;
}

double signedArea(const std::vector<Vec2>& p) {
  double a = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec2 &u = p[i], &v = p[(i + 1) % p.size()];
    a += u.x * v.y - v.x * u.y;
  }
  return 0.5 * a;
}

double cross2(Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; }

bool inTriangle(Vec2 p, Vec2 a, Vec2 b, Vec2 c) {
  const double d1 = cross2(b - a, p - a), d2 = cross2(c - b, p - b), d3 = cross2(a - c, p - c);
  const bool neg = d1 < 0 || d2 < 0 || d3<0, pos = d1> 0 || d2 > 0 || d3 > 0;
  return !(neg && pos);
}

// The parameters of sample (i, j) of an n x n grid over the mirror's parameter square.
Vec2 sampleParameters(const Element& el, int i, int j, int n) {
  return mirrorParameters(el, Vec2(-1 + 2.0 * i / (n - 1), -1 + 2.0 * j / (n - 1)));
}

}  // namespace

Vec2 mirrorParameters(const Element& el, Vec2 s) {
  if (el.has_outline) return el.outline.fromSquare(s);
  const cad::ParamDomain dom = el.frontSurface().domain();
  return Vec2(dom.u0 + (dom.u1 - dom.u0) * 0.5 * (s.x + 1), dom.v0 + (dom.v1 - dom.v0) * 0.5 * (s.y + 1));
}

VehicleFrame::VehicleFrame(const VehicleDesc& v) : v_(v) {
  z_ = glm::normalize(v.up);
  x_ = glm::normalize(v.forward - glm::dot(v.forward, z_) * z_);
  y_ = glm::cross(z_, x_);
  const Vec3 mid = 0.5 * (v.eye_left + v.eye_right);
  origin_ = mid - (glm::dot(mid, z_) - v.road_height_m) * z_;
}

Vec3 VehicleFrame::toVehicle(const Vec3& w) const { return toVehicleDir(w - origin_); }
Vec3 VehicleFrame::toVehicleDir(const Vec3& w) const { return Vec3(glm::dot(w, x_), glm::dot(w, y_), glm::dot(w, z_)); }
Vec3 VehicleFrame::toWorld(const Vec3& p) const { return origin_ + p.x * x_ + p.y * y_ + p.z * z_; }

int EyeFootprint::count(RayFate f) const { return int(std::count(fate.begin(), fate.end(), f)); }

EyeFootprint traceFootprint(const RayScene& rays, int element, const VehicleFrame& frame, const Vec3& eye_world,
                            const std::string& eye_name, const FovOptions& options) {
  const Scene& scene = rays.scene();
  PVRR_CHECK(element >= 0 && size_t(element) < scene.elements.size());
  PVRR_CHECK(options.samples >= 2);
  const Element& el = scene.elements[size_t(element)];
  const cad::Surface& surface = el.frontSurface();
  std::vector<bool> obstructs(scene.meshes.size(), false);
  for (size_t i = 0; i < scene.meshes.size(); ++i)
    obstructs[i] = std::find(frame.desc().obstructions.begin(), frame.desc().obstructions.end(),
                             scene.meshes[i].name) != frame.desc().obstructions.end();

  EyeFootprint f;
  f.eye = eye_name;
  f.eye_vehicle = frame.toVehicle(eye_world);
  const int n = f.n = options.samples;
  f.road.assign(size_t(n) * size_t(n), Vec2(0));
  f.fate.assign(f.road.size(), RayFate::Back);
  f.mirror_point.assign(f.road.size(), Vec3(0));
  // One ray through square point s: its mirror point, road point and fate (CONVENTIONS); the obstruction tests
  // only when `obstruction` (the outline's extra points need the road point alone).
  struct Ray {
    Vec3 p{0};
    Vec2 road{0};
    RayFate fate = RayFate::Back;
  };
  auto trace = [&](Vec2 s, bool obstruction) {
    Ray out;
    const Vec2 uv = mirrorParameters(el, s);
    const cad::SurfacePoint sp = surface.sample(uv.x, uv.y, false);
    Vec3 p = el.toWorldPoint(sp.p), nrm = glm::normalize(el.toWorldDir(sp.n));
    out.p = p;
    const double dist = glm::length(p - eye_world);
    const Vec3 d = (p - eye_world) / dist;
    if (glm::dot(d, nrm) >= 0) return out;  // the mirror's back faces the eye here
    // The sight line: the exact hit where it meets the sampled point (the tracer's point and normal; a
    // sample on the outline itself may be missed by rounding, and keeps the surface's own point and normal).
    const RayHit h = rays.intersect(eye_world, d, 0, dist + 1e3 * kSamePoint_m);
    if (h.kind == HitKind::Element && h.element == element && glm::length(h.point - p) < kSamePoint_m) {
      p = h.point;
      nrm = h.normal;
    }
    bool blocked = obstruction && obstructed(rays, obstructs, eye_world, d, 0, dist - kSamePoint_m);
    const Vec3 r = reflect(d, nrm);
    const Vec3 pv = frame.toVehicle(p), rv = frame.toVehicleDir(r);
    const double hr = std::hypot(rv.x, rv.y);
    const Vec2 dir_h = hr > 0 ? Vec2(rv.x, rv.y) / hr : Vec2(0);
    double t_end;
    if (rv.z < 0 && -pv.z / rv.z * hr <= options.horizon_m) {
      t_end = -pv.z / rv.z;
      out.road = Vec2(pv.x, pv.y) + t_end * Vec2(rv.x, rv.y);
      out.fate = RayFate::Road;
    } else {
      t_end = hr > 0 ? options.horizon_m / hr : options.horizon_m;
      out.road = Vec2(pv.x, pv.y) + options.horizon_m * dir_h;
      out.fate = RayFate::Horizon;
    }
    if (obstruction && !blocked) blocked = obstructed(rays, obstructs, p, r, rays.epsilon(), t_end);
    if (blocked) out.fate = RayFate::Obstructed;
    return out;
  };
  auto square = [n](int i, int j) { return Vec2(-1 + 2.0 * i / (n - 1), -1 + 2.0 * j / (n - 1)); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const size_t k = size_t(j) * size_t(n) + size_t(i);
      const Ray r = trace(square(i, j), true);
      f.mirror_point[k] = r.p;
      f.road[k] = r.road;
      f.fate[k] = r.fate;
      if (r.fate == RayFate::Road) f.reach_m = std::max(f.reach_m, -r.road.x);
      if (r.fate == RayFate::Horizon) f.sees_horizon = true;
    }
  // The boundary of the parameter square, once round; between two boundary samples whose road points lie far apart
  // (where the mirror's edge runs out towards the horizon: a chord there would cut across the horizon's arc and the
  // outline would cross itself), points of the edge between them, halving until they lie close.
  std::vector<std::pair<int, int>> ring;
  for (int i = 0; i < n - 1; ++i) ring.push_back({i, 0});
  for (int j = 0; j < n - 1; ++j) ring.push_back({n - 1, j});
  for (int i = n - 1; i > 0; --i) ring.push_back({i, n - 1});
  for (int j = n - 1; j > 0; --j) ring.push_back({0, j});
  auto far = [](Vec2 a, Vec2 b) {
    return glm::length(a - b) > std::max(kOutlineStep_m, kOutlineRelStep * std::max(glm::length(a), glm::length(b)));
  };
  std::function<void(Vec2, Ray, Vec2, Ray, int)> refine = [&](Vec2 sa, Ray a, Vec2 sb, Ray b, int depth) {
    if (depth >= kOutlineDepth || a.fate == RayFate::Back || b.fate == RayFate::Back || !far(a.road, b.road)) return;
    const Vec2 sm = 0.5 * (sa + sb);
    const Ray m = trace(sm, false);
    refine(sa, a, sm, m, depth + 1);
    if (m.fate != RayFate::Back) f.outline.push_back(m.road);
    refine(sm, m, sb, b, depth + 1);
  };
  for (size_t q = 0; q < ring.size(); ++q) {
    const auto [i0, j0] = ring[q];
    const auto [i1, j1] = ring[(q + 1) % ring.size()];
    const size_t k0 = size_t(j0) * size_t(n) + size_t(i0), k1 = size_t(j1) * size_t(n) + size_t(i1);
    f.outline.push_back(f.road[k0]);
    const Ray a{f.mirror_point[k0], f.road[k0], f.fate[k0] == RayFate::Back ? RayFate::Back : RayFate::Road};
    const Ray b{f.mirror_point[k1], f.road[k1], f.fate[k1] == RayFate::Back ? RayFate::Back : RayFate::Road};
    refine(square(i0, j0), a, square(i1, j1), b, 0);
  }
  if (signedArea(f.outline) < 0) std::reverse(f.outline.begin(), f.outline.end());
  f.outline_cut_area_m2 = makeSimple(f.outline);
  return f;
}

int firstSelfCrossing(const std::vector<Vec2>& p, size_t& i_out, size_t& j_out, Vec2& x_out) {
  const size_t n = p.size();
  if (n < 4) return 0;
  // Bounding boxes of the edges, so that most pairs are rejected at once.
  std::vector<Vec2> lo(n), hi(n);
  for (size_t i = 0; i < n; ++i) {
    lo[i] = glm::min(p[i], p[(i + 1) % n]);
    hi[i] = glm::max(p[i], p[(i + 1) % n]);
  }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours across the closing edge
      if (hi[i].x < lo[j].x || hi[j].x < lo[i].x || hi[i].y < lo[j].y || hi[j].y < lo[i].y) continue;
      const Vec2 a = p[i], d = p[(i + 1) % n] - a, b = p[j], e = p[(j + 1) % n] - b;
      const double den = cross2(d, e);
      if (den == 0) continue;
      const double t = cross2(b - a, e) / den, u = cross2(b - a, d) / den;
      if (t >= 0 && t <= 1 && u >= 0 && u <= 1) {
        i_out = i;
        j_out = j;
        x_out = a + t * d;
        return 1;
      }
    }
  return 0;
}

double makeSimple(std::vector<Vec2>& p) {
  double cut = 0;
  size_t i = 0, j = 0;
  Vec2 x(0);
  // Each cut removes at least one vertex, so this ends.
  while (firstSelfCrossing(p, i, j, x)) {
    // The loop from the crossing through p[i + 1] .. p[j] back to the crossing, and the rest.
    std::vector<Vec2> inner{x}, outer(p.begin(), p.begin() + std::ptrdiff_t(i) + 1);
    inner.insert(inner.end(), p.begin() + std::ptrdiff_t(i) + 1, p.begin() + std::ptrdiff_t(j) + 1);
    outer.push_back(x);
    outer.insert(outer.end(), p.begin() + std::ptrdiff_t(j) + 1, p.end());
    const double ai = std::abs(signedArea(inner)), ao = std::abs(signedArea(outer));
    cut += std::min(ai, ao);
    p = ai > ao ? inner : outer;
    // Drop a repeated point (the crossing at a shared vertex).
    std::vector<Vec2> q;
    for (const Vec2& v : p)
      if (q.empty() || v != q.back()) q.push_back(v);
    while (q.size() > 1 && q.front() == q.back()) q.pop_back();
    p = q;
  }
  if (signedArea(p) < 0) std::reverse(p.begin(), p.end());
  return cut;
}

std::vector<Vec2> zoneInVehicle(const FovZone& z, const VehicleFrame& frame, double zone_horizon_m) {
  const bool left = (frame.desc().driver_side == VehicleDesc::Side::Left) == z.driver_side;
  const double y0 = frame.outermost(left).y, sign = left ? 1 : -1;
  std::vector<Vec2> out;
  for (const Vec2& p : z.polygon) out.push_back(Vec2(std::isfinite(p.x) ? p.x : -zone_horizon_m, y0 + sign * p.y));
  return out;
}

std::vector<std::vector<Vec2>> polygonUnion(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  struct Piece {
    Vec2 from, to;
  };
  // Every edge of `p` split at its crossings with the edges of `q`, keeping the pieces outside q.
  auto outside = [](const std::vector<Vec2>& p, const std::vector<Vec2>& q, std::vector<Piece>& out) {
    for (size_t i = 0; i < p.size(); ++i) {
      const Vec2 s0 = p[i], s1 = p[(i + 1) % p.size()], d = s1 - s0;
      std::vector<double> ts = {0, 1};
      for (size_t j = 0; j < q.size(); ++j) {
        const Vec2 e0 = q[j], e = q[(j + 1) % q.size()] - e0;
        const double den = cross2(d, e);
        if (den == 0) continue;
        const double t = cross2(e0 - s0, e) / den, u = cross2(e0 - s0, d) / den;
        if (t > 0 && t < 1 && u >= 0 && u <= 1) ts.push_back(t);
      }
      std::sort(ts.begin(), ts.end());
      for (size_t k = 0; k + 1 < ts.size(); ++k) {
        const Vec2 x0 = s0 + d * ts[k], x1 = s0 + d * ts[k + 1];
        if (!insidePolygon(q, 0.5 * (x0 + x1))) out.push_back({x0, x1});
      }
    }
  };
  std::vector<Piece> pieces;
  outside(a, b, pieces);
  outside(b, a, pieces);
  // Chain: each piece's end meets the start of the next (a crossing point is computed twice, once per
  // polygon, so ends are matched to the nearest start within a tolerance of the polygons' size).
  double extent = 0;
  for (const Piece& pc : pieces) extent = std::max({extent, std::abs(pc.from.x), std::abs(pc.from.y)});
  const double tol = 1e-9 * std::max(1.0, extent);
  std::vector<bool> used(pieces.size(), false);
  std::vector<std::vector<Vec2>> loops;
  for (size_t start = 0; start < pieces.size(); ++start) {
    if (used[start]) continue;
    std::vector<Vec2> loop;
    size_t cur = start;
    while (!used[cur]) {
      used[cur] = true;
      loop.push_back(pieces[cur].from);
      size_t next = pieces.size();
      double best = tol;
      for (size_t k = 0; k < pieces.size(); ++k) {
        if (used[k] && k != start) continue;
        const double dist = glm::length(pieces[k].from - pieces[cur].to);
        if (dist <= best) {
          best = dist;
          next = k;
        }
      }
      if (next == pieces.size() || next == start) break;
      cur = next;
    }
    if (loop.size() >= 3) loops.push_back(loop);
  }
  return loops;
}

bool insidePolygon(const std::vector<Vec2>& poly, Vec2 p) {
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2 &a = poly[i], &b = poly[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x) in = !in;
  }
  return in;
}

ZoneResult evaluateZone(const FovZone& z, const VehicleFrame& frame, const std::vector<const EyeFootprint*>& eyes,
                        const FovOptions& options) {
  ZoneResult res;
  res.polygon = zoneInVehicle(z, frame, options.zone_horizon_m);
  Vec2 lo(kInf), hi(-kInf);
  for (const Vec2& p : res.polygon) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  // Samples: uniform in the angle of depression from the ocular points' height where the zone lies wholly
  // behind them (CONVENTIONS), else uniform in x; uniform in y.
  const double h = 0.5 * (frame.eye(true).z + frame.eye(false).z);
  std::vector<Vec2> pts;
  const int nx = options.zone_samples_x, ny = options.zone_samples_y;
  for (int a = 0; a < nx; ++a) {
    const double f = (a + 0.5) / nx;
    double x;
    if (hi.x < -1) {
      const double a0 = std::atan2(h, -hi.x), a1 = std::atan2(h, -lo.x);
      x = -h / std::tan(a0 + (a1 - a0) * f);
    } else {
      x = hi.x + (lo.x - hi.x) * f;
    }
    for (int b = 0; b < ny; ++b) {
      const Vec2 p(x, lo.y + (hi.y - lo.y) * (b + 0.5) / ny);
      if (insidePolygon(res.polygon, p)) pts.push_back(p);
    }
  }
  PVRR_CHECK(!pts.empty(), "zone " << z.name << " has no sample points");
  // Per eye: 0 unseen, 1 seen, 2 seen only through obstructed cells.
  auto classify = [&](const EyeFootprint& f) {
    std::vector<int> state(pts.size(), 0);
    const int n = f.n;
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const size_t k[4] = {size_t(j) * size_t(n) + size_t(i), size_t(j) * size_t(n) + size_t(i + 1),
                             size_t(j + 1) * size_t(n) + size_t(i + 1), size_t(j + 1) * size_t(n) + size_t(i)};
        bool back = false, obs = false;
        Vec2 qlo(kInf), qhi(-kInf);
        for (size_t c : k) {
          back |= f.fate[c] == RayFate::Back;
          obs |= f.fate[c] == RayFate::Obstructed;
          qlo = glm::min(qlo, f.road[c]);
          qhi = glm::max(qhi, f.road[c]);
        }
        if (back) continue;
        for (size_t s = 0; s < pts.size(); ++s) {
          const Vec2 p = pts[s];
          if (p.x < qlo.x || p.x > qhi.x || p.y < qlo.y || p.y > qhi.y || state[s] == 1) continue;
          if (inTriangle(p, f.road[k[0]], f.road[k[1]], f.road[k[2]]) ||
              inTriangle(p, f.road[k[0]], f.road[k[2]], f.road[k[3]]))
            state[s] = obs ? 2 : 1;
        }
      }
    return state;
  };
  // Several footprints of one eye (the samples of its eye ellipse): seen when any sample sees the point clear,
  // else obstructed when any sees it through an obstructed cell.
  std::vector<int> sl(pts.size(), 0), sr(pts.size(), 0);
  for (const EyeFootprint* e : eyes) {
    const std::vector<int> st = classify(*e);
    std::vector<int>& dst = e->eye == "left" ? sl : sr;
    for (size_t s = 0; s < pts.size(); ++s) dst[s] = (dst[s] == 1 || st[s] == 1) ? 1 : (dst[s] || st[s]) ? 2 : 0;
  }
  int seen = 0, obs = 0;
  for (size_t s = 0; s < pts.size(); ++s) {
    int st = 0;
    switch (z.eyes) {
      case FovZone::Eyes::Either:
        st = (sl[s] == 1 || sr[s] == 1) ? 1 : (sl[s] || sr[s]) ? 2 : 0;
        break;
      case FovZone::Eyes::Both:
        st = (sl[s] == 1 && sr[s] == 1) ? 1 : (sl[s] && sr[s]) ? 2 : 0;
        break;
      case FovZone::Eyes::Left:
        st = sl[s];
        break;
      case FovZone::Eyes::Right:
        st = sr[s];
        break;
    }
    seen += st == 1;
    obs += st == 2;
    if (st != 1) res.missed.push_back(pts[s]);
  }
  res.samples = int(pts.size());
  res.covered_fraction = double(seen) / double(pts.size());
  res.obstructed_fraction = double(obs) / double(pts.size());
  res.pass = seen + obs == int(pts.size()) && res.obstructed_fraction <= z.allowed_obstructed_fraction;
  return res;
}

SurfaceFigures surfaceFigures(const RayScene& rays, int element, const Vec3& eye_world, const FovOptions& options) {
  const Element& el = rays.scene().elements[size_t(element)];
  const cad::Surface& surface = el.frontSurface();
  SurfaceFigures out;
  const int n = out.n = options.samples;
  std::vector<Vec3> d(size_t(n) * size_t(n)), r(d.size());
  std::vector<bool> front(d.size(), false);
  double radius_sum = 0;
  int radius_count = 0;
  double rmin = kInf, rmax = -kInf;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const size_t k = size_t(j) * size_t(n) + size_t(i);
      const Vec2 uv = sampleParameters(el, i, j, n);
      const cad::SurfacePoint sp = surface.sample(uv.x, uv.y, true);
      const Vec3 p = el.toWorldPoint(sp.p), nrm = glm::normalize(el.toWorldDir(sp.n));
      d[k] = glm::normalize(p - eye_world);
      r[k] = reflect(d[k], nrm);
      front[k] = glm::dot(d[k], nrm) < 0;
      const double r1 = sp.k.k1 != 0 ? 1 / sp.k.k1 : kInf, r2 = sp.k.k2 != 0 ? 1 / sp.k.k2 : kInf;
      radius_sum += 0.5 * (r1 + r2);
      ++radius_count;
      for (double v : {r1, r2}) {
        rmin = std::min(rmin, v);
        rmax = std::max(rmax, v);
      }
    }
  out.mean_radius_m = radius_sum / radius_count;
  out.principal_radius_min_m = rmin;
  out.principal_radius_max_m = rmax;
  // Angular differences of unit vectors a, b, c (c - a, b - a) in the plane perpendicular to their mean.
  auto frame2 = [](const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 m = glm::normalize(a + b + c);
    const Vec3 e1 = glm::normalize(glm::cross(m, std::abs(m.z) < 0.9 ? Vec3(0, 0, 1) : Vec3(1, 0, 0)));
    const Vec3 e2 = glm::cross(m, e1);
    const Vec3 du = b - a, dv = c - a;
    return glm::dmat2(glm::dot(du, e1), glm::dot(du, e2), glm::dot(dv, e1), glm::dot(dv, e2));
  };
  out.magnification.assign(size_t(n - 1) * size_t(n - 1), std::nan(""));
  out.principal_magnifications.assign(out.magnification.size(), Vec2(std::nan("")));
  double mmin = kInf, mmax = 0;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const size_t a = size_t(j) * size_t(n) + size_t(i), b = a + 1, c = a + size_t(n);
      if (!front[a] || !front[b] || !front[c]) continue;
      const glm::dmat2 D = frame2(d[a], d[b], d[c]), R = frame2(r[a], r[b], r[c]);
      if (std::abs(glm::determinant(R)) < 1e-300) continue;
      const glm::dmat2 M = D * glm::inverse(R);
      // Singular values of a 2 x 2 matrix from its Frobenius norm and determinant.
      const double f2 = M[0][0] * M[0][0] + M[0][1] * M[0][1] + M[1][0] * M[1][0] + M[1][1] * M[1][1];
      const double det = std::abs(glm::determinant(M));
      const double disc = std::sqrt(std::max(0.0, f2 * f2 - 4 * det * det));
      const double s1 = std::sqrt(0.5 * (f2 + disc)), s2 = std::sqrt(std::max(0.0, 0.5 * (f2 - disc)));
      const size_t cell = size_t(j) * size_t(n - 1) + size_t(i);
      out.magnification[cell] = std::sqrt(det);
      out.principal_magnifications[cell] = Vec2(s1, s2);
      mmin = std::min(mmin, s2);
      mmax = std::max(mmax, s1);
    }
  out.magnification_min = mmin;
  out.magnification_max = mmax;
  return out;
}

}  // namespace pvrr
