#include "pvrr/trace/tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>
#include <pmmintrin.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>

#include "pvrr/base/error.h"
#include "pvrr/optics/optics.h"
#include "pvrr/trace/ambient_occlusion.h"
#include "pvrr/trace/light_tracer.h"
#include "pvrr/trace/shading.h"
#include "pvrr/trace/specular.h"
#include "pvrr/optics/spectrum.h"

namespace pvrr {

Tracer::Tracer(const RayScene& rays, TraceOptions options)
    : rays_(rays), scene_(rays.scene()), options_(options) {
  if (options_.dispersion == DispersionMode::Spectral) spectral_ = spectralSamples(options_.spectral_samples);
}

namespace {

double lensIndex(const Element& el, double wavelength_nm) {
  return el.dispersion.index(wavelength_nm > 0 ? wavelength_nm : kLineD_nm);
}

}  // namespace

TraceResult Tracer::trace(const Vec3& o, const Vec3& d, double wavelength_nm,
                          std::vector<PathSegment>* path) const {
  return traceImpl(o, d, wavelength_nm, path, nullptr, false);
}

TraceResult Tracer::traceImpl(const Vec3& o_in, const Vec3& d_in, double wavelength_nm,
                              std::vector<PathSegment>* path, const RayHit* first, bool metal_spectral) const {
  TraceResult r;
  Vec3 o = o_in, d = glm::normalize(d_in);
  Vec3 throughput(1.0);
  int inside = -1;  // the lens element the ray is inside, or -1
  double t_min = 0;
  const double eps = rays_.epsilon();
  for (int depth = 0;; ++depth) {
    RayHit hit;
    if (depth == 0 && first)
      hit = *first;
    else if (inside < 0)
      hit = rays_.intersect(o, d, t_min);
    if (inside >= 0) {
      // Inside a lens: the next event is on one of its own surfaces.
      hit = hitInsideLens(rays_, inside, o, d, t_min);
      // The glass absorbs along the segment inside it (Beer-Lambert, per channel; exactly 1 for clear glass).
      const Element& glass = scene_.elements[size_t(inside)];
      if (hit.hit() && glass.absorbing()) throughput *= glass.internalTransmittance(glm::length(hit.point - o));
      if (!hit.hit()) {
        // Leaving through the lens's edge band, which is not modelled as a surface: absorbed.
        if (path) path->push_back({o, d, "absorb", inside, false, {}, {}, 1, 1});
        r.color = Vec3(0);
        r.seen = o + scene_.render.far_distance_m * d;
        r.escaped = true;
        return r;
      }
    }
    PathSegment seg;
    seg.origin = o;
    seg.direction = d;
    if (!hit.hit()) {
      r.escaped = true;
      r.seen = o + scene_.render.far_distance_m * d;
      r.color = throughput * scene_.render.background;
      seg.event = "escape";
      if (path) path->push_back(seg);
      return r;
    }
    seg.has_point = true;
    seg.point = hit.point;
    seg.normal = hit.normal;
    if (hit.kind == HitKind::Environment) {
      const EnvMesh& mesh = scene_.meshes[size_t(hit.mesh)];
      Vec3 n = glm::dot(hit.normal, d) > 0 ? -hit.normal : hit.normal;
      const ShadowRays shadows(rays_, options_.caustics != nullptr);
      const Vec3 caustic = options_.caustics ? options_.caustics->irradianceAt(hit.point) : Vec3(0.0);
      const AmbientOcclusionDesc& ao = scene_.render.ambient_occlusion;
      const double ambient =
          ao.on ? referenceAmbientVisibility(rays_, hit.point, n, occluderOfMesh(scene_, hit.mesh), ao.reference_samples)
                : 1.0;
      r.color = throughput * shadeDiffuse(scene_, scene_.materials[size_t(mesh.material)], hit.point, n, hit.uv,
                                          &shadows, ambient, caustic);
      r.seen = hit.point;
      seg.event = "diffuse";
      if (path) path->push_back(seg);
      return r;
    }
    // An optical element.
    const Element& el = scene_.elements[size_t(hit.element)];
    seg.element = hit.element;
    if (r.first_element < 0) {
      r.first_element = hit.element;
      r.element_point = hit.point;
    }
    if (depth >= options_.max_depth) {
      seg.event = "absorb";
      if (path) path->push_back(seg);
      r.color = Vec3(0);
      r.seen = hit.point;
      r.depth_limited = true;
      return r;
    }
    const double n_glass = el.type == ElementType::Lens ? lensIndex(el, wavelength_nm) : 1.0;
    const SpecularEvent e = specularEvent(el, hit, d, inside, n_glass, metal_spectral, wavelength_nm);
    if (el.type == ElementType::Mirror) {
      if (e.kind == SpecularKind::MirrorBack) {
        // The mirror's back: dark diffuse.
        seg.event = "diffuse";
        if (path) path->push_back(seg);
        r.color = throughput * kMirrorBackAlbedo * shadeDiffuse(scene_, DiffuseMaterial{Vec3(1.0), -1}, hit.point,
                                                                -hit.normal, Vec2(0));
        r.seen = hit.point;
        return r;
      }
      if (el.mirror.metal && el.mirror.metal_table) r.hit_metal = true;
      throughput *= e.factor;
      seg.event = "reflect";
      if (path) path->push_back(seg);
      o = hit.point;
      d = e.direction;
      t_min = eps;
      ++r.bounces;
      continue;
    }
    // Lens interface.
    r.hit_lens = true;
    seg.n1 = e.n1;
    seg.n2 = e.n2;
    ++r.bounces;
    o = hit.point;
    t_min = eps;
    seg.event = e.kind == SpecularKind::TotalInternal ? "tir" : "refract";
    if (path) path->push_back(seg);
    if (e.kind == SpecularKind::Refract) throughput *= e.factor;
    d = e.direction;
    inside = e.inside;
  }
}

TraceResult Tracer::tracePixel(double px, double py) const {
  return tracePrimary(scene_.observer.pixelDirection(px, py), nullptr, nullptr);
}

TraceResult Tracer::tracePrimary(const Vec3& d, const RayHit* first, std::array<Vec3, 3>* channel_seen) const {
  const Vec3& eye = scene_.observer.eye;
  // The primary hit does not depend on the wavelength: every trace below reuses `first`.
  switch (options_.dispersion) {
    case DispersionMode::Off:
      return traceImpl(eye, d, 0, nullptr, first, false);
    case DispersionMode::Rgb: {
      const double* wl = kRgbWavelengths_nm;
      TraceResult g = traceImpl(eye, d, wl[1], nullptr, first, false);
      // Without any lens on the path the three channels follow the same path: skip the other two.
      if (!g.hit_lens) {
        if (channel_seen) *channel_seen = {g.seen, g.seen, g.seen};
        return g;
      }
      TraceResult rr = traceImpl(eye, d, wl[0], nullptr, first, false);
      TraceResult bb = traceImpl(eye, d, wl[2], nullptr, first, false);
      if (channel_seen) *channel_seen = {rr.seen, g.seen, bb.seen};
      g.color = Vec3(rr.color.r, g.color.g, bb.color.b);
      return g;
    }
    case DispersionMode::Spectral: {
      TraceResult centre = traceImpl(eye, d, 0, nullptr, first, false);
      // Only lenses (the path) and tabulated metals (the reflectance) depend on the wavelength.
      if (!centre.hit_lens && !centre.hit_metal) return centre;
      Vec3 sum(0.0);
      for (const SpectralSample& s : spectral_)
        sum += s.rgb_weight * traceImpl(eye, d, s.wavelength_nm, nullptr, first, true).color;
      centre.color = sum;
      return centre;
    }
  }
  return {};
}

namespace {

// Primary rays are traced in square tiles of kTile x kTile pixels, one Embree packet each.
constexpr int kTile = 4;
static_assert(kTile * kTile == RayScene::kPacketSize, "one packet per tile");

}  // namespace

Frame Tracer::render(const std::function<void(double)>& progress) const {
  const int w = scene_.observer.width, h = scene_.observer.height;
  Frame f;
  f.width = w;
  f.height = h;
  const size_t n = size_t(w) * size_t(h);
  f.color.resize(n);
  f.seen.resize(n);
  f.element.resize(n);
  f.element_point.resize(n);
  f.bounces.resize(n);
  f.depth_limited.resize(n);
  const bool rgb = options_.dispersion == DispersionMode::Rgb;
  if (rgb)
    for (auto& c : f.channel_seen) c.resize(n);
  auto start = std::chrono::steady_clock::now();
  std::atomic<int> rows_done{0};
  std::mutex progress_mutex;
  const Vec3 eye = scene_.observer.eye;
  // Bands of kTile rows; each band is cut into kTile x kTile tiles.
  const int bands = (h + kTile - 1) / kTile;
  tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& range) {
    // Denormals only slow the traversal down; flush them in every tracing thread (Embree's advice).
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    std::array<Vec3, RayScene::kPacketSize> origins, dirs, units;
    std::array<RayHit, RayScene::kPacketSize> hits;
    std::array<int, RayScene::kPacketSize> px, py;
    origins.fill(eye);
    int rows = 0;
    for (int band = range.begin(); band < range.end(); ++band) {
      const int y0 = band * kTile, y1 = std::min(h, y0 + kTile);
      rows += y1 - y0;
      for (int x0 = 0; x0 < w; x0 += kTile) {
        const int x1 = std::min(w, x0 + kTile);
        int count = 0;
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) {
            px[size_t(count)] = x;
            py[size_t(count)] = y;
            dirs[size_t(count)] = scene_.observer.pixelDirection(x + 0.5, y + 0.5);
            // The direction traceImpl() will trace (it normalises), so that the hit is the same.
            units[size_t(count)] = glm::normalize(dirs[size_t(count)]);
            ++count;
          }
        if (options_.primary_packets) rays_.intersectPacket(origins.data(), units.data(), count, hits.data());
        for (int k = 0; k < count; ++k) {
          std::array<Vec3, 3> cs;
          TraceResult r = tracePrimary(dirs[size_t(k)], options_.primary_packets ? &hits[size_t(k)] : nullptr,
                                       rgb ? &cs : nullptr);
          const size_t i = size_t(py[size_t(k)]) * size_t(w) + size_t(px[size_t(k)]);
          f.color[i] = r.color;
          f.seen[i] = r.seen;
          f.element[i] = r.first_element;
          f.element_point[i] = r.element_point;
          f.bounces[i] = r.bounces;
          f.depth_limited[i] = r.depth_limited ? 1 : 0;
          if (rgb)
            for (size_t c = 0; c < 3; ++c) f.channel_seen[c][i] = cs[c];
        }
      }
    }
    int done = rows_done.fetch_add(rows) + rows;
    if (progress && progress_mutex.try_lock()) {
      progress(double(done) / h);
      progress_mutex.unlock();
    }
  });
  f.frame_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  f.stages.ran("ray-trace", f.frame_ms);
  return f;
}

}  // namespace pvrr
