#include "app/compare_caustics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pvrr/analysis/accuracy.h"
#include "pvrr/analysis/caustic_metrics.h"
#include "pvrr/base/image.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/trace/light_tracer.h"

namespace pvrr::app {

using nlohmann::json;

namespace {

// The reference's photons per side: its default (within 0.1 % of 1024^2 inside the spot, docs/caustics.md).
constexpr int kReferencePhotons = 512;
// The heat map: each panel this many pixels on its longer side; the difference panel magnified this much.
constexpr int kPanel = 256, kGap = 8;
constexpr double kDifferenceGain = 10;

void drawPanel(ImageRGB8& img, int x0, const IrradianceGrid& g, const std::vector<double>& values, double scale) {
  const ReceiverRect& r = g.rect;
  const int side = std::max(r.cells_u, r.cells_v);
  for (int y = 0; y < kPanel; ++y)
    for (int x = 0; x < kPanel; ++x) {
      const int i = x * side / kPanel, j = (kPanel - 1 - y) * side / kPanel;  // +v up
      if (i >= r.cells_u || j >= r.cells_v) continue;
      const Vec3 c = errorHeatColour(values[g.index(i, j)] / scale);
      uint8_t* p = img.at(x0 + x, y);
      for (int k = 0; k < 3; ++k) p[k] = uint8_t(std::lround(255 * std::clamp(c[k], 0.0, 1.0)));
    }
}

void writeCausticHeatMap(const std::string& path, const IrradianceGrid& raster, const IrradianceGrid& ref,
                         double peak) {
  ImageRGB8 img(3 * kPanel + 2 * kGap, kPanel);
  const std::vector<double> r = raster.scalars(), f = ref.scalars();
  std::vector<double> d(r.size());
  for (size_t k = 0; k < d.size(); ++k) d[k] = kDifferenceGain * std::abs(r[k] - f[k]);
  drawPanel(img, 0, ref, f, peak);
  drawPanel(img, kPanel + kGap, raster, r, peak);
  drawPanel(img, 2 * (kPanel + kGap), raster, d, peak);
  writePngAtomic(path, img);
}

json vec2mm(const Vec2& v) { return json::array({1e3 * v.x, 1e3 * v.y}); }

}  // namespace

nlohmann::json compareCaustics(LoadedScene& ls, const std::string& gl_name, const std::string& out_dir) {
  if (causticLights(ls.scene).empty()) return nullptr;
  RenderSession session;
  session.seen_points = false;
  renderFrame(ls, RenderMode::Raster, gl_name, &session);
  const std::vector<gl::CausticMap> maps = session.renderer->causticMaps();
  json out = {{"what",
               "raster caustic maps (the same in every raster mode) against the reference's light tracer "
               "on the same cells; the spot: the reference's cells at or above half its peak"},
              {"reference_photons_per_side", kReferencePhotons},
              {"plan_notes", session.renderer->causticPlan().notes},
              {"receivers", json::array()}};
  if (maps.empty()) return out;
  CausticOptions o;
  o.photons_per_side = kReferencePhotons;
  o.dispersion = ls.scene.render.dispersion;
  o.spectral_samples = ls.scene.render.spectral_samples;
  const PhotonBundle bundle = shootCausticPhotons(*session.rays, o);
  for (const gl::CausticMap& m : maps) {
    // A sheet of a split mesh (a box's face) is named with its index.
    const std::string name =
        ls.scene.meshes[size_t(m.mesh)].name + (m.sheet.whole() ? std::string() : "-sheet" + std::to_string(m.sheet.index));
    DepositOptions d;
    d.mesh = m.mesh;
    d.height_field = !m.height.empty();  // a curved receiver: irradiance per unit area of its surface
    d.sheet = m.sheet;                   // a sheet: only the photons hitting its triangles
    const IrradianceGrid ref = depositPhotons(bundle, m.grid.rect, d).grid;
    json j = {{"receiver", name},
              {"cells", {m.grid.rect.cells_u, m.grid.rect.cells_v}},
              {"cell_mm", 1e3 * m.grid.rect.cellWidth()}};
    if (!spotMetrics(ref).found) {
      j["note"] = "no reference caustic light on these cells";
      out["receivers"].push_back(j);
      continue;
    }
    const IrradianceComparison c = compareIrradiance(m.grid, ref);
    j["peak_irradiance_w_m2"] = {{"raster", c.test.peak_irradiance}, {"reference", c.reference.peak_irradiance}};
    j["focus_uv_mm"] = {{"raster", vec2mm(c.test.peak_uv_m)}, {"reference", vec2mm(c.reference.peak_uv_m)}};
    j["peak_distance_mm"] = 1e3 * c.peak_distance_m;
    j["centroid_distance_mm"] = 1e3 * c.centroid_distance_m;
    j["relative_l1_in_spot"] = c.relative_l1_in_spot;
    j["spot_cells"] = c.reference.spot_cells;
    j["power_ratio"] = c.power_ratio;
    const std::string png = "caustic-" + name + ".png";
    writeCausticHeatMap(out_dir + "/" + png, m.grid, ref, c.reference.peak_irradiance);
    j["heat_map"] = png + ": reference | raster | |raster - reference| x 10, 0 to the reference's peak";
    std::printf(
        "caustic on %s: peak %.4g W/m^2 (reference %.4g), focus %.3f mm from the reference's, relative L1 "
        "in the spot %.2f %% (%d cells), power ratio %.4f\n",
        name.c_str(), c.test.peak_irradiance, c.reference.peak_irradiance, 1e3 * c.peak_distance_m,
        100 * c.relative_l1_in_spot, c.reference.spot_cells, c.power_ratio);
    out["receivers"].push_back(j);
  }
  return out;
}

}  // namespace pvrr::app
