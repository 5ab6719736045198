#include "pvrr/trace/light_tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "pvrr/base/error.h"
#include "pvrr/optics/optics.h"
#include "pvrr/optics/spectrum.h"
#include "pvrr/trace/specular.h"

namespace pvrr {

namespace {

// splitmix64 (Steele, Lea, Flood 2014): a portable hash of the stratum's identity, so that every photon's
// jitter depends on nothing but (seed, light, element, sample, stratum), whatever the thread schedule.
uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}
double unitFromBits(uint64_t x) { return double(x >> 11) * 0x1.0p-53; }

// An orthonormal pair perpendicular to unit w.
void perpendicularPair(const Vec3& w, Vec3& a, Vec3& b) {
  const Vec3 h = std::abs(w.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  a = glm::normalize(glm::cross(w, h));
  b = glm::cross(w, a);
}

// Points of an element's surfaces in world, on a grid over their parameter domains (its silhouette's support).
std::vector<Vec3> elementPoints(const Element& el) {
  constexpr int kGrid = 25;
  std::vector<const cad::Surface*> surfaces;
  if (el.type == ElementType::Lens) {
    surfaces = {el.lens.front.get(), el.lens.back.get()};
  } else {
    surfaces = {el.surface.get()};
  }
  std::vector<Vec3> pts;
  for (const cad::Surface* s : surfaces) {
    if (!s) continue;
    const cad::ParamDomain d = s->domain();
    for (int i = 0; i < kGrid; ++i)
      for (int j = 0; j < kGrid; ++j) {
        const double u = d.u0 + (d.u1 - d.u0) * i / (kGrid - 1), v = d.v0 + (d.v1 - d.v0) * j / (kGrid - 1);
        const Vec3 p = s->evaluate(u, v).p;
        if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) pts.push_back(el.toWorldPoint(p));
      }
  }
  return pts;
}

}  // namespace

bool causticAperture(const Scene& scene, const Light& light, const Element& el, CausticAperture& ap, std::string& why) {
  const std::vector<Vec3> pts = elementPoints(el);
  if (pts.empty()) {
    why = "no finite point on its surfaces";
    return false;
  }
  Vec3 centre(0);
  for (const Vec3& p : pts) centre += p;
  centre /= double(pts.size());
  ap.point = light.type == Light::Type::Point;
  if (ap.point) {
    ap.origin = light.position;
    const Vec3 w = centre - light.position;
    if (glm::length(w) <= 0) {
      why = "the light sits inside the element";
      return false;
    }
    ap.axis = glm::normalize(w);
  } else {
    ap.axis = glm::normalize(light.direction);
  }
  perpendicularPair(ap.axis, ap.a, ap.b);
  ap.x0 = ap.y0 = kInf;
  ap.x1 = ap.y1 = -kInf;
  double along_min = kInf;
  for (const Vec3& p : pts) {
    const Vec3 r = p - (ap.point ? light.position : centre);
    double x = glm::dot(r, ap.a), y = glm::dot(r, ap.b);
    const double s = glm::dot(r, ap.axis);
    if (ap.point) {
      if (s <= 1e-9 * glm::length(r)) {
        why = "the light lies within the element's extent (not all of it is ahead of the light)";
        return false;
      }
      x /= s;
      y /= s;
    }
    along_min = std::min(along_min, glm::dot(p, ap.axis));
    ap.x0 = std::min(ap.x0, x), ap.x1 = std::max(ap.x1, x);
    ap.y0 = std::min(ap.y0, y), ap.y1 = std::max(ap.y1, y);
  }
  const double pad = kAperturePad * std::max(ap.x1 - ap.x0, ap.y1 - ap.y0);
  ap.x0 -= pad, ap.x1 += pad, ap.y0 -= pad, ap.y1 += pad;
  if (!ap.point) {
    // Start upstream of everything in the scene, so that what lies between the light and the element blocks it.
    for (int k = 0; k < 8; ++k) {
      const Vec3 c((k & 1) ? scene.bounds_max.x : scene.bounds_min.x, (k & 2) ? scene.bounds_max.y : scene.bounds_min.y,
                   (k & 4) ? scene.bounds_max.z : scene.bounds_min.z);
      along_min = std::min(along_min, glm::dot(c, ap.axis));
    }
    const double margin = 1e-2 + 1e-3 * glm::length(scene.bounds_max - scene.bounds_min);
    ap.origin = centre + (along_min - margin - glm::dot(centre, ap.axis)) * ap.axis;
  }
  return true;
}

std::vector<SpectralSample> causticSamples(const Scene& scene, const CausticOptions& o) {
  bool depends = false;
  for (const Element& e : scene.elements) {
    if (e.type == ElementType::Lens && e.dispersion.abbe() < kInf) depends = true;
    if (o.dispersion == DispersionMode::Spectral && e.type == ElementType::Mirror && e.mirror.metal_table)
      depends = true;
  }
  if (!depends || o.dispersion == DispersionMode::Off) return {SpectralSample{0, Vec3(1.0)}};
  return o.dispersion == DispersionMode::Rgb ? rgbSamples() : spectralSamples(o.spectral_samples);
}

CausticPhoton photonAt(const CausticAperture& ap, const Light& light, const SpectralSample& sample, double x, double y,
                       double measure) {
  CausticPhoton p;
  if (ap.point) {
    p.origin = ap.origin;
    p.direction = glm::normalize(ap.axis + x * ap.a + y * ap.b);
    const double q = 1.0 + x * x + y * y;
    p.power = light.radiance * sample.rgb_weight * (measure / (q * std::sqrt(q)));
  } else {
    p.origin = ap.origin + x * ap.a + y * ap.b;
    p.direction = ap.axis;
    p.power = light.radiance * sample.rgb_weight * measure;
  }
  return p;
}

PhotonFate followPhoton(const RayScene& rays, int element, double wavelength_nm, bool spectral, int max_depth,
                 CausticPhoton& p) {
  const Scene& scene = rays.scene();
  Vec3 o = p.origin, d = p.direction;
  int inside = -1;
  double t_min = 0;
  for (int depth = 0;; ++depth) {
    RayHit hit;
    if (inside < 0) {
      hit = rays.intersect(o, d, t_min);
    } else {
      hit = hitInsideLens(rays, inside, o, d, t_min);
      if (!hit.hit()) return PhotonFate::Absorbed;  // out through the lens's edge band, not modelled as a surface
      // The glass absorbs along the segment (Beer-Lambert, per channel; exactly 1 for clear glass).
      const Element& glass = scene.elements[size_t(inside)];
      if (glass.absorbing()) p.power *= glass.internalTransmittance(glm::length(hit.point - o));
    }
    if (depth == 0 && (hit.kind != HitKind::Element || hit.element != element)) return PhotonFate::Missed;
    if (hit.kind != HitKind::Element) {
      p.origin = o;
      p.direction = d;
      p.t_hit = hit.hit() ? hit.t : kInf;
      p.mesh = hit.hit() ? hit.mesh : -1;
      p.triangle = hit.hit() ? hit.triangle : -1;
      p.hit_normal = hit.hit() ? hit.normal : Vec3(0);
      return PhotonFate::Left;
    }
    if (depth >= max_depth) return PhotonFate::Absorbed;
    const Element& el = scene.elements[size_t(hit.element)];
    ++p.bounces;
    const double n_glass =
        el.type == ElementType::Lens ? el.dispersion.index(wavelength_nm > 0 ? wavelength_nm : kLineD_nm) : 1.0;
    const SpecularEvent e = specularEvent(el, hit, d, inside, n_glass, spectral, wavelength_nm);
    if (e.kind == SpecularKind::MirrorBack) return PhotonFate::Absorbed;
    if (e.kind != SpecularKind::TotalInternal) p.power *= e.factor;
    o = hit.point;
    d = e.direction;
    t_min = rays.epsilon();
    inside = e.inside;
  }
}

namespace {

// Counts and photons of one row of strata.
struct RowOut {
  std::vector<CausticPhoton> photons;
  long long entered = 0, absorbed = 0;
  Vec3 entering_power{0}, leaving_power{0};
};

void shootRow(const RayScene& rays, const Light& light, const CausticAperture& ap, int light_index, int element,
              int sample_index, const SpectralSample& sample, bool spectral, const CausticOptions& o, int row,
              RowOut& out) {
  const int side = o.photons_per_side;
  const double dx = (ap.x1 - ap.x0) / side, dy = (ap.y1 - ap.y0) / side;
  for (int col = 0; col < side; ++col) {
    uint64_t h = mix64(o.seed);
    for (uint64_t k : {uint64_t(light_index), uint64_t(element), uint64_t(sample_index), uint64_t(row), uint64_t(col)})
      h = mix64(h ^ k);
    const double x = ap.x0 + (col + unitFromBits(h)) * dx;
    const double y = ap.y0 + (row + unitFromBits(mix64(h))) * dy;
    CausticPhoton p = photonAt(ap, light, sample, x, y, dx * dy);
    p.light = light_index;
    p.element = element;
    const Vec3 entering = p.power;
    const PhotonFate fate = followPhoton(rays, element, sample.wavelength_nm, spectral, o.max_depth, p);
    if (fate == PhotonFate::Missed) continue;
    ++out.entered;
    out.entering_power += entering;
    if (fate == PhotonFate::Absorbed) {
      ++out.absorbed;
      continue;
    }
    out.leaving_power += p.power;
    out.photons.push_back(p);
  }
}

}  // namespace

PhotonBundle shootCausticPhotons(const RayScene& rays, const CausticOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const Scene& scene = rays.scene();
  if (o.photons_per_side < 1 || o.photons_per_side > 8192)
    throw Error("caustics: photons per side must be in [1, 8192], got " + std::to_string(o.photons_per_side));
  if (o.element >= int(scene.elements.size()))
    throw Error("caustics: element " + std::to_string(o.element) + " out of range");
  const std::vector<SpectralSample> samples = causticSamples(scene, o);
  const bool spectral = o.dispersion == DispersionMode::Spectral;
  PhotonBundle b;
  b.samples_per_photon = int(samples.size());
  const int side = o.photons_per_side;
  for (size_t li = 0; li < scene.lights.size(); ++li) {
    const Light& light = scene.lights[li];
    if (light.type == Light::Type::Ambient) continue;  // no direction: it makes no caustic
    if (o.caustic_lights_only && !light.caustics) continue;
    for (size_t ei = 0; ei < scene.elements.size(); ++ei) {
      if (o.element >= 0 && int(ei) != o.element) continue;
      CausticAperture ap;
      std::string why;
      if (!causticAperture(scene, light, scene.elements[ei], ap, why)) {
        b.notes.push_back("light " + std::to_string(li) + ", element \"" + scene.elements[ei].name + "\": skipped, " +
                          why);
        continue;
      }
      for (size_t si = 0; si < samples.size(); ++si) {
        std::vector<RowOut> rows(static_cast<size_t>(side));
        tbb::parallel_for(tbb::blocked_range<int>(0, side, 1), [&](const tbb::blocked_range<int>& r) {
          for (int row = r.begin(); row < r.end(); ++row)
            shootRow(rays, light, ap, int(li), int(ei), int(si), samples[si], spectral, o, row, rows[size_t(row)]);
        });
        b.emitted += (long long)side * side;
        for (RowOut& r : rows) {
          b.entered += r.entered;
          b.absorbed += r.absorbed;
          b.entering_power += r.entering_power;
          b.leaving_power += r.leaving_power;
          b.photons.insert(b.photons.end(), r.photons.begin(), r.photons.end());
        }
      }
    }
  }
  b.elapsed_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return b;
}

CausticResult depositPhotons(const PhotonBundle& bundle, const ReceiverRect& rect, const DepositOptions& opt) {
  if (rect.cells_u < 1 || rect.cells_v < 1 || !(rect.width_m > 0) || !(rect.height_m > 0))
    throw Error("caustics: the receiver needs positive cells and size");
  const bool curved = opt.mode == DepositOptions::Mode::Surfaces && opt.height_field;
  if (curved && opt.mesh < 0) throw Error("caustics: a curved (height-field) receiver needs its mesh");
  CausticResult res;
  res.emitted = bundle.emitted;
  res.grid = IrradianceGrid::zeros(rect);
  const size_t n = res.grid.irradiance.size();
  std::vector<double> sum_sq(n, 0.0);  // per cell: sum of (w P_scalar)^2
  const Vec3 normal = rect.normal();
  const double cw = rect.cellWidth(), ch = rect.cellHeight(), inv_area = 1.0 / rect.cellArea();
  for (const CausticPhoton& p : bundle.photons) {
    Vec3 x;
    if (opt.mode == DepositOptions::Mode::Plane) {
      const double dn = glm::dot(p.direction, normal);
      if (dn == 0) continue;
      const double t = glm::dot(rect.centre - p.origin, normal) / dn;
      if (!(t > 0)) continue;
      x = p.origin + t * p.direction;
    } else {
      if (!std::isfinite(p.t_hit) || (opt.mesh >= 0 && p.mesh != opt.mesh)) continue;
      if (!opt.sheet.holds(p.triangle)) continue;
      x = p.origin + p.t_hit * p.direction;
      if (!curved && std::abs(glm::dot(x - rect.centre, normal)) > opt.slab_m) continue;
    }
    const Vec2 uv = rect.toReceiver(x);
    // Photons up to half a cell outside still reach the border cells through the kernel.
    if (std::abs(uv.x) > 0.5 * (rect.width_m + cw) || std::abs(uv.y) > 0.5 * (rect.height_m + ch)) continue;
    if (rect.contains(uv)) {
      ++res.deposited;
      res.landed_power += p.power;
    }
    // Tent kernel: continuous cell coordinates with cell centres at integers.
    const double fx = (uv.x + 0.5 * rect.width_m) / cw - 0.5, fy = (uv.y + 0.5 * rect.height_m) / ch - 0.5;
    const int i0 = int(std::floor(fx)), j0 = int(std::floor(fy));
    const double ax = fx - i0, ay = fy - j0;
    // Curved: the power per unit area of the surface, whose piece over a cell is cell area / cos of it.
    const Vec3 power = curved ? p.power * std::abs(glm::dot(p.hit_normal, normal)) : p.power;
    const double scalar = (power.x + power.y + power.z) / 3.0;
    for (int dj = 0; dj < 2; ++dj)
      for (int di = 0; di < 2; ++di) {
        const int i = i0 + di, j = j0 + dj;
        if (i < 0 || j < 0 || i >= rect.cells_u || j >= rect.cells_v) continue;
        const double w = (di ? ax : 1 - ax) * (dj ? ay : 1 - ay);
        const size_t k = res.grid.index(i, j);
        res.grid.irradiance[k] += w * inv_area * power;
        sum_sq[k] += (w * scalar) * (w * scalar);
      }
  }
  res.grid.variance.resize(n);
  double peak = 0;
  size_t peak_k = 0;
  for (size_t k = 0; k < n; ++k) {
    res.grid.variance[k] = sum_sq[k] * inv_area * inv_area;
    const Vec3& e = res.grid.irradiance[k];
    const double s = (e.x + e.y + e.z) / 3.0;
    if (s > peak) peak = s, peak_k = k;
  }
  if (peak > 0) {
    res.peak_rel_stderr = std::sqrt(res.grid.variance[peak_k]) / peak;
    double wsum = 0, acc = 0;
    for (size_t k = 0; k < n; ++k) {
      const Vec3& e = res.grid.irradiance[k];
      const double s = (e.x + e.y + e.z) / 3.0;
      if (s < 0.5 * peak) continue;
      wsum += s;
      acc += std::sqrt(res.grid.variance[k]);  // the cell's standard error, weighted by its irradiance s
    }
    res.spot_rel_stderr = acc / wsum;
  }
  return res;
}

namespace {

// Bilinear between cell centres, clamped to the border cells (GL_CLAMP_TO_EDGE), at receiver coordinates uv.
template <typename T>
T bilinearCells(const ReceiverRect& r, const std::vector<T>& cells, const Vec2& uv) {
  const double x = (uv.x + 0.5 * r.width_m) / r.cellWidth() - 0.5;
  const double y = (uv.y + 0.5 * r.height_m) / r.cellHeight() - 0.5;
  const double fx = std::floor(x), fy = std::floor(y), ax = x - fx, ay = y - fy;
  const auto cell = [&](int i, int j) {
    return cells[size_t(std::clamp(j, 0, r.cells_v - 1)) * size_t(r.cells_u) + size_t(std::clamp(i, 0, r.cells_u - 1))];
  };
  const int i0 = int(fx), j0 = int(fy);
  const auto mix = [](const T& a, const T& b, double t) { return T(a * (1 - t) + b * t); };  // glm::mix's rounding
  return mix(mix(cell(i0, j0), cell(i0 + 1, j0), ax), mix(cell(i0, j0 + 1), cell(i0 + 1, j0 + 1), ax), ay);
}

}  // namespace

Vec3 CausticLightField::irradianceAt(const Vec3& p) const {
  Vec3 e(0.0);
  const double slab = DepositOptions{}.slab_m;
  for (const CausticReceiverMap& m : receivers) {
    const ReceiverRect& r = m.grid.rect;
    const double h = glm::dot(p - r.centre, r.normal());
    if (m.height.empty() && std::abs(h) > slab) continue;
    const Vec2 uv = r.toReceiver(p);
    if (!r.contains(uv)) continue;
    // A curved receiver: the point is on it where its height matches the surface's (the map's heights).
    if (!m.height.empty() && !(std::abs(h - double(bilinearCells(r, m.height, uv))) <= slab)) continue;
    e += bilinearCells(r, m.grid.irradiance, uv);
  }
  return e;
}

CausticLightField causticLightField(const RayScene& rays, const std::vector<CausticReceiverMap>& windows,
                                    CausticOptions options) {
  const auto start = std::chrono::steady_clock::now();
  options.caustic_lights_only = true;
  const PhotonBundle b = shootCausticPhotons(rays, options);
  CausticLightField f;
  f.emitted = b.emitted;
  f.photons_per_side = options.photons_per_side;
  f.samples_per_photon = b.samples_per_photon;
  for (const CausticReceiverMap& w : windows) {
    DepositOptions d;
    d.mesh = w.mesh;
    d.height_field = !w.height.empty();
    d.sheet = w.sheet;
    f.receivers.push_back({w.mesh, depositPhotons(b, w.grid.rect, d).grid, w.height, w.sheet});
  }
  f.elapsed_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return f;
}

std::optional<PowerWindow> powerWindow(const std::vector<std::pair<Vec2, double>>& landed, double quantile,
                                       double scale, double min_side_m) {
  double total = 0;
  Vec2 acc(0);
  for (const auto& [q, w] : landed) {
    total += w;
    acc += w * q;
  }
  if (!(total > 0)) return std::nullopt;
  const Vec2 c = acc / total;
  std::vector<std::pair<double, double>> radii;  // (Chebyshev distance from the centroid, power)
  for (const auto& [q, w] : landed) radii.push_back({std::max(std::abs(q.x - c.x), std::abs(q.y - c.y)), w});
  std::sort(radii.begin(), radii.end());
  double sum = 0, radius = 0;
  for (const auto& [d, w] : radii) {
    sum += w;
    radius = d;
    if (sum >= quantile * total) break;
  }
  return PowerWindow{c, std::max(min_side_m, 2 * scale * radius)};
}

}  // namespace pvrr
