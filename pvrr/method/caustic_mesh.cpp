#include "pvrr/method/caustic_mesh.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "pvrr/base/error.h"

namespace pvrr {

namespace {

// The window about the landed power (as `pvrr caustic` chooses its own): the square about the power centroid
// out to kWindowScale times the (Chebyshev) radius holding kWindowQuantile of the power, at least kMinWindow_m.
constexpr double kWindowQuantile = 0.99, kWindowScale = 1.3, kMinWindow_m = 0.004;
// Planarity of a receiver mesh: its normals within this of one another (1 - cos), its vertices within this
// fraction of its extent of one plane (float vertices: a few ulps).
constexpr double kNormalTol = 1e-9, kPlaneTol = 1e-6;

struct Traced {
  CausticPhoton p;
  bool left = false;
  int surface = -1;  // CausticVertex::surface
};

// The receiving surfaces' ids: a whole mesh's is its index; a split mesh's sheets' are base + sheet.
struct Surfaces {
  std::vector<std::shared_ptr<const std::vector<int>>> split;  // per mesh: its triangles' sheets, or null (whole)
  std::vector<int> base;                    // per mesh: its first sheet's id
  int count = 0;                            // ids 0 .. count - 1
  int of(int mesh, int triangle) const {
    if (mesh < 0) return -1;
    const std::vector<int>* s = split[size_t(mesh)].get();
    if (!s) return mesh;
    const int sheet = triangle >= 0 && size_t(triangle) < s->size() ? (*s)[size_t(triangle)] : -1;
    return sheet < 0 ? -1 : base[size_t(mesh)] + sheet;
  }
};

bool consistent(const Traced* c[4]) {
  for (int k = 0; k < 4; ++k)
    if (!c[k]->left) return false;
  for (int k = 1; k < 4; ++k)
    if (c[k]->p.bounces != c[0]->p.bounces || c[k]->p.mesh != c[0]->p.mesh || c[k]->surface != c[0]->surface)
      return false;
  return true;
}

// A photon-mesh vertex's exit ray that meets no environment surface may have slipped between two receiver
// triangles through their shared edge: Embree's float triangle test is not watertight there, and the photon grid is
// regular, so a row of its vertices can run exactly along a receiver's symmetry line (a bowl of 140 x 140 facets
// with a vertex on the beam's central ray lost the photons of a sliver of cells along that row, a dip of up to
// 24 % in 4 cells, docs/caustics.md). Such a ray is tried again moved sideways by kEdgeNudge_m (far above the
// float rounding at the scene's scale, far below a map cell), in four directions, and takes the first environment
// hit; a ray that truly escapes misses all four and stays as it was. The reference's photons are jittered: an exact
// edge hit has probability zero there.
constexpr double kEdgeNudge_m = 1e-6;

void catchEdgeSlip(const RayScene& rays, CausticPhoton& p) {
  if (p.mesh >= 0) return;
  const Vec3 a = glm::normalize(glm::cross(p.direction, std::abs(p.direction.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0)));
  const Vec3 b = glm::cross(p.direction, a);
  for (const Vec3& side : {a, -a, b, -b}) {
    const RayHit h = rays.intersect(p.origin + kEdgeNudge_m * side, p.direction, rays.epsilon());
    if (!h.hit()) continue;
    if (h.kind != HitKind::Environment) return;
    p.t_hit = h.t;
    p.mesh = h.mesh;
    p.triangle = h.triangle;
    p.hit_normal = h.normal;
    return;
  }
}

// The traced photons of one (light, element, sample).
struct PairTracer {
  const RayScene& rays;
  const Light& light;
  const CausticAperture& ap;
  const SpectralSample& sample;
  int element;
  bool spectral;
  int max_depth;
  const Surfaces& surfaces;

  Traced at(double x, double y) const {
    Traced t;
    t.p = photonAt(ap, light, sample, x, y, 1.0);
    t.left = followPhoton(rays, element, sample.wavelength_nm, spectral, max_depth, t.p) == PhotonFate::Left;
    if (t.left) {
      catchEdgeSlip(rays, t.p);
      t.surface = surfaces.of(t.p.mesh, t.p.triangle);
    }
    return t;
  }
};

// One cell's sub-grid: its traced corners and the consistent sub-cells' triangles (local indices).
struct Refined {
  std::vector<Traced> vertices;
  std::vector<uint32_t> triangles;
  double lost_area = 0;
};

void addQuad(std::vector<uint32_t>& tris, uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  tris.insert(tris.end(), {a, b, c, a, c, d});  // corners a (x0, y0), b (x1, y0), c (x1, y1), d (x0, y1)
}

Refined refineCell(const PairTracer& tr, double x0, double y0, double dx, double dy, int s) {
  Refined r;
  r.vertices.resize(size_t(s + 1) * size_t(s + 1));
  for (int j = 0; j <= s; ++j)
    for (int i = 0; i <= s; ++i) r.vertices[size_t(j) * (s + 1) + i] = tr.at(x0 + dx * i / s, y0 + dy * j / s);
  for (int j = 0; j < s; ++j)
    for (int i = 0; i < s; ++i) {
      const uint32_t a = uint32_t(j * (s + 1) + i), b = a + 1, c = a + uint32_t(s) + 2, d = a + uint32_t(s) + 1;
      const Traced* corners[4] = {&r.vertices[a], &r.vertices[b], &r.vertices[c], &r.vertices[d]};
      if (consistent(corners)) {
        addQuad(r.triangles, a, b, c, d);
      } else if (corners[0]->left || corners[1]->left || corners[2]->left || corners[3]->left) {
        r.lost_area += dx * dy / (double(s) * s);
      }
    }
  return r;
}

CausticVertex vertexOf(const Traced& t, double x, double y) {
  CausticVertex v;
  v.xy = Vec2(x, y);
  v.origin = t.p.origin;
  v.direction = t.p.direction;
  v.power_density = t.p.power;
  v.mesh = t.left ? t.p.mesh : -1;
  v.surface = t.left ? t.surface : -1;
  if (v.mesh >= 0 && std::isfinite(t.p.t_hit)) {
    v.t_hit = t.p.t_hit;
    v.hit_normal = t.p.hit_normal;
  }
  return v;
}

// Landed power per receiving surface (Surfaces' ids): (landing point, weight) of each vertex photon that meets a mesh.
using Landings = std::vector<std::vector<std::pair<Vec3, double>>>;

// A kept cell on a curved receiver is refined as well when the photon at its centre does not land where its
// corners' landings predict (their mean) within kJumpFraction of their spread: the receiver shadows itself
// along the photons' paths (a bump hiding what lies behind it), a jump in the landing distance that the texels'
// interpolation would smear across the cell. A smooth surface's deviation is second order in the cell's size.
constexpr double kJumpFraction = 0.25;

Vec3 landing(const Traced& t) { return t.p.origin + t.p.t_hit * t.p.direction; }

CausticMesh tracePair(const PairTracer& tr, const CausticPlanOptions& o, const std::vector<bool>& curved,
                      Landings& landed, long long& traced) {
  const CausticAperture& ap = tr.ap;
  const int g = o.grid, s = o.refine;
  const double dx = (ap.x1 - ap.x0) / g, dy = (ap.y1 - ap.y0) / g;
  std::vector<Traced> grid(size_t(g + 1) * size_t(g + 1));
  tbb::parallel_for(0, g + 1, [&](int j) {
    for (int i = 0; i <= g; ++i) grid[size_t(j) * (g + 1) + i] = tr.at(ap.x0 + i * dx, ap.y0 + j * dy);
  });
  traced += (long long)grid.size();
  CausticMesh m;
  m.aperture = ap;
  auto land = [&](const Traced& t, double weight) {
    if (!t.left || t.p.mesh < 0 || !std::isfinite(t.p.t_hit)) return;
    // A split mesh's triangle in no sheet: counted apart (strays), for the notes.
    const size_t slot = t.surface >= 0 ? size_t(t.surface) : size_t(tr.surfaces.count) + size_t(t.p.mesh);
    const double w = weight * (t.p.power.x + t.p.power.y + t.p.power.z) / 3.0;
    landed[slot].push_back({t.p.origin + t.p.t_hit * t.p.direction, w});
  };
  for (int j = 0; j <= g; ++j)
    for (int i = 0; i <= g; ++i) {
      const Traced& t = grid[size_t(j) * (g + 1) + i];
      m.vertices.push_back(vertexOf(t, ap.x0 + i * dx, ap.y0 + j * dy));
      land(t, dx * dy);
    }
  std::vector<std::pair<int, int>> to_refine;
  double kept_area = 0;
  // Consistent cells on a curved receiver: their centres traced (in parallel) before they are kept.
  std::vector<char> jump(size_t(g) * size_t(g), 0);
  if (s > 1) {
    std::vector<std::pair<int, int>> check;
    for (int j = 0; j < g; ++j)
      for (int i = 0; i < g; ++i) {
        const uint32_t a = uint32_t(j * (g + 1) + i), b = a + 1, c = a + uint32_t(g) + 2, d = a + uint32_t(g) + 1;
        const Traced* corners[4] = {&grid[a], &grid[b], &grid[c], &grid[d]};
        const int surface = corners[0]->surface;
        if (consistent(corners) && surface >= 0 && curved[size_t(surface)]) check.push_back({i, j});
      }
    tbb::parallel_for(size_t(0), check.size(), [&](size_t k) {
      const auto [i, j] = check[k];
      const uint32_t a = uint32_t(j * (g + 1) + i), b = a + 1, c = a + uint32_t(g) + 2, d = a + uint32_t(g) + 1;
      const Traced centre = tr.at(ap.x0 + (i + 0.5) * dx, ap.y0 + (j + 0.5) * dy);
      const Vec3 mean = 0.25 * (landing(grid[a]) + landing(grid[b]) + landing(grid[c]) + landing(grid[d]));
      double spread = 0;
      for (uint32_t v : {a, b, c, d}) spread = std::max(spread, glm::length(landing(grid[v]) - mean));
      jump[size_t(j) * size_t(g) + size_t(i)] =
          !centre.left || centre.p.mesh != grid[a].p.mesh || centre.surface != grid[a].surface ||
          centre.p.bounces != grid[a].p.bounces ||
          glm::length(landing(centre) - mean) > kJumpFraction * spread;
    });
    traced += (long long)check.size();
  }
  for (int j = 0; j < g; ++j)
    for (int i = 0; i < g; ++i) {
      const uint32_t a = uint32_t(j * (g + 1) + i), b = a + 1, c = a + uint32_t(g) + 2, d = a + uint32_t(g) + 1;
      const Traced* corners[4] = {&grid[a], &grid[b], &grid[c], &grid[d]};
      if (consistent(corners) && !jump[size_t(j) * size_t(g) + size_t(i)]) {
        addQuad(m.triangles, a, b, c, d);
        kept_area += dx * dy;
      } else if (s > 1 && (corners[0]->left || corners[1]->left || corners[2]->left || corners[3]->left)) {
        to_refine.push_back({i, j});
      }
    }
  std::vector<Refined> refined(to_refine.size());
  tbb::parallel_for(size_t(0), to_refine.size(), [&](size_t k) {
    refined[k] = refineCell(tr, ap.x0 + to_refine[k].first * dx, ap.y0 + to_refine[k].second * dy, dx, dy, s);
  });
  double lost = 0;
  for (size_t k = 0; k < refined.size(); ++k) {
    const Refined& r = refined[k];
    const uint32_t base = uint32_t(m.vertices.size());
    const double x0 = ap.x0 + to_refine[k].first * dx, y0 = ap.y0 + to_refine[k].second * dy;
    for (int jj = 0; jj <= s; ++jj)
      for (int ii = 0; ii <= s; ++ii) {
        const Traced& t = r.vertices[size_t(jj) * (s + 1) + ii];
        m.vertices.push_back(vertexOf(t, x0 + dx * ii / s, y0 + dy * jj / s));
        land(t, dx * dy / (double(s) * s));
      }
    for (uint32_t idx : r.triangles) m.triangles.push_back(base + idx);
    kept_area += dx * dy / (double(s) * s) * double(r.triangles.size() / 6);
    lost += r.lost_area;
    traced += (long long)r.vertices.size();
  }
  m.lost_fraction = kept_area + lost > 0 ? lost / (kept_area + lost) : 0;
  return m;
}

// The window of receiver r about its landed power, with cells.
void chooseWindow(CausticReceiver& r, const std::vector<std::pair<Vec3, double>>& landed, int cells) {
  const ReceiverRect& full = r.full;
  std::vector<std::pair<Vec2, double>> uv;
  double total = 0;
  for (const auto& [x, w] : landed) {
    const Vec2 q = full.toReceiver(x);
    if (!full.contains(q) || !(w > 0)) continue;
    uv.push_back({q, w});
    total += w;
  }
  r.landed_power = total;
  const std::optional<PowerWindow> window = powerWindow(uv, kWindowQuantile, kWindowScale, kMinWindow_m);
  if (!window) return;
  const Vec2 c = window->centre;
  const double side = window->side_m;
  const double u0 = std::max(c.x - 0.5 * side, -0.5 * full.width_m),
               u1 = std::min(c.x + 0.5 * side, 0.5 * full.width_m);
  const double v0 = std::max(c.y - 0.5 * side, -0.5 * full.height_m),
               v1 = std::min(c.y + 0.5 * side, 0.5 * full.height_m);
  r.window = full;
  r.window.centre = full.toWorld(Vec2(0.5 * (u0 + u1), 0.5 * (v0 + v1)));
  r.window.width_m = u1 - u0;
  r.window.height_m = v1 - v0;
  const double cell = std::max(r.window.width_m, r.window.height_m) / cells;
  r.window.cells_u = std::max(1, int(std::lround(r.window.width_m / cell)));
  r.window.cells_v = std::max(1, int(std::lround(r.window.height_m / cell)));
}

}  // namespace

std::vector<int> causticLights(const Scene& scene) {
  std::vector<int> out;
  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (scene.lights[i].caustics && scene.lights[i].type != Light::Type::Ambient) out.push_back(int(i));
  return out;
}

std::vector<CausticReceiver> planarReceivers(const Scene& scene) {
  std::vector<CausticReceiver> out;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const EnvMesh& mesh = scene.meshes[m];
    if (mesh.triangles.empty() || mesh.normals.size() != mesh.positions.size()) continue;
    const Vec3 n = glm::normalize(Vec3(mesh.normals[0]));
    const Vec3 p0 = Vec3(mesh.positions[0]);
    double extent = 0;
    for (const glm::vec3& p : mesh.positions) extent = std::max(extent, glm::length(Vec3(p) - p0));
    bool planar = extent > 0;
    for (size_t k = 0; k < mesh.positions.size() && planar; ++k)
      planar = glm::dot(glm::normalize(Vec3(mesh.normals[k])), n) >= 1 - kNormalTol &&
               std::abs(glm::dot(Vec3(mesh.positions[k]) - p0, n)) <= kPlaneTol * extent;
    if (!planar) continue;
    const glm::u32vec3 t = mesh.triangles[0];
    Vec3 u = Vec3(mesh.positions[t.y]) - Vec3(mesh.positions[t.x]);
    u = glm::normalize(u - glm::dot(u, n) * n);
    const Vec3 v = glm::cross(n, u);  // so that u x v = n
    double u0 = kInf, u1 = -kInf, v0 = kInf, v1 = -kInf;
    for (const glm::vec3& p : mesh.positions) {
      const Vec3 q = Vec3(p) - p0;
      u0 = std::min(u0, glm::dot(q, u)), u1 = std::max(u1, glm::dot(q, u));
      v0 = std::min(v0, glm::dot(q, v)), v1 = std::max(v1, glm::dot(q, v));
    }
    CausticReceiver r;
    r.mesh = int(m);
    r.surface = int(m);
    r.full.u_axis = u;
    r.full.v_axis = v;
    r.full.centre = mesh.anchor + p0 + 0.5 * (u0 + u1) * u + 0.5 * (v0 + v1) * v;
    r.full.width_m = u1 - u0;
    r.full.height_m = v1 - v0;
    out.push_back(r);
  }
  return out;
}

namespace {

CausticReceiver receiverOver(int mesh, const HeightFieldPlane& plane, bool curved) {
  CausticReceiver r;
  r.mesh = mesh;
  r.surface = mesh;
  r.curved = curved;
  r.full.u_axis = plane.u;
  r.full.v_axis = plane.v;
  r.full.centre = plane.centre;
  r.full.width_m = plane.width_m;
  r.full.height_m = plane.height_m;
  return r;
}

// The meshes that are whole receivers: planar, or height fields over their best-fit plane.
std::vector<bool> wholeReceiverMeshes(const Scene& scene) {
  std::vector<bool> whole(scene.meshes.size(), false);
  for (const CausticReceiver& r : planarReceivers(scene)) whole[size_t(r.mesh)] = true;
  for (const CausticReceiver& r : heightFieldReceivers(scene)) whole[size_t(r.mesh)] = true;
  return whole;
}

}  // namespace

std::vector<CausticReceiver> heightFieldReceivers(const Scene& scene) {
  std::vector<bool> planar(scene.meshes.size(), false);
  for (const CausticReceiver& r : planarReceivers(scene)) planar[size_t(r.mesh)] = true;
  std::vector<CausticReceiver> out;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (planar[m]) continue;
    const std::optional<HeightFieldPlane> plane = heightFieldPlane(scene.meshes[m], nullptr);
    if (plane) out.push_back(receiverOver(int(m), *plane, true));
  }
  return out;
}

std::vector<CausticReceiver> sheetReceivers(const Scene& scene, std::vector<std::string>* unsplit) {
  const std::vector<bool> whole = wholeReceiverMeshes(scene);
  std::vector<CausticReceiver> out;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const EnvMesh& mesh = scene.meshes[m];
    if (whole[m] || mesh.triangles.empty() || mesh.normals.size() != mesh.positions.size()) continue;
    ReceiverSheets sheets = splitIntoSheets(mesh);
    if (sheets.unassigned > 0 && unsplit) unsplit->push_back(mesh.name);
    const auto of = std::make_shared<const std::vector<int>>(std::move(sheets.sheet_of_triangle));
    for (size_t k = 0; k < sheets.planes.size(); ++k) {
      CausticReceiver r = receiverOver(int(m), sheets.planes[k], !sheets.planes[k].planar);
      r.sheet.of_triangle = of;
      r.sheet.index = int(k);
      out.push_back(std::move(r));
    }
  }
  return out;
}

std::vector<float> receiverHeights(const EnvMesh& mesh, const ReceiverRect& w, const ReceiverSheet& sheet) {
  const int nu = w.cells_u, nv = w.cells_v;
  std::vector<double> h(size_t(nu) * size_t(nv), kInf);
  const Vec3 n = w.normal();
  const double cw = w.cellWidth(), ch = w.cellHeight();
  std::vector<Vec3> p(mesh.positions.size());  // (u, v, height) over the window's plane
  for (size_t k = 0; k < p.size(); ++k) {
    const Vec3 d = mesh.anchor + Vec3(mesh.positions[k]) - w.centre;
    p[k] = Vec3(glm::dot(d, w.u_axis), glm::dot(d, w.v_axis), glm::dot(d, n));
  }
  constexpr double kEdge = 1e-9;  // cell centres on a shared edge count for both triangles (same height)
  for (size_t k = 0; k < mesh.triangles.size(); ++k) {
    if (!sheet.holds(int(k))) continue;
    const glm::u32vec3 t = mesh.triangles[k];
    const Vec3 a = p[t.x], b = p[t.y], c = p[t.z];
    const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (area == 0) continue;
    // Cells whose centres lie in the triangle's bounding box (cell centre i: -w/2 + (i + 0.5) cw).
    const auto first = [](double x, double lo, double size, int count) {
      return std::clamp(int(std::ceil((x - lo) / size - 0.5)), 0, count);
    };
    const auto last = [](double x, double lo, double size, int count) {
      return std::clamp(int(std::floor((x - lo) / size - 0.5)), -1, count - 1);
    };
    const double lu = -0.5 * w.width_m, lv = -0.5 * w.height_m;
    const int i0 = first(std::min({a.x, b.x, c.x}), lu, cw, nu), i1 = last(std::max({a.x, b.x, c.x}), lu, cw, nu);
    const int j0 = first(std::min({a.y, b.y, c.y}), lv, ch, nv), j1 = last(std::max({a.y, b.y, c.y}), lv, ch, nv);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const Vec2 x = w.cellCentre(i, j);
        const double w0 = ((b.x - x.x) * (c.y - x.y) - (b.y - x.y) * (c.x - x.x)) / area;
        const double w1 = ((c.x - x.x) * (a.y - x.y) - (c.y - x.y) * (a.x - x.x)) / area;
        const double w2 = 1 - w0 - w1;
        if (w0 < -kEdge || w1 < -kEdge || w2 < -kEdge) continue;
        h[size_t(j) * size_t(nu) + size_t(i)] = w0 * a.z + w1 * b.z + w2 * c.z;
      }
  }
  // Two rings of uncovered cells take the mean of their covered neighbours (8-connected).
  for (int ring = 0; ring < 2; ++ring) {
    std::vector<double> next = h;
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        if (std::isfinite(h[size_t(j) * size_t(nu) + size_t(i)])) continue;
        double sum = 0;
        int count = 0;
        for (int dj = -1; dj <= 1; ++dj)
          for (int di = -1; di <= 1; ++di) {
            const int ii = i + di, jj = j + dj;
            if (ii < 0 || jj < 0 || ii >= nu || jj >= nv) continue;
            const double v = h[size_t(jj) * size_t(nu) + size_t(ii)];
            if (std::isfinite(v)) sum += v, ++count;
          }
        if (count) next[size_t(j) * size_t(nu) + size_t(i)] = sum / count;
      }
    h.swap(next);
  }
  std::vector<float> out(h.size());
  for (size_t k = 0; k < h.size(); ++k) out[k] = std::isfinite(h[k]) ? float(h[k]) : kNoHeight;
  return out;
}

CausticPlan planCaustics(const RayScene& rays, const CausticPlanOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  if (o.grid < 1 || o.grid > 1024 || o.refine < 1 || o.refine > 64 || o.cells < 4 || o.cells > 4096)
    throw Error("caustics: photon grid, refinement or map cells out of range");
  const Scene& scene = rays.scene();
  CausticPlan plan;
  CausticOptions co;
  co.dispersion = o.dispersion;
  co.spectral_samples = o.spectral_samples;
  const std::vector<SpectralSample> samples = causticSamples(scene, co);
  const bool spectral = o.dispersion == DispersionMode::Spectral;
  std::vector<CausticReceiver> candidates = planarReceivers(scene);
  for (CausticReceiver& r : heightFieldReceivers(scene)) candidates.push_back(std::move(r));
  // Meshes that are neither planar nor height fields: their sheets, with ids after the meshes'.
  Surfaces surfaces;
  surfaces.split.assign(scene.meshes.size(), nullptr);
  surfaces.base.assign(scene.meshes.size(), -1);
  surfaces.count = int(scene.meshes.size());
  std::vector<std::string> unsplit;
  const size_t whole_count = candidates.size();
  for (CausticReceiver& r : sheetReceivers(scene, &unsplit)) candidates.push_back(std::move(r));
  std::vector<int> sheet_count(scene.meshes.size(), 0);
  for (size_t k = whole_count; k < candidates.size(); ++k) {
    CausticReceiver& r = candidates[k];
    if (!surfaces.split[size_t(r.mesh)]) {
      surfaces.split[size_t(r.mesh)] = r.sheet.of_triangle;
      surfaces.base[size_t(r.mesh)] = surfaces.count - r.sheet.index;
    }
    r.surface = surfaces.count++;
    ++sheet_count[size_t(r.mesh)];
  }
  std::vector<bool> curved_surface(size_t(surfaces.count), false);
  for (const CausticReceiver& r : candidates) curved_surface[size_t(r.surface)] = r.curved;
  // Per surface, then per mesh for a split mesh's triangles in no sheet.
  Landings landed(size_t(surfaces.count) + scene.meshes.size());
  for (const int li : causticLights(scene)) {
    const Light& light = scene.lights[size_t(li)];
    for (size_t ei = 0; ei < scene.elements.size(); ++ei) {
      CausticAperture ap;
      std::string why;
      if (!causticAperture(scene, light, scene.elements[ei], ap, why)) {
        plan.notes.push_back("light " + std::to_string(li) + ", element \"" + scene.elements[ei].name +
                             "\": skipped, " + why);
        continue;
      }
      for (size_t si = 0; si < samples.size(); ++si) {
        const PairTracer tr{rays, light, ap, samples[si], int(ei), spectral, o.max_depth, surfaces};
        CausticMesh m = tracePair(tr, o, curved_surface, landed, plan.traced);
        if (m.triangles.empty()) {
          if (si == 0)
            plan.notes.push_back("light " + std::to_string(li) + ", element \"" + scene.elements[ei].name +
                                 "\": no light reaches it and leaves it");
          continue;
        }
        m.light = li;
        m.element = int(ei);
        m.sample = int(si);
        m.anchor = Vec3(scene.elements[ei].local_to_world[3]);
        plan.meshes.push_back(std::move(m));
      }
    }
  }
  std::vector<bool> is_receiver(size_t(surfaces.count), false);
  for (CausticReceiver& r : candidates) {
    is_receiver[size_t(r.surface)] = true;
    chooseWindow(r, landed[size_t(r.surface)], o.cells);
  }
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (sheet_count[m] > 0) {
      int lit = 0;
      for (size_t k = whole_count; k < candidates.size(); ++k)
        if (candidates[k].mesh == int(m) && candidates[k].landed_power > 0) ++lit;
      if (lit > 0)
        plan.notes.push_back("mesh \"" + scene.meshes[m].name + "\" is not one sheet over a plane: split into " +
                             std::to_string(sheet_count[m]) + " sheets, " + std::to_string(lit) + " of them lit");
    }
    if ((!is_receiver[m] && !landed[m].empty()) || !landed[size_t(surfaces.count) + m].empty())
      plan.notes.push_back("mesh \"" + scene.meshes[m].name +
                           "\" receives caustic light on triangles in no planar or height-field sheet: not drawn "
                           "there");
  }
  // By landed power; stable, so that equal powers keep the planar receivers' order.
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const CausticReceiver& a, const CausticReceiver& b) { return a.landed_power > b.landed_power; });
  for (CausticReceiver& r : candidates) {
    if (!(r.landed_power > 0)) break;
    if (int(plan.receivers.size()) == kMaxCausticReceivers) {
      plan.notes.push_back("mesh \"" + scene.meshes[size_t(r.mesh)].name + "\"" +
                           (r.sheet.whole() ? std::string() : " sheet " + std::to_string(r.sheet.index)) +
                           ": not drawn, more than " +
                           std::to_string(kMaxCausticReceivers) + " receivers");
      continue;
    }
    if (r.curved) r.height = receiverHeights(scene.meshes[size_t(r.mesh)], r.window, r.sheet);
    plan.receivers.push_back(r);
  }
  plan.elapsed_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return plan;
}

std::optional<CausticLightField> referenceCaustics(const RayScene& rays, const CausticPlanOptions& plan_options,
                                                   int photons_per_side, FrameStages& stages) {
  if (causticLights(rays.scene()).empty()) {
    stages.skipped(kReferenceCausticsStage, "no light has \"caustics\": true");
    return std::nullopt;
  }
  const auto start = std::chrono::steady_clock::now();
  const CausticPlan plan = planCaustics(rays, plan_options);
  std::vector<CausticReceiverMap> windows;
  for (const CausticReceiver& r : plan.receivers)
    windows.push_back({r.mesh, IrradianceGrid::zeros(r.window), r.height, r.sheet});
  CausticOptions o;
  o.photons_per_side = photons_per_side;
  o.max_depth = plan_options.max_depth;
  o.dispersion = plan_options.dispersion;
  o.spectral_samples = plan_options.spectral_samples;
  CausticLightField field = causticLightField(rays, windows, o);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::string note = std::to_string(field.emitted) + " photons (" + std::to_string(photons_per_side) + "^2 per light, element and " +
                     "wavelength sample, " + std::to_string(field.samples_per_photon) + " sample(s)) on " +
                     std::to_string(windows.size()) + " receiver window(s) of the raster plan; lenses block the caustic "
                     "lights' shadow rays";
  for (const std::string& n : plan.notes) note += "; " + n;
  if (windows.empty()) note = "no caustic light lands on a planar or height-field receiver: none added; " + note;
  stages.ran(kReferenceCausticsStage, ms, int(std::min<long long>(field.emitted, 2147483647LL)), note);
  return field;
}

}  // namespace pvrr
