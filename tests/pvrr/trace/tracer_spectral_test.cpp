// The tracer's dispersion modes: spectral integration against the RGB and off modes, chromatic spread
// through a dispersive lens, and metal mirrors reflecting their measured (n, k) per wavelength.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "cad/lens.h"
#include "pvrr/optics/optics.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/optics/spectrum.h"
#include "pvrr/trace/tracer.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// The spectral sum of N equal colours with weights summing to (1, 1, 1) (spectrum.h) reproduces the colour
// up to the rounding of N products and sums: a few ulps of values ~1. 1e-12 leaves room for N = 16..64.
constexpr double kWhiteTol = 1e-12;

TraceOptions mode(DispersionMode m, int samples = 16) {
  TraceOptions o;
  o.dispersion = m;
  o.spectral_samples = samples;
  return o;
}

// A room, the observer looking at a plane mirror tilted 30 degrees about y (oblique incidence, so that the
// conductor Fresnel is not just its normal-incidence value).
Scene mirrorScene(int width = 24, int height = 18) {
  Scene s = test::roomScene(Vec3(0.0, 0.1, 1.2), Vec3(0, 0, 0), width, height);
  const cad::Outline o = cad::Outline::rectangle(0.5, 0.4, 0.03);
  test::addMirror(s, cad::makePlane(o), o, test::pose(Vec3(0), Vec3(std::sin(radians(30)), 0, std::cos(radians(30)))));
  s.updateBounds();
  return s;
}

// A dispersive biconvex lens (polycarbonate, V_d = 30) centred in front of the observer.
Scene lensScene(int width = 32, int height = 24) {
  Scene s = test::roomScene(Vec3(0.0, 0.05, 0.6), Vec3(0, 0, 0), width, height);
  const cad::Outline outline = cad::Outline::circle(0.3);
  Element e;
  e.name = "lens";
  e.type = ElementType::Lens;
  e.lens = cad::makeLens(cad::makeSphere(0.35, outline), cad::makeSphere(-0.35, outline), outline, 0.08, 0, "lens");
  e.outline = outline;
  e.local_to_world = test::pose(Vec3(0), Vec3(0, 0, 1));
  e.world_to_local = glm::inverse(e.local_to_world);
  e.dispersion = lookupLensMaterial("polycarbonate").dispersion;
  e.dispersion_on = true;
  s.elements.push_back(e);
  s.updateBounds();
  return s;
}

size_t pixels(const Frame& f) { return size_t(f.width) * size_t(f.height); }

TEST(SpectralMode, WithoutLensesMatchesOffAndRgbModes) {
  // The weights integrate white to white (the normalisation of spectrum.h).
  Vec3 sum(0.0);
  for (const SpectralSample& smp : spectralSamples(16)) sum += smp.rgb_weight;
  EXPECT_LT(glm::length(sum - Vec3(1.0)), kWhiteTol);

  Scene s = mirrorScene();
  RayScene rays(s);
  const Frame off = Tracer(rays, mode(DispersionMode::Off)).render();
  const Frame rgb = Tracer(rays, mode(DispersionMode::Rgb)).render();
  const Frame spec = Tracer(rays, mode(DispersionMode::Spectral)).render();
  int on_mirror = 0;
  for (size_t i = 0; i < pixels(off); ++i) {
    on_mirror += off.element[i] == 0;
    EXPECT_LT(glm::length(spec.color[i] - off.color[i]), kWhiteTol) << i;
    EXPECT_LT(glm::length(rgb.color[i] - off.color[i]), kWhiteTol) << i;
    EXPECT_EQ(spec.seen[i], off.seen[i]);
  }
  EXPECT_GT(on_mirror, 50);
}

TEST(SpectralMode, GreyMetalIntegratesToItsOwnReflectance) {
  // A metal whose table is flat: every spectral sample reflects the same fraction, so the spectral mode,
  // which does integrate this mirror sample by sample, must give the per-channel (off mode) colour.
  Scene s = mirrorScene();
  Element& m = s.elements[0];
  m.mirror.metal = true;
  m.mirror.n = Vec3(1.2);
  m.mirror.k = Vec3(3.1);
  m.mirror.metal_table = std::make_shared<const Metal>(
      Metal("grey", "test", {{380.0, 1.2, 3.1}, {560.0, 1.2, 3.1}, {780.0, 1.2, 3.1}}));
  RayScene rays(s);
  const Frame off = Tracer(rays, mode(DispersionMode::Off)).render();
  const Frame spec = Tracer(rays, mode(DispersionMode::Spectral, 24)).render();
  int on_mirror = 0;
  for (size_t i = 0; i < pixels(off); ++i) {
    on_mirror += off.element[i] == 0;
    EXPECT_LT(glm::length(spec.color[i] - off.color[i]), kWhiteTol) << i;
  }
  EXPECT_GT(on_mirror, 50);
}

TEST(SpectralMode, MetalMirrorReflectsItsTableIntegratedOverWavelength) {
  for (const std::string name : {"silver", "chromium"}) {
    const Metal metal = lookupMetal(name);
    Scene s = mirrorScene();
    Element& m = s.elements[0];
    m.mirror.metal = true;
    m.mirror.n = metal.n_rgb();
    m.mirror.k = metal.k_rgb();
    m.mirror.metal_table = std::make_shared<const Metal>(metal);
    // The same scene with a perfect mirror gives the colour each reflected ray sees.
    Scene perfect = mirrorScene();
    perfect.elements[0].mirror.reflectance = Vec3(1.0);
    RayScene rays(s), perfect_rays(perfect);
    const int samples = 16;
    const Tracer spectral(rays, mode(DispersionMode::Spectral, samples));
    const Tracer off(rays, mode(DispersionMode::Off));
    const Tracer seen(perfect_rays, mode(DispersionMode::Off));
    const std::vector<SpectralSample> weights = spectralSamples(samples);
    int checked = 0;
    double max_spectral_vs_rgb = 0;
    for (int y = 0; y < s.observer.height; ++y)
      for (int x = 0; x < s.observer.width; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const Vec3 d = s.observer.pixelDirection(px, py);
        std::vector<PathSegment> path;
        const TraceResult ref = seen.trace(s.observer.eye, d, 0, &path);
        if (path.empty() || path[0].event != "reflect") continue;
        // Independently: the unpolarised conductor Fresnel at each sample's wavelength and incidence angle,
        // summed with the colour-matching weights.
        const double cos_i = std::abs(glm::dot(path[0].direction, path[0].normal));
        Vec3 expected(0.0);
        for (const SpectralSample& w : weights) {
          const ComplexIndex nk = metal.index(w.wavelength_nm);
          expected += w.rgb_weight * fresnelConductor(cos_i, 1.0, nk.n, nk.k) * ref.color;
        }
        const TraceResult got = spectral.tracePixel(px, py);
        EXPECT_TRUE(got.hit_metal);
        EXPECT_LT(glm::length(got.color - expected), kWhiteTol) << name << " " << px << "," << py;
        max_spectral_vs_rgb = std::max(max_spectral_vs_rgb, glm::length(got.color - off.tracePixel(px, py).color));
        ++checked;
      }
    EXPECT_GE(checked, 50) << name;
    // The integral over the table is not the three-wavelength colour (the test would be vacuous otherwise).
    EXPECT_GT(max_spectral_vs_rgb, 1e-4) << name;
  }
}

TEST(SpectralMode, SceneBuildKeepsTheMetalTable) {
  const SceneDesc desc = loadScene(std::string(PVRR_SOURCE_DIR) + "/models/car-mirror.json", {});
  const Scene s = buildScene(desc);
  ASSERT_FALSE(s.elements.empty());
  const MirrorMaterial& m = s.elements[0].mirror;
  ASSERT_TRUE(m.metal);
  ASSERT_TRUE(m.metal_table);
  EXPECT_EQ(m.metal_table->name(), "chromium");
  EXPECT_EQ(m.n, m.metal_table->n_rgb());
}

TEST(SpectralMode, DispersiveLensSpreadsSeenPointsBetweenTheCAndFLines) {
  Scene s = lensScene();
  RayScene rays(s);
  const Tracer tracer(rays, mode(DispersionMode::Spectral));
  // A ray through the lens well off its axis, where the lateral colour is large.
  const Vec3 eye = s.observer.eye, d = glm::normalize(Vec3(0.1, 0.07, 0) - eye);
  auto finalRay = [&](double lambda_nm, Vec3& seen) {
    std::vector<PathSegment> path;
    seen = tracer.trace(eye, d, lambda_nm, &path).seen;
    EXPECT_GE(path.size(), 3u);
    EXPECT_EQ(path[0].event, "refract");
    return path.back().direction;
  };
  Vec3 seen_c, seen_f;
  const Vec3 out_c = finalRay(kLineC_nm, seen_c), out_f = finalRay(kLineF_nm, seen_f);
  // Blue bends more than red: the F ray is deviated further from the incident direction.
  const double dev_c = std::acos(std::clamp(glm::dot(d, out_c), -1.0, 1.0));
  const double dev_f = std::acos(std::clamp(glm::dot(d, out_f), -1.0, 1.0));
  EXPECT_GT(dev_f, dev_c);
  const Vec3 axis = seen_f - seen_c;
  const double spread = glm::length(axis);
  ASSERT_GT(spread, 1e-4);  // polycarbonate, ~0.1 m off axis: millimetres on the wall
  // Each spectral sample's seen point, as a fraction of the way from the C point to the F point: inside
  // [0, 1] for the wavelengths between the lines, beyond them outside, and monotonic in wavelength.
  double prev = kInf;
  int inside = 0;
  for (const SpectralSample& smp : spectralSamples(16)) {
    Vec3 seen;
    finalRay(smp.wavelength_nm, seen);
    const double f = glm::dot(seen - seen_c, axis) / (spread * spread);
    // Off the C-F line by much less than the spread (the points lie on a nearly straight curve).
    EXPECT_LT(glm::length(seen - seen_c - f * axis), 0.05 * spread) << smp.wavelength_nm;
    const bool between = smp.wavelength_nm > kLineF_nm && smp.wavelength_nm < kLineC_nm;
    if (between) {
      EXPECT_GT(f, 0.0) << smp.wavelength_nm;
      EXPECT_LT(f, 1.0) << smp.wavelength_nm;
      ++inside;
    } else {
      EXPECT_TRUE(f < 0.0 || f > 1.0) << smp.wavelength_nm;
    }
    EXPECT_LT(f, prev) << smp.wavelength_nm;  // longer wavelength: closer to the red end
    prev = f;
  }
  EXPECT_GE(inside, 8);
}

TEST(SpectralMode, LensPixelColourIsCloseToTheRgbModes) {
  Scene s = lensScene(40, 30);
  RayScene rays(s);
  const Frame rgb = Tracer(rays, mode(DispersionMode::Rgb)).render();
  const Frame spec = Tracer(rays, mode(DispersionMode::Spectral)).render();
  // The walls are flat colours under parallel light, so away from colour edges both modes see the same
  // colour times the lens's transmittance; the modes differ only in how T(lambda) = (1 - R)^2 is weighted,
  // a few 1e-3 at most for n = 1.57..1.61. Pixels whose fringes straddle an edge differ by more.
  constexpr double kInteriorTol = 3e-3;
  int lens = 0, close = 0;
  double sum = 0;
  for (size_t i = 0; i < pixels(rgb); ++i) {
    if (rgb.element[i] != 0) continue;
    ++lens;
    const Vec3 diff = glm::abs(spec.color[i] - rgb.color[i]);
    const double m = std::max({diff.x, diff.y, diff.z});
    close += m < kInteriorTol;
    sum += m;
  }
  ASSERT_GT(lens, 100);
  EXPECT_GE(close, lens * 9 / 10);
  EXPECT_LT(sum / lens, 0.01);
}

}  // namespace
}  // namespace pvrr
