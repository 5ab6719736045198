#include "pvrr/impostor/surface_map.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/parallel_for.h>

#include "pvrr/base/error.h"
#include "pvrr/base/bilinear.h"

namespace pvrr {

SurfaceMap buildSurfaceMap(const cad::Surface& surface, int n, const cad::Outline* outline) {
  if (n < 2 || n > 4096) throw Error("buildSurfaceMap: map size " + std::to_string(n) + ", expected 2 to 4096");
  const cad::ParamDomain d = surface.domain();
  SurfaceMap m;
  m.n = n;
  m.u0 = d.u0, m.v0 = d.v0, m.u1 = d.u1, m.v1 = d.v1;
  const size_t samples = size_t(n) * size_t(n);
  for (auto* a : {&m.position, &m.du, &m.dv, &m.normal}) a->assign(4 * samples, 0.0f);
  const Vec2 centre(0.5 * (d.u0 + d.u1), 0.5 * (d.v0 + d.v1));
  std::atomic<bool> failed{false};
  std::atomic<int> moved{0};
  tbb::parallel_for(0, n, [&](int j) {
    const double v = j == n - 1 ? d.v1 : d.v0 + (d.v1 - d.v0) * double(j) / double(n - 1);
    for (int i = 0; i < n; ++i) {
      const double u = i == n - 1 ? d.u1 : d.u0 + (d.u1 - d.u0) * double(i) / double(n - 1);
      Vec2 q(u, v);
      cad::SurfaceDerivs s{};
      Vec3 nrm(0.0);
      bool ok = false;
      for (int k = 0; k < 60 && !ok; ++k) {
        if (k > 0) q = centre + 0.9 * (q - centre);
        try {
          s = surface.evaluate(q.x, q.y);
          nrm = surface.normal(q.x, q.y);
          ok = isFinite(s.p) && isFinite(s.du) && isFinite(s.dv) && isFinite(nrm) && glm::length(nrm) > 0.5;
        } catch (const Error&) {
          ok = false;
        }
      }
      if (!ok) {
        failed = true;
        continue;
      }
      const bool moved_here = q != Vec2(u, v);
      moved += moved_here;
      const bool inside = !moved_here && (!outline || outline->contains(Vec2(u, v)));
      const size_t k = 4 * (size_t(j) * size_t(n) + size_t(i));
      for (int c = 0; c < 3; ++c) {
        m.position[k + size_t(c)] = float(s.p[c]);
        m.du[k + size_t(c)] = float(s.du[c] * (d.u1 - d.u0));
        m.dv[k + size_t(c)] = float(s.dv[c] * (d.v1 - d.v0));
        m.normal[k + size_t(c)] = float(nrm[c]);
      }
      m.position[k + 3] = inside ? 1.0f : 0.0f;
    }
  });
  if (failed)
    throw Error("buildSurfaceMap: a sample of the surface's parameter domain has no evaluable point with a normal "
                "between it and the domain's centre");
  m.moved_samples = moved;
  return m;
}

SurfaceMapSample sampleSurfaceMap(const SurfaceMap& m, double u, double v) {
  // The domain's corners are samples: sample coordinates run from 0 to n - 1 across it.
  const double x = std::clamp((u - m.u0) / (m.u1 - m.u0), 0.0, 1.0) * (m.n - 1);
  const double y = std::clamp((v - m.v0) / (m.v1 - m.v0), 0.0, 1.0) * (m.n - 1);
  auto at = [&](const std::vector<float>& data) { return bilinearSample(data, m.n, m.n, x, y); };
  const Vec4 p = at(m.position);
  return {Vec3(p), Vec3(at(m.du)), Vec3(at(m.dv)), glm::normalize(Vec3(at(m.normal))), p.w};
}

}  // namespace pvrr
