// The reference's caustics (pvrr/trace/light_tracer.h) against paraxial optics and energy conservation:
// a thin lens in a directional light focuses at its paraxial focal distance, the power through its aperture is
// conserved up to the Fresnel losses, a concave mirror's spot lies at R/2. Figures: docs/caustics.md.
#include "pvrr/trace/light_tracer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "cad/lens.h"
#include "pvrr/base/error.h"
#include "pvrr/optics/optics.h"
#include "pvrr/optics/spectrum.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// The lens: symmetric biconvex, R = 0.5 m, n = 1.5 (constant), 3 mm thick, 40 mm round, vertex at the origin
// facing +z; the sun travels along -z. Thin-lens (lensmaker) focal length (n - 1)(2/R) = 1/0.5 m.
constexpr double kLensR = 0.5, kLensN = 1.5, kLensT = 0.003, kLensD = 0.04;
// The mirror: concave sphere R = -1 m (centre 1 m in front), 100 mm round, reflectance 0.9; focus at R/2.
constexpr double kMirrorR = 1.0, kMirrorD = 0.1, kMirrorRefl = 0.9;

// A scene with only the element and, far off to the side, one small quad (the scene needs an environment).
Scene bareScene() {
  Scene s;
  s.name = "caustic-test";
  s.observer.eye = Vec3(0, 0, 2);
  s.observer.target = Vec3(0);
  EnvMesh far = makeQuadMesh(Vec3(5, 0, -5), Vec3(0, 0, 1), Vec3(0, 1, 0), 0.1, 0.1);
  s.meshes.push_back(far);
  s.materials.push_back(DiffuseMaterial{});
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = Vec3(0, 0, -1);
  sun.radiance = Vec3(1.0);  // 1 W/m^2 facing the light
  s.lights = {sun};
  return s;
}

Scene lensScene(const Dispersion& glass = Dispersion::constant(kLensN)) {
  Scene s = bareScene();
  const cad::Outline disc = cad::Outline::circle(kLensD);
  Element e;
  e.name = "lens";
  e.type = ElementType::Lens;
  e.lens = cad::makeLens(cad::makeSphere(kLensR, disc), cad::makeSphere(-kLensR, disc), disc, kLensT, 0.0, "lens");
  e.outline = disc;
  e.local_to_world = test::pose(Vec3(0), Vec3(0, 0, 1));
  e.world_to_local = glm::inverse(e.local_to_world);
  e.dispersion = glass;
  e.tess_u = e.tess_v = 24;
  s.elements.push_back(e);
  s.updateBounds();
  return s;
}

Scene mirrorScene() {
  Scene s = bareScene();
  const cad::Outline disc = cad::Outline::circle(kMirrorD);
  test::addMirror(s, cad::makeSphere(-kMirrorR, disc), disc, test::pose(Vec3(0), Vec3(0, 0, 1)), 7, kMirrorRefl);
  s.updateBounds();
  return s;
}

// The back focal distance of a thick lens in air (paraxial; light entering the R1 surface): with surface powers
// F1 = (n - 1)/R1, F2 = (1 - n)/R2 and F = F1 + F2 - (t/n) F1 F2, BFD = (1 - (t/n) F1)/F.
double backFocalDistance(double n, double r1, double r2, double t) {
  const double f1 = (n - 1) / r1, f2 = (1 - n) / r2;
  const double f = f1 + f2 - t / n * f1 * f2;
  return (1 - t / n * f1) / f;
}

// The image distance behind the back vertex of an axial point `object_m` before the front vertex, by a paraxial
// (y, n u) ray trace: refraction n'u' = n u - y F at each surface, transfer y += (t/n) n u.
double imageDistance(double n, double r1, double r2, double t, double object_m) {
  const double f1 = (n - 1) / r1, f2 = (1 - n) / r2;
  const double u0 = 1e-3, y1 = object_m * u0;
  const double w1 = u0 - y1 * f1, y2 = y1 + t / n * w1, w2 = w1 - y2 * f2;
  return -y2 / w2;
}

// A small receiver square in the plane z = z, on the axis, facing +z.
ReceiverRect axialReceiver(double z, double size_m, int cells) {
  ReceiverRect r;
  r.centre = Vec3(0, 0, z);
  r.u_axis = Vec3(1, 0, 0);
  r.v_axis = Vec3(0, 1, 0);
  r.width_m = r.height_m = size_m;
  r.cells_u = r.cells_v = cells;
  return r;
}

// The brightest cell's irradiance: the scalar (channel < 0) or one channel.
double peakOf(const IrradianceGrid& g, int channel = -1) {
  double peak = 0;
  for (size_t k = 0; k < g.irradiance.size(); ++k) {
    const Vec3& e = g.irradiance[k];
    peak = std::max(peak, channel < 0 ? (e.x + e.y + e.z) / 3 : e[channel]);
  }
  return peak;
}

// The plane z in [z0, z1] (steps of dz) whose brightest cell is brightest.
double sweepPeak(const PhotonBundle& b, double z0, double z1, double dz, double size_m, int cells, int channel = -1) {
  DepositOptions plane;
  plane.mode = DepositOptions::Mode::Plane;
  double best_z = z0, best = -1;
  for (double z = z0; z <= z1 + 0.5 * dz; z += dz) {
    const double p = peakOf(depositPhotons(b, axialReceiver(z, size_m, cells), plane).grid, channel);
    if (p > best) best = p, best_z = z;
  }
  return best_z;
}

// Receiver cells of 0.1 mm: the blur diameter the sweep resolves.
constexpr double kCell = 1e-4;
constexpr int kCells = 60;

TEST(LightTracer, ThinLensFocusesAtItsParaxialFocalDistance) {
  Scene s = lensScene();
  RayScene rays(s);
  CausticOptions o;
  o.photons_per_side = 200;
  const PhotonBundle b = shootCausticPhotons(rays, o);
  ASSERT_GT(b.photons.size(), 0u);
  const double bfd = backFocalDistance(kLensN, kLensR, -kLensR, kLensT);
  const double z_paraxial = -kLensT - bfd;
  // The lensmaker's thin-lens focal length for scale: the thick lens's BFD differs from it by t-terms only.
  const double f_thin = 1.0 / ((kLensN - 1) * (2.0 / kLensR));
  EXPECT_NEAR(bfd, f_thin, 0.01 * f_thin);
  const double z_peak = sweepPeak(b, z_paraxial - 0.01, z_paraxial + 0.01, 2.5e-4, kCells * kCell, kCells);
  // Depth of focus: the axial range over which the geometric blur of an aberration-free cone of f-number
  // N = f/D stays below the receiver's cell (its resolution), +-N c, widened by the lens's longitudinal
  // spherical aberration (the axial caustic from the paraxial to the marginal focus lies before the paraxial
  // focus; third order for an equiconvex n = 1.5 lens: 1.67 h^2/f at marginal height h = D/2, ~1.3 mm here).
  const double n_number = bfd / kLensD;
  const double lsa = 1.67 * (0.5 * kLensD) * (0.5 * kLensD) / bfd;
  const double depth_of_focus = n_number * kCell + lsa;
  std::printf(
      "lens: paraxial BFD %.4f m, peak %.4f m behind the back vertex (error %.2f mm; depth of focus "
      "%.2f mm), %lld photons, %.0f ms\n",
      bfd, -kLensT - z_peak, 1e3 * (z_paraxial - z_peak), 1e3 * depth_of_focus, b.emitted, b.elapsed_ms);
  EXPECT_LE(std::abs(z_peak - z_paraxial), depth_of_focus);
}

TEST(LightTracer, PowerThroughTheLensIsConservedUpToFresnelLosses) {
  Scene s = lensScene();
  RayScene rays(s);
  CausticOptions o;
  o.photons_per_side = 200;
  const PhotonBundle b = shootCausticPhotons(rays, o);
  // Accounting: the sun's irradiance (1 W/m^2) times the aperture's area facing it is what enters; what leaves
  // is that times the two interfaces' transmittance (1 - R0)^2 at normal incidence (R0 = ((n-1)/(n+1))^2; the
  // incidence angles stay under 2.5 deg over this aperture, where 1 - R changes by < 1e-5); nothing is absorbed
  // (non-absorbing glass, no edge band crossed, no TIR). All of it lands on a large enough screen.
  const double area = kPi * 0.25 * kLensD * kLensD;
  const double t = 1 - normalIncidenceReflectance(1.0, kLensN);
  // The bound on power conservation.
  constexpr double kPowerTol = 0.02;
  EXPECT_NEAR(b.entering_power.y / area, 1.0, kPowerTol);
  EXPECT_EQ(b.absorbed, 0);
  EXPECT_NEAR(b.leaving_power.y / (area * t * t), 1.0, kPowerTol);
  DepositOptions plane;
  plane.mode = DepositOptions::Mode::Plane;
  const CausticResult r = depositPhotons(b, axialReceiver(-0.3, 0.05, 100), plane);
  EXPECT_EQ(r.deposited, (long long)b.photons.size());
  EXPECT_NEAR(r.grid.power().y / (area * t * t), 1.0, kPowerTol);
  std::printf(
      "lens power: entering %.5f of E A, leaving %.5f of E A (1-R0)^2, on the grid %.5f; rel. stderr at the "
      "peak %.3f\n",
      b.entering_power.y / area, b.leaving_power.y / (area * t * t), r.grid.power().y / (area * t * t),
      r.peak_rel_stderr);
}

TEST(LightTracer, ConcaveMirrorSpotLiesAtHalfItsRadius) {
  Scene s = mirrorScene();
  RayScene rays(s);
  CausticOptions o;
  o.photons_per_side = 200;
  const PhotonBundle b = shootCausticPhotons(rays, o);
  const double z_paraxial = 0.5 * kMirrorR;
  const double z_peak = sweepPeak(b, z_paraxial - 0.01, z_paraxial + 0.01, 2.5e-4, kCells * kCell, kCells);
  // Depth of focus as for the lens: +-N c, widened by the mirror's longitudinal spherical aberration (exact:
  // the marginal ray at h = D/2 crosses the axis R/2 (1/cos(theta) - 1) before the paraxial focus, sin = h/R).
  const double h = 0.5 * kMirrorD;
  const double lsa = 0.5 * kMirrorR * (1 / std::sqrt(1 - h * h / (kMirrorR * kMirrorR)) - 1);
  const double depth_of_focus = z_paraxial / kMirrorD * kCell + lsa;
  std::printf("mirror: R/2 %.4f m, peak %.4f m (error %.2f mm; depth of focus %.2f mm)\n", z_paraxial, z_peak,
              1e3 * (z_peak - z_paraxial), 1e3 * depth_of_focus);
  EXPECT_LE(std::abs(z_peak - z_paraxial), depth_of_focus);
  // Power: the reflectance times the aperture facing the light.
  constexpr double kPowerTol = 0.02;
  const double area = kPi * 0.25 * kMirrorD * kMirrorD;
  EXPECT_NEAR(b.leaving_power.y / (area * kMirrorRefl), 1.0, kPowerTol);
}

// The irradiance itself, not only its total: a plane delta before the paraxial focus holds a disc of light whose
// centre (the paraxial rays) has the irradiance E T (f/delta)^2, T the two faces' transmittance, f the equivalent
// focal length (the distance from the rear principal plane to the focus).
TEST(LightTracer, DefocusedDiscHasTheParaxialIrradiance) {
  Scene s = lensScene();
  RayScene rays(s);
  CausticOptions o;
  o.photons_per_side = 300;
  const PhotonBundle b = shootCausticPhotons(rays, o);
  const double n = kLensN, f1 = (n - 1) / kLensR, f2 = f1;
  const double f = 1 / (f1 + f2 - kLensT / n * f1 * f2);
  const double delta = 0.05;
  const double z = -kLensT - backFocalDistance(n, kLensR, -kLensR, kLensT) + delta;
  DepositOptions plane;
  plane.mode = DepositOptions::Mode::Plane;
  // Cells of 0.05 mm over the central 0.5 mm: rays within h < 6.3 mm of the axis, where spherical aberration
  // raises the irradiance by under 1.1 % (third order: E/E_0 = 1 / ((1 - k h^2/delta)(1 - 3 k h^2/delta)),
  // k h^2 = 1.67 h^2/f).
  const CausticResult r = depositPhotons(b, axialReceiver(z, 0.0005, 10), plane);
  double sum = 0;
  for (double e : r.grid.scalars()) sum += e;
  const double mean = sum / double(r.grid.irradiance.size());
  const double t = 1 - normalIncidenceReflectance(1.0, kLensN);
  const double expected = t * t * (f / delta) * (f / delta);
  // 1.1 % of aberration, and the estimate's noise: about 1300 photons land here, stratified (well under the
  // 2.8 % of independent ones).
  constexpr double kDiscTol = 0.03;
  EXPECT_NEAR(mean / expected, 1.0, kDiscTol);
  std::printf("defocused disc: centre irradiance %.2f W/m^2, paraxial %.2f W/m^2 (ratio %.4f), %lld photons there\n",
              mean, expected, mean / expected, r.deposited);
}

// Dispersion: in the rgb mode each channel focuses at the paraxial BFD of its own line's index (C, d, F), blue
// nearest the lens: a coloured caustic. Abbe V_d = 20 (a strongly dispersing glass) spreads the foci by
// f/V_d = 25 mm, far more than the depth of focus.
TEST(LightTracer, DispersionFocusesEachChannelAtItsOwnIndex) {
  const Dispersion glass = Dispersion::fromAbbe(kLensN, 20);
  Scene s = lensScene(glass);
  RayScene rays(s);
  CausticOptions o;
  o.photons_per_side = 160;
  o.dispersion = DispersionMode::Rgb;
  const PhotonBundle b = shootCausticPhotons(rays, o);
  EXPECT_EQ(b.samples_per_photon, 3);
  const double lsa = 1.67 * (0.5 * kLensD) * (0.5 * kLensD) / 0.5;
  double z_peak[3];
  for (int c = 0; c < 3; ++c) {
    const double bfd = backFocalDistance(glass.index(kRgbWavelengths_nm[c]), kLensR, -kLensR, kLensT);
    const double z_paraxial = -kLensT - bfd;
    z_peak[c] = sweepPeak(b, z_paraxial - 0.006, z_paraxial + 0.006, 2.5e-4, kCells * kCell, kCells, c);
    EXPECT_LE(std::abs(z_peak[c] - z_paraxial), bfd / kLensD * kCell + lsa) << "channel " << c;
  }
  EXPECT_LT(z_peak[0], z_peak[1]);  // red focuses farthest from the lens (z more negative)
  EXPECT_LT(z_peak[1], z_peak[2]);
  // Each channel's weight is 1 on its own sample: each channel's power is conserved on its own.
  const double area = kPi * 0.25 * kLensD * kLensD;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(b.entering_power[c] / area, 1.0, 0.02) << "channel " << c;
}

// A point light 1.5 m before the lens images at 1/(1/f - 1/s) behind it, and the lens intercepts the light's
// intensity times the solid angle of its rim circle.
TEST(LightTracer, PointLightImagesThroughTheLens) {
  Scene s = lensScene();
  const double dist = 1.5;
  s.lights[0].type = Light::Type::Point;
  s.lights[0].position = Vec3(0, 0, dist);
  s.lights[0].radiance = Vec3(1.0);  // 1 W/sr
  s.updateBounds();
  RayScene rays(s);
  CausticOptions o;
  o.photons_per_side = 200;
  const PhotonBundle b = shootCausticPhotons(rays, o);
  const double s_img = imageDistance(kLensN, kLensR, -kLensR, kLensT, dist);
  const double z_paraxial = -kLensT - s_img;
  const double f = backFocalDistance(kLensN, kLensR, -kLensR, kLensT);
  const double z_peak = sweepPeak(b, z_paraxial - 0.01, z_paraxial + 0.01, 2.5e-4, kCells * kCell, kCells);
  // Depth of focus as above: the cone's N = s'/D times the cell, and the spherical aberration, whose
  // longitudinal extent grows as the square of the image distance (third order, the same lens bending).
  const double lsa = 1.67 * (0.5 * kLensD) * (0.5 * kLensD) / f * (s_img / f) * (s_img / f);
  EXPECT_LE(std::abs(z_peak - z_paraxial), s_img / kLensD * kCell + lsa);
  // The rim circle (radius D/2) lies the front sag below the vertex plane.
  const double rim_z = -(kLensR - std::sqrt(kLensR * kLensR - 0.25 * kLensD * kLensD));
  const double d_rim = dist - rim_z, r = 0.5 * kLensD;
  const double solid_angle = 2 * kPi * (1 - d_rim / std::sqrt(d_rim * d_rim + r * r));
  EXPECT_NEAR(b.entering_power.y / solid_angle, 1.0, 0.02);
  std::printf("point light: image %.4f m behind the back vertex, peak at %.4f m; intercepted %.5f of I omega\n",
              -kLensT - z_paraxial, -kLensT - z_peak, b.entering_power.y / solid_angle);
}

// Deposits on a real surface (a quad at the receiver's plane, the first thing the photons meet) and on the
// virtual plane agree; an occluder upstream of half the lens takes half the power away.
TEST(LightTracer, SurfaceReceiverMatchesThePlaneAndOccludersBlock) {
  Scene s = lensScene();
  const double z = -0.3;
  EnvMesh screen = makeQuadMesh(Vec3(0, 0, z), Vec3(0, 0, 1), Vec3(0, 1, 0), 0.2, 0.2);
  s.meshes.push_back(screen);
  s.updateBounds();
  {
    RayScene rays(s);
    CausticOptions o;
    o.photons_per_side = 100;
    const PhotonBundle b = shootCausticPhotons(rays, o);
    DepositOptions plane, surfaces;
    plane.mode = DepositOptions::Mode::Plane;
    surfaces.mesh = 1;
    const ReceiverRect rect = axialReceiver(z, 0.05, 50);
    const CausticResult a = depositPhotons(b, rect, plane), c = depositPhotons(b, rect, surfaces);
    EXPECT_EQ(a.deposited, c.deposited);
    // The exact hit on the quad and the analytic plane agree to the exact-hit precision, far below a cell.
    constexpr double kSameTol = 1e-9;
    for (size_t k = 0; k < a.grid.irradiance.size(); ++k)
      ASSERT_NEAR(a.grid.irradiance[k].y, c.grid.irradiance[k].y, kSameTol * (1 + a.grid.irradiance[k].y));
  }
  // A box above the lens covering x > 0 (upstream of the sun on that half).
  s.meshes.push_back(makeBoxMesh(Vec3(0.05, 0, 0.2), Vec3(0.1, 0.1, 0.02), Mat3(1.0)));
  s.updateBounds();
  RayScene rays(s);
  CausticOptions o;
  o.photons_per_side = 100;
  const PhotonBundle b = shootCausticPhotons(rays, o);
  const double area = kPi * 0.25 * kLensD * kLensD;
  EXPECT_NEAR(b.entering_power.y / (0.5 * area), 1.0, 0.02);
}

// The same seed gives the same photons; another seed other jitters with the same totals.
TEST(LightTracer, SeedingIsDeterministic) {
  Scene s = lensScene();
  RayScene rays(s);
  CausticOptions o;
  o.photons_per_side = 64;
  const PhotonBundle a = shootCausticPhotons(rays, o), b = shootCausticPhotons(rays, o);
  ASSERT_EQ(a.photons.size(), b.photons.size());
  for (size_t k = 0; k < a.photons.size(); ++k) ASSERT_EQ(a.photons[k].direction, b.photons[k].direction);
  o.seed = 2;
  const PhotonBundle c = shootCausticPhotons(rays, o);
  ASSERT_FALSE(c.photons.empty());
  EXPECT_NE(c.photons[0].origin, a.photons[0].origin);
  EXPECT_NEAR(c.entering_power.y / a.entering_power.y, 1.0, 0.02);
}

TEST(LightTracer, RefusesBadOptions) {
  Scene s = lensScene();
  RayScene rays(s);
  CausticOptions o;
  o.photons_per_side = 0;
  EXPECT_THROW(shootCausticPhotons(rays, o), Error);
  o.photons_per_side = 8;
  o.element = 3;
  EXPECT_THROW(shootCausticPhotons(rays, o), Error);
  ReceiverRect r;
  r.cells_u = 0;
  EXPECT_THROW(depositPhotons(PhotonBundle{}, r, DepositOptions{}), Error);
}

}  // namespace
}  // namespace pvrr
