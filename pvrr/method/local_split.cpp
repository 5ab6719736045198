#include "pvrr/method/local_split.h"

#include <algorithm>
#include <cmath>

#include "cad/local_refine.h"
#include "pvrr/method/vertex_stage.h"

namespace pvrr {

std::vector<double> quadSpreadRatios(const ElementFrame& f, const FrameQualityLimits& limits) {
  const int gu = f.grid.grid_u, gv = f.grid.grid_v;
  std::vector<double> ratio(size_t(std::max(gu - 1, 0)) * size_t(std::max(gv - 1, 0)), 0.0);
  if (gu < 2 || gv < 2 || f.rays.empty()) return ratio;
  const size_t n_grid = size_t(gu) * size_t(gv);
  // The middle channel stands for all, as in assessFrameQuality.
  const std::vector<VertexRay>& rays = f.rays[f.rays.size() / 2];
  const std::vector<Vec3>& n = f.world_normal;
  for (size_t t = 0; t < f.grid.triangles.size(); ++t) {
    const cad::Triangle& tri = f.grid.triangles[t];
    const uint32_t a = tri.x, b = tri.y, c = tri.z;
    if (!f.in_view.empty() && !(f.in_view[a] && f.in_view[b] && f.in_view[c])) continue;
    size_t q;
    if (f.grid.locallyRefined()) {
      q = f.grid.triangle_quads[t];
    } else {
      if (std::max({a, b, c}) >= n_grid) continue;
      q = size_t(std::min({a / gv, b / gv, c / gv})) * size_t(gv - 1) + std::min({a % gv, b % gv, c % gv});
    }
    double r;
    if (rays[a].status == VertexStatus::Tir || rays[b].status == VertexStatus::Tir ||
        rays[c].status == VertexStatus::Tir) {
      auto shown = [&](uint32_t v) {
        const VertexRay& vr = rays[v];
        return glm::normalize((vr.status == VertexStatus::Tir && vr.traced ? vr.traced_seen : vr.hit) - f.world_pos[v]);
      };
      const Vec3 da = shown(a), db = shown(b), dc = shown(c);
      r = degrees(std::max({angleBetween(da, db), angleBetween(db, dc), angleBetween(dc, da)})) /
          limits.max_traced_spread_deg;
    } else {
      r = degrees(std::max({angleBetween(n[a], n[b]), angleBetween(n[b], n[c]), angleBetween(n[c], n[a])})) /
          limits.max_normal_spread_deg;
    }
    if (std::isfinite(r)) ratio[q] = std::max(ratio[q], r);
  }
  return ratio;
}

LocalSplit chooseLocalSplit(const ElementFrame& f, int max_vertices, const FrameQualityLimits& limits, double target) {
  const int gu = f.grid.grid_u, gv = f.grid.grid_v;
  LocalSplit out;
  const std::vector<double> ratio = quadSpreadRatios(f, limits);
  const std::vector<uint8_t> now =
      f.grid.quad_levels.empty() ? std::vector<uint8_t>(ratio.size(), 0) : f.grid.quad_levels;
  out.levels = now;
  auto finish = [&]() -> LocalSplit& {
    out.changed = out.levels != now;
    for (uint8_t l : out.levels) {
      out.quads_split += l > 0;
      out.max_level = std::max(out.max_level, int(l));
    }
    out.vertices = out.quads_split ? cad::locallyRefinedVertexCount(gu, gv, out.levels) : f.grid.vertexCount();
    return out;
  };
  if (gu < 2 || gv < 2 || !std::any_of(ratio.begin(), ratio.end(), [](double r) { return r > 1.0; }))
    return finish();
  // The levels that bring every quad to tau: each level halves its ratio.
  auto levelsFor = [&](double tau, bool* capped) {
    std::vector<uint8_t> l = now;
    for (size_t q = 0; q < ratio.size(); ++q) {
      if (!(ratio[q] > tau)) continue;
      const int more = int(std::ceil(std::log2(ratio[q] / tau) - 1e-9));
      const int want = int(now[q]) + std::max(more, 0);
      if (want > cad::kMaxLocalLevel && capped) *capped = true;
      l[q] = uint8_t(std::min(want, cad::kMaxLocalLevel));
    }
    return cad::balanceQuadLevels(gu, gv, l);
  };
  bool capped = false;
  std::vector<uint8_t> best = levelsFor(target, &capped);
  if (cad::locallyRefinedVertexCount(gu, gv, best) > size_t(max_vertices)) {
    // Over the budget: the lowest tau above target whose levels fit, by bisection on log(tau); the quads above
    // it (the worst) are refined, the others not.
    out.budget_limited = true;
    const double r_max = *std::max_element(ratio.begin(), ratio.end());
    double lo = std::log(target), hi = std::log(std::max(r_max, target) * 1.000001);
    best = now;
    for (int it = 0; it < 40; ++it) {
      const double mid = 0.5 * (lo + hi);
      std::vector<uint8_t> l = levelsFor(std::exp(mid), nullptr);
      if (cad::locallyRefinedVertexCount(gu, gv, l) <= size_t(max_vertices)) {
        hi = mid;
        best = std::move(l);
      } else {
        lo = mid;
      }
    }
  }
  out.budget_limited = out.budget_limited || capped;
  out.levels = std::move(best);
  return finish();
}

}  // namespace pvrr
