// Lens solids: thicknesses from the sag formula, edge-thickness specification, and rejection of surfaces that
// cross or are undefined inside the outline. NURBS surfaces as sag graphs (makeNurbsSag) against analytic
// sags, and the shipped progressive back surface (models/progressive-back.igs) against its generator.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>

#include "cad/cad_import.h"
#include "pvrr/base/error.h"
#include "cad/lens.h"
#include "cad/model_generator.h"
#include "cad/same_model.h"

namespace pvrr::cad {
namespace {

// Thicknesses of ~1e-3 m from sags of ~1e-3 m: roundoff ~1e-18 m; 1e-15 m leaves room for the naive
// reference formula's cancellation.
constexpr double kThicknessAbs = 1e-15;

// Naive sphere sag |R| - sqrt(R^2 - r^2) (magnitude), in long double.
double sagMagnitude(double R, double r) {
  const long double Rl = std::abs(R);
  return double(Rl - std::sqrt(Rl * Rl - (long double)r * r));
}

TEST(Lens, PlusTwoDioptreLensFromRadii) {
  // Equiconvex, n = 1.5: lensmaker P = (n - 1)(1/R1 - 1/R2) = 2 D gives R1 = -R2 = 2 (n - 1) / P = 0.5 m.
  const double n = 1.5, power_d = 2.0;
  const double R1 = 2 * (n - 1) / power_d, R2 = -R1;
  const double diameter = 0.05, edge = 0.001;
  const Outline disc = Outline::circle(diameter);
  // Front bulges towards the eye (+z): R > 0. Back bulges away: centre of curvature in front, R < 0.
  const LensSolid lens = makeLens(makeSphere(R1, disc), makeSphere(R2, disc), disc, 0.0, edge, "plus lens");
  const double s = sagMagnitude(R1, 0.5 * diameter);
  EXPECT_NEAR(lens.centre_thickness, edge + 2 * s, kThicknessAbs);
  EXPECT_NEAR(lens.thicknessAt(0, 0), lens.centre_thickness, kThicknessAbs);
  EXPECT_NEAR(lens.edgeThicknessMin(), edge, kThicknessAbs);
  EXPECT_NEAR(lens.minimumThickness(), edge, kThicknessAbs);
  EXPECT_EQ(lens.front->zVertex(), 0.0);
  EXPECT_EQ(lens.back->zVertex(), -lens.centre_thickness);
  // Half way out: thickness = t_c - 2 sag(r).
  EXPECT_NEAR(lens.thicknessAt(0.01, -0.005), lens.centre_thickness - 2 * sagMagnitude(R1, std::hypot(0.01, 0.005)),
              kThicknessAbs);
  // A larger given centre thickness is kept (the edge requirement only raises it).
  const LensSolid thick = makeLens(makeSphere(R1, disc), makeSphere(R2, disc), disc, 0.004, edge, "plus lens");
  EXPECT_EQ(thick.centre_thickness, 0.004);
}

TEST(Lens, MinusLensEdgeIsThickest) {
  // Front R = 1 m, back R = 0.25 m (both convex towards the eye): (n - 1)(1 - 4) = -1.5 D at n = 1.5.
  const Outline rect = Outline::rectangle(0.05, 0.03, 0.005);
  const double tc = 0.0018;
  const LensSolid lens = makeLens(makeSphere(1.0, rect), makeSphere(0.25, rect), rect, tc, 0.0, "minus lens");
  EXPECT_EQ(lens.centre_thickness, tc);
  // Thickness = t_c + sag_back - sag_front, largest at the far corners, smallest at the centre.
  const Vec2 far = rect.fromSquare(Vec2(1, 1));
  const double r = glm::length(far);
  EXPECT_NEAR(lens.thicknessAt(far.x, far.y), tc + sagMagnitude(0.25, r) - sagMagnitude(1.0, r), kThicknessAbs);
  EXPECT_NEAR(lens.minimumThickness(), tc, kThicknessAbs);
  // Along the boundary the thinnest point is the middle of the long sides, at r = 0.015.
  EXPECT_NEAR(lens.edgeThicknessMin(), tc + sagMagnitude(0.25, 0.015) - sagMagnitude(1.0, 0.015), kThicknessAbs);
}

TEST(Lens, CrossingSurfacesAreRejected) {
  const Outline disc = Outline::circle(0.05);
  // Strongly curved plus lens with too little centre thickness: the surfaces cross before the edge
  // (2 sag(25 mm, 0.2 m) = 3.1 mm > 1 mm).
  try {
    makeLens(makeSphere(0.2, disc), makeSphere(-0.2, disc), disc, 0.001, 0.0, "lens.json: elements[2]");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("lens.json: elements[2]"), std::string::npos) << msg;
    EXPECT_NE(msg.find("cross or touch"), std::string::npos) << msg;
  }
  // Identical surfaces touch everywhere with zero centre thickness.
  EXPECT_THROW(makeLens(makeSphere(0.5, disc), makeSphere(0.5, disc), disc, 0.0, 0.0, "lens"), Error);
  // Zero centre thickness, a concave front (R < 0, rising towards the eye) and a plane back: they touch at
  // the vertex.
  EXPECT_THROW(makeLens(makeSphere(-0.5, disc), makePlane(disc), disc, 0.0, 0.0, "lens"), Error);
}

TEST(Lens, UndefinedSagAndBadArgumentsAreRejected) {
  const Outline disc = Outline::circle(0.05);
  try {
    makeLens(makeSphere(0.02, disc), makePlane(disc), disc, 0.01, 0.0, "steep lens");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("steep lens: front surface (sphere R=0.02 m) is undefined"), std::string::npos) << msg;
  }
  EXPECT_THROW(makeLens(nullptr, makePlane(disc), disc, 0.01, 0, "lens"), Error);
  EXPECT_THROW(makeLens(makePlane(disc), makePlane(disc), disc, -0.01, 0, "lens"), Error);
  EXPECT_THROW(makeLens(makePlane(disc), makePlane(disc), disc, 0.01, std::nan(""), "lens"), Error);
}

// ---- NURBS surfaces as sag graphs ----

// A cylinder of radius r (axis along local y, convex towards +z, vertex at the origin) as an exact rational
// patch whose x(u) is rational, not affine: the 90-degree cylinder patch of cad/nurbs.h turned so that its
// middle azimuth looks along +z. (Control points of a NURBS transform exactly under an affine map.)
std::shared_ptr<const NurbsSurface> turnedCylinder(double r, double height) {
  NurbsDefinition d = makeCylinderPatch(r, 0.5 * kPi, height).definition();
  const double s = std::sqrt(0.5);
  for (Vec3& p : d.points) p = Vec3(s * (p.x - p.y), p.z - 0.5 * height, s * (p.x + p.y) - r);
  return std::make_shared<NurbsSurface>(std::move(d), "turned cylinder");
}

// The graph of an exact rational cylinder against the analytic cylinder sag: the inversion and the implicit
// derivatives are exact to rounding. Values of ~1e-3 m (sag), ~0.2 (slope), ~10 /m (curvature): a few ulps
// each, with Newton's last step and the rational evaluation adding a few more.
constexpr double kGraphSagAbs = 1e-16;    // m
constexpr double kGraphSlopeAbs = 1e-13;
constexpr double kGraphCurvRel = 1e-10;

TEST(NurbsSag, RationalCylinderMatchesTheAnalyticSag) {
  const double r = 0.1;
  const Outline disc = Outline::circle(0.04);
  const SagSurfacePtr graph = makeNurbsSag(turnedCylinder(r, 0.06), disc, std::nullopt, 0, "cylinder test", 0.0);
  const SagSurfacePtr exact = makeCylinder(r, 0.5 * kPi, disc);
  for (int i = -4; i <= 4; ++i)
    for (int j = -4; j <= 4; ++j) {
      const double x = 0.005 * i, y = 0.005 * j;
      if (!disc.contains(Vec2(x, y))) continue;
      ASSERT_TRUE(graph->defined(x, y)) << x << ", " << y;
      const SagDerivs a = graph->sag(x, y), b = exact->sag(x, y);
      EXPECT_NEAR(a.z, b.z, kGraphSagAbs) << x << ", " << y;
      EXPECT_NEAR(a.zx, b.zx, kGraphSlopeAbs);
      EXPECT_NEAR(a.zy, b.zy, kGraphSlopeAbs);
      EXPECT_NEAR(a.zxx, b.zxx, kGraphCurvRel * std::abs(b.zxx));
      EXPECT_NEAR(a.zxy, b.zxy, kGraphCurvRel / r);
      EXPECT_NEAR(a.zyy, b.zyy, kGraphCurvRel / r);
      // The sag surface's normal and position are the NURBS surface's own.
      EXPECT_LT(angleBetween(graph->normal(x, y), exact->normal(x, y)), 1e-13);
    }
  // withVertex moves it along z only.
  const SagSurfacePtr moved = graph->withVertex(-0.003);
  EXPECT_EQ(moved->evaluate(0.01, 0.002).p.z, graph->evaluate(0.01, 0.002).p.z - 0.003);
}

// A spherical cap built from rational arcs (makeSphereCap) has a pole of its parametrisation at its apex,
// the lens axis: there d(x, y)/d(u, v) is singular, and the slope and curvature come from the points around
// it. The graph still matches the analytic sphere, at the apex and next to it.
TEST(NurbsSag, SphereCapWithItsPoleOnTheAxisMatchesTheSphere) {
  const double r = 0.2;
  const Outline disc = Outline::circle(0.06);
  auto cap = std::make_shared<NurbsSurface>(makeSphereCap(Vec3(0, 0, -r), r, 0.3));
  const SagSurfacePtr graph = makeNurbsSag(cap, disc, std::nullopt, 0, "sphere cap", 0.0);
  const SagSurfacePtr exact = makeSphere(r, disc);
  for (const Vec2 p : {Vec2(0, 0), Vec2(1e-9, 0), Vec2(0, -1e-7), Vec2(1e-5, 2e-5), Vec2(0.01, -0.02), Vec2(-0.025, 0.015)}) {
    ASSERT_TRUE(graph->defined(p.x, p.y)) << p.x << ", " << p.y;
    const SagDerivs a = graph->sag(p.x, p.y), b = exact->sag(p.x, p.y);
    EXPECT_NEAR(a.z, b.z, 1e-15) << p.x << ", " << p.y;
    EXPECT_NEAR(a.zx, b.zx, 1e-10) << p.x << ", " << p.y;
    EXPECT_NEAR(a.zy, b.zy, 1e-10) << p.x << ", " << p.y;
    EXPECT_NEAR(a.zxx, b.zxx, 1e-7 / r) << p.x << ", " << p.y;
    EXPECT_NEAR(a.zxy, b.zxy, 1e-7 / r) << p.x << ", " << p.y;
    EXPECT_NEAR(a.zyy, b.zyy, 1e-7 / r) << p.x << ", " << p.y;
    EXPECT_LT(angleBetween(graph->normal(p.x, p.y), exact->normal(p.x, p.y)), 1e-10);
  }
}

TEST(NurbsSag, ContinuesBeyondTheSurfaceWithContinuousSlope) {
  // The patch spans x in [-r/sqrt(2), r/sqrt(2)] and y in [-h/2, h/2]; outside, the Taylor continuation.
  const double r = 0.1, h = 0.06, edge = r * std::sqrt(0.5);
  const Outline disc = Outline::circle(0.04);
  const SagSurfacePtr graph = makeNurbsSag(turnedCylinder(r, h), disc, std::nullopt, 0, "cylinder test", 0.0);
  EXPECT_TRUE(graph->defined(0.01, 0.5 * h - 1e-6));
  EXPECT_FALSE(graph->defined(0.01, 0.5 * h + 1e-6));
  EXPECT_FALSE(graph->defined(edge + 1e-6, 0.0));
  // Across the edge y = h/2 (the cylinder is straight along y): value and slope continuous.
  const double dy = 1e-7;
  const SagDerivs in = graph->sag(0.01, 0.5 * h - dy), out = graph->sag(0.01, 0.5 * h + dy);
  EXPECT_NEAR(in.z, out.z, 2 * dy * std::abs(in.zy) + 1e-15);
  EXPECT_NEAR(in.zx, out.zx, 1e-9);
  // Across the curved edge x = edge: the continuation is the osculating parabola, close to the circle.
  const SagDerivs a = graph->sag(edge - dy, 0.0), b = graph->sag(edge + dy, 0.0);
  EXPECT_NEAR(a.z, b.z, 4 * dy * std::abs(a.zx));
  EXPECT_NEAR(a.zx, b.zx, 4 * dy * std::abs(a.zxx));
  EXPECT_TRUE(std::isfinite(graph->sag(0.2, -0.2).z));
}

TEST(NurbsSag, TrimAndAxisAreChecked) {
  const Outline disc = Outline::circle(0.04);
  // A trim loop (in (u, v)) smaller than the outline: points outside it are not defined.
  const auto cyl = turnedCylinder(0.1, 0.06);
  const ParamDomain dom = cyl->domain();
  const Vec2 mid(0.5 * (dom.u0 + dom.u1), 0.5 * (dom.v0 + dom.v1));
  // The middle fifth of the azimuth range: |x| < r sin(9 deg) = 15.6 mm.
  const Outline trim = Outline::rectangle(0.2 * (dom.u1 - dom.u0), dom.v1 - dom.v0, 0, mid);
  const SagSurfacePtr trimmed = makeNurbsSag(cyl, disc, trim, 1e-12, "trimmed", 0.0);
  EXPECT_TRUE(trimmed->defined(0.0, 0.0));
  EXPECT_FALSE(trimmed->defined(0.019, 0.0));
  // A lens with that surface and this outline is refused, naming the surface's source.
  try {
    makeLens(makeSphere(-0.3, disc), trimmed, disc, 0.003, 0.0, "scene.json: elements[0]");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("scene.json: elements[0]: back surface"), std::string::npos) << msg;
    EXPECT_NE(msg.find("from trimmed"), std::string::npos) << msg;
    EXPECT_NE(msg.find("is undefined"), std::string::npos) << msg;
  }
  // A surface that is not over the lens axis.
  NurbsDefinition d = cyl->definition();
  for (Vec3& p : d.points) p.x += 1.0;
  try {
    makeNurbsSag(std::make_shared<NurbsSurface>(d), disc, std::nullopt, 0, "shifted.igs face 0");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("shifted.igs face 0: the surface"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("lens axis"), std::string::npos) << e.what();
  }
}

TEST(NurbsSag, LensWithANurbsBackHasTheAnalyticThickness) {
  // Plano-convex-like: plane front, cylinder back (centre of curvature towards the eye: R < 0 as a sag).
  const double r = 0.1;
  const Outline disc = Outline::circle(0.04);
  auto cyl = turnedCylinder(r, 0.06);
  NurbsDefinition d = cyl->definition();
  for (Vec3& p : d.points) p.z = -p.z;  // mirror in z: concave towards +z, the sag of R = -0.1 m
  const SagSurfacePtr back = makeNurbsSag(std::make_shared<NurbsSurface>(d), disc, std::nullopt, 0, "back", 0.0);
  const LensSolid lens = makeLens(makePlane(disc), back, disc, 0.003, 0.0, "lens");
  const LensSolid ref = makeLens(makePlane(disc), makeCylinder(-r, 0.5 * kPi, disc), disc, 0.003, 0.0, "lens");
  for (double x : {0.0, 0.007, -0.015})
    EXPECT_NEAR(lens.thicknessAt(x, 0.01), ref.thicknessAt(x, 0.01), kGraphSagAbs);
  EXPECT_NEAR(lens.minimumThickness(), ref.minimumThickness(), kGraphSagAbs);
  // Too thin: the back rises through the plane front before the edge (sag 2.02 mm at x = 20 mm).
  EXPECT_THROW(makeLens(makePlane(disc), back, disc, 0.0015, 0.0, "lens"), Error);
}

// ---- the shipped progressive back surface ----

std::string modelPath(const std::string& name) { return std::string(PVRR_SOURCE_DIR) + "/models/" + name; }

// The bicubic fit of the design over the lens outline (the fit's own report; measured ~0.1 um): 1 um in sag
// is ~0.02 D of surface power over the 3-4 mm knot spacing.
constexpr double kProgressiveFitMm = 1e-3;
// IGES prints fewer digits than STEP: the round-trip tolerance of tests/cad/cad_import_test.cpp, relative to
// the blank's size.
constexpr double kIgesRelTol = 1e-9;
// Surface power from the fitted surface's curvature: the fit's curvature error over the knot spacing.
constexpr double kPowerTol_D = 0.03;

TEST(ProgressiveBack, DesignFitHasTheAddAlongAnUmbilicCorridor) {
  using D = ProgressiveBackDesign;
  const GeneratedSurface g = progressiveBackSurface();
  EXPECT_LT(g.fit_max_mm, kProgressiveFitMm);
  std::cout << "[ measured ] progressive fit rms " << g.fit_rms_mm << " mm, max " << g.fit_max_mm << " mm\n";
  // As a lens surface in metres: the add is -(n - 1) times the change of sag curvature from the base sphere.
  const Outline lens = Outline::ellipse(D::lens_width_mm * 1e-3, D::lens_height_mm * 1e-3);
  const SagSurfacePtr s = makeNurbsSag(std::make_shared<NurbsSurface>(scaled(g.surface, 1e-3)), lens,
                                       std::nullopt, 0, "progressive", 0.0);
  const SagSurfacePtr base = makeSphere(D::base_radius_mm * 1e-3, lens);
  for (double y_mm : {8.0, 3.0, 0.0, -3.0, -6.0, -9.0, -12.0, -15.0, -18.0}) {
    const SagDerivs a = s->sag(0, y_mm * 1e-3), b = base->sag(0, y_mm * 1e-3);
    const double add_x = -(D::n_d - 1) * (a.zxx - b.zxx), add_y = -(D::n_d - 1) * (a.zyy - b.zyy);
    EXPECT_NEAR(add_x, D::addAt(y_mm), kPowerTol_D) << "y = " << y_mm << " mm";
    EXPECT_NEAR(add_y, D::addAt(y_mm), kPowerTol_D) << "y = " << y_mm << " mm";
    EXPECT_NEAR((D::n_d - 1) * a.zxy, 0.0, kPowerTol_D) << "corridor is umbilic";
  }
  EXPECT_NEAR(D::addAt(-D::corridor_length_mm), D::add_d, 1e-15);
  // Astigmatism (twist) beside the middle of the corridor: kappa S' x, about 1.6 D at x = 10 mm.
  const SagDerivs side = s->sag(0.010, -0.006);
  EXPECT_GT(std::abs((D::n_d - 1) * side.zxy), 0.5);
}

TEST(ProgressiveBack, ShippedIgesMatchesTheGenerator) {
  const std::string path = modelPath("progressive-back.igs");
  if (std::getenv("PVRR_REGENERATE_MODELS")) writeProgressiveBackIges(path);  // the one way to update it
  const GeneratedSurface g = progressiveBackSurface();
  const ImportedModel m = importCadFile(path);
  EXPECT_EQ(m.unit_name, "mm");
  ASSERT_EQ(m.faces.size(), 1u);
  EXPECT_FALSE(m.faces[0].trim.has_value()) << "the blank is untrimmed";
  const NurbsSurface& s = *m.faces[0].surface;
  const double size = ProgressiveBackDesign::blank_width_mm;
  double worst = 0, worst_d = 0;
  for (int i = 0; i <= 28; ++i)
    for (int j = 0; j <= 23; ++j) {
      const double u = -28 + 2.0 * i, v = -23 + 2.0 * j;
      const SurfaceDerivs a = s.evaluate(u, v), b = g.surface.evaluate(u, v);
      worst = std::max(worst, glm::length(a.p - b.p));
      worst_d = std::max({worst_d, glm::length(a.du - b.du), glm::length(a.dv - b.dv)});
    }
  EXPECT_LT(worst, kIgesRelTol * size);
  EXPECT_LT(worst_d, kIgesRelTol * 10);  // derivatives are ~1
  std::cout << "[ measured ] progressive-back.igs vs generator: position " << worst << " mm, derivative " << worst_d
            << "\n";
  // Regenerating gives the same model (the IGES header holds the file name: same name, another folder).
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "pvrr_lens_test_models";
  std::filesystem::create_directories(dir);
  const std::string tmp = (dir / "progressive-back.igs").string();
  writeProgressiveBackIges(tmp);
  expectSameModel(tmp, path);  // if not: PVRR_REGENERATE_MODELS=1 cad_tests --gtest_filter=ProgressiveBack.*
  std::filesystem::remove_all(dir);
  EXPECT_LT(std::filesystem::file_size(path), 100u * 1024u);
}

}  // namespace
}  // namespace pvrr::cad
