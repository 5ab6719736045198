// STEP/IGES import and export (cad/cad_import.h) and the shipped CAD models (cad/model_generator.h).
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepLib.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <GCE2d_MakeSegment.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_SphericalSurface.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <STEPControl_Writer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Ax2.hxx>
#include <gp_Ax22d.hxx>
#include <gp_Ax3.hxx>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "cad/cad_import.h"
#include "pvrr/base/error.h"
#include "cad/model_generator.h"
#include "cad/same_model.h"

namespace pvrr::cad {
namespace {

namespace fs = std::filesystem;

// STEP prints reals with 17 significant digits (measured: 2e-13 relative on D1 in platform notes), so a
// round trip reproduces the surface to near rounding; 1e-9 relative leaves four orders of margin.
constexpr double kStepRelTol = 1e-9;
// IGES: OCCT writes reals with fewer significant digits than STEP. Measured on the test surface: 2e-12
// relative on positions, 4e-11 on first derivatives (IgesRoundTrip prints both); 1e-9 leaves a margin.
constexpr double kIgesRelTol = 1e-9;
// Exact rational conversion of analytic surfaces: rounding only.
constexpr double kExactRelTol = 1e-9;
// Loop vertices are samples of the exact trim curve, mapped through a file round trip (STEP) and, for
// converted analytic surfaces, a projection; this bounds both (relative to the surface size).
constexpr double kOnCurveRelTol = 1e-9;

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void spit(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

class CadImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("pvrr_cad_import_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// A rational, non-uniform, unequal-degree NURBS of about 100 units: every part of the format is exercised.
NurbsSurface testSurface(double scale = 1.0) {
  NurbsDefinition d;
  d.degree_u = 3;
  d.degree_v = 2;
  d.count_u = 6;
  d.count_v = 4;
  d.knots_u = {-50, -50, -50, -50, -12.5, 20, 50, 50, 50, 50};
  d.knots_v = {-40, -40, -40, 5, 40, 40, 40};
  for (int i = 0; i < d.count_u; ++i)
    for (int j = 0; j < d.count_v; ++j) {
      const double x = -50 + 20.0 * i + 1.5 * j, y = -40 + 26.0 * j - 0.7 * i;
      d.points.emplace_back(scale * x, scale * y, scale * (0.01 * x * y - 0.002 * x * x + 3.0 * std::sin(0.1 * i * j)));
      d.weights.push_back(1.0 + 0.15 * ((i * 3 + j * 5) % 4));
    }
  return NurbsSurface(d, "test surface");
}

double sizeOf(const NurbsSurface& s) {
  Vec3 lo(kInf), hi(-kInf);
  for (const Vec3& p : s.definition().points) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return glm::length(hi - lo);
}

// Largest differences of positions and first derivatives over an 11 x 11 grid, relative to the size.
struct Diff {
  double position = 0, derivative = 0;
};
Diff compareOnGrid(const Surface& a, const Surface& b, double size) {
  const ParamDomain da = a.domain();
  Diff diff;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j) {
      const double u = da.u0 + (da.u1 - da.u0) * i / 10, v = da.v0 + (da.v1 - da.v0) * j / 10;
      const SurfaceDerivs x = a.evaluate(u, v), y = b.evaluate(u, v);
      diff.position = std::max(diff.position, glm::length(x.p - y.p) / size);
      const double span = std::max(da.u1 - da.u0, da.v1 - da.v0);
      diff.derivative = std::max({diff.derivative, glm::length(x.du - y.du) * span / size,
                                  glm::length(x.dv - y.dv) * span / size});
    }
  return diff;
}

void expectSameDomain(const ParamDomain& a, const ParamDomain& b, double tol) {
  EXPECT_NEAR(a.u0, b.u0, tol);
  EXPECT_NEAR(a.u1, b.u1, tol);
  EXPECT_NEAR(a.v0, b.v0, tol);
  EXPECT_NEAR(a.v1, b.v1, tol);
}

TEST_F(CadImportTest, StepRoundTripReproducesTheNurbs) {
  const NurbsSurface s = testSurface();
  const std::string path = file("surface.step");
  writeStep(path, s, std::nullopt, "mm");
  const ImportedModel m = importCadFile(path);
  ASSERT_EQ(m.faces.size(), 1u);
  const ImportedFace& f = m.faces[0];
  EXPECT_EQ(f.source_type, "b-spline");
  EXPECT_FALSE(f.trim.has_value());
  EXPECT_EQ(f.surface->definition().degree_u, 3);
  EXPECT_EQ(f.surface->definition().degree_v, 2);
  EXPECT_EQ(f.surface->definition().weights.size(), s.definition().points.size());
  expectSameDomain(f.surface->domain(), s.domain(), kStepRelTol * 100);
  const Diff d = compareOnGrid(s, *f.surface, sizeOf(s));
  EXPECT_LT(d.position, kStepRelTol);
  EXPECT_LT(d.derivative, kStepRelTol);
  std::cout << "[ measured ] STEP round trip: position " << d.position << ", derivative " << d.derivative
            << " (relative)\n";
}

TEST_F(CadImportTest, IgesRoundTripReproducesTheNurbs) {
  const NurbsSurface s = testSurface();
  const std::string path = file("surface.igs");
  writeIges(path, s, std::nullopt, "mm");
  const ImportedModel m = importCadFile(path);
  ASSERT_EQ(m.faces.size(), 1u);
  EXPECT_EQ(m.faces[0].source_type, "b-spline");
  EXPECT_EQ(m.unit_name, "mm");
  const Diff d = compareOnGrid(s, *m.faces[0].surface, sizeOf(s));
  EXPECT_LT(d.position, kIgesRelTol);
  EXPECT_LT(d.derivative, kIgesRelTol);
  std::cout << "[ measured ] IGES round trip: position " << d.position << ", derivative " << d.derivative
            << " (relative)\n";
}

// Signed distance from p to the boundary of a rounded rectangle centred at the origin (negative inside).
double roundedRectDistance(Vec2 p, double w, double h, double r) {
  const Vec2 q = glm::abs(p) - Vec2(0.5 * w - r, 0.5 * h - r);
  return glm::length(glm::max(q, Vec2(0.0))) + std::min(std::max(q.x, q.y), 0.0) - r;
}

TEST_F(CadImportTest, TrimmedStepFaceKeepsItsRoundedRectangleLoop) {
  const GeneratedSurface g = carMirrorSurface();
  const double w = CarMirrorDesign::width_mm, h = CarMirrorDesign::height_mm, r = CarMirrorDesign::corner_radius_mm;
  const std::string path = file("trimmed.step");
  writeStep(path, g.surface, Outline::rectangle(w, h, r), "mm");
  const ImportedModel m = importCadFile(path);
  ASSERT_EQ(m.faces.size(), 1u);
  const ImportedFace& f = m.faces[0];
  ASSERT_TRUE(f.trim.has_value());
  const std::vector<Vec2>& loop = f.trim->loop();
  EXPECT_GE(loop.size(), 1000u);
  const double tol = kOnCurveRelTol * w;
  // Every loop vertex lies on the trim curve.
  double worst_vertex = 0;
  for (const Vec2& p : loop) worst_vertex = std::max(worst_vertex, std::abs(roundedRectDistance(p, w, h, r)));
  EXPECT_LT(worst_vertex, tol);
  // Chord midpoints lie inside the (convex) trim curve, no deeper than the reported chord error.
  double worst_mid = 0;
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const Vec2 mid = 0.5 * (loop[k] + loop[(k + 1) % loop.size()]);
    const double dist = roundedRectDistance(mid, w, h, r);
    EXPECT_LT(dist, tol);
    worst_mid = std::max(worst_mid, -dist);
  }
  EXPECT_LE(worst_mid, f.trim_chord_error_uv * 1.01 + tol);
  EXPECT_GT(f.trim_chord_error_uv, 0.0);
  // The chord error is honest and small: a quarter circle of r = 30 gets ~1/8 of 1024 samples at least
  // (sagitta s^2 / (8 r) with s = (pi/2) r / 128 is 5e-4 mm); allow that bound.
  const double s = 0.5 * kPi * r / 128;
  EXPECT_LT(f.trim_chord_error_uv, s * s / (8 * r));
  EXPECT_GT(f.trim_chord_error, 0.0);
  // The loop passes through the eight points where the straight sides meet the corner arcs.
  const double hw = 0.5 * w, hh = 0.5 * h;
  const Vec2 junctions[8] = {{hw - r, -hh}, {hw, -hh + r}, {hw, hh - r}, {hw - r, hh},
                             {-hw + r, hh}, {-hw, hh - r}, {-hw, -hh + r}, {-hw + r, -hh}};
  for (const Vec2& j : junctions) {
    double nearest = kInf;
    for (const Vec2& p : loop) nearest = std::min(nearest, glm::length(p - j));
    EXPECT_LT(nearest, tol) << "junction (" << j.x << ", " << j.y << ")";
  }
  // The untrimmed surface itself is unchanged by the trim.
  EXPECT_LT(compareOnGrid(g.surface, *f.surface, sizeOf(g.surface)).position, kStepRelTol);
  std::cout << "[ measured ] trim loop " << loop.size() << " points, chord error " << f.trim_chord_error_uv
            << " mm in (u,v), " << f.trim_chord_error << " mm on the surface\n";
}

TEST_F(CadImportTest, TrimmedIgesFaceKeepsItsCircleAndPolygonLoops) {
  const GeneratedSurface g = lensFrontSurface();
  const double radius = 0.5 * LensFrontDesign::diameter_mm;
  const double size = sizeOf(g.surface);
  {
    const std::string path = file("circle.igs");
    writeIges(path, g.surface, Outline::circle(2 * radius, Vec2(1.0, -2.0)), "mm");
    const ImportedModel m = importCadFile(path);
    ASSERT_EQ(m.faces.size(), 1u);
    ASSERT_TRUE(m.faces[0].trim.has_value());
    double worst = 0;
    for (const Vec2& p : m.faces[0].trim->loop())
      worst = std::max(worst, std::abs(glm::length(p - Vec2(1.0, -2.0)) - radius));
    EXPECT_LT(worst, kIgesRelTol * size);
    std::cout << "[ measured ] IGES circle trim: vertices within " << worst << " mm of the circle\n";
  }
  {
    // A star-shaped polygon: its corners must survive as loop vertices.
    std::vector<Vec2> poly;
    for (int k = 0; k < 7; ++k) {
      const double th = 2 * kPi * k / 7, rr = (k % 2 ? 0.6 : 1.0) * radius;
      poly.emplace_back(rr * std::cos(th), rr * std::sin(th));
    }
    const std::string path = file("polygon.igs");
    writeIges(path, g.surface, Outline::polygon(poly, Vec2(0.0)), "mm");
    const ImportedModel m = importCadFile(path);
    ASSERT_TRUE(m.faces[0].trim.has_value());
    const std::vector<Vec2>& loop = m.faces[0].trim->loop();
    for (const Vec2& c : poly) {
      double nearest = kInf;
      for (const Vec2& p : loop) nearest = std::min(nearest, glm::length(p - c));
      EXPECT_LT(nearest, kIgesRelTol * size);
    }
    EXPECT_NEAR(m.faces[0].trim_chord_error_uv, 0.0, kIgesRelTol * size);  // straight edges: chords are exact
  }
}

// Writes `face` with OCCT's own STEP writer (not ours), in mm.
void writeFaceStep(const TopoDS_Shape& face, const std::string& path) {
  Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
  STEPControl_Writer w;
  ASSERT_EQ(w.Transfer(face, STEPControl_AsIs), IFSelect_RetDone);
  ASSERT_EQ(w.Write(path.c_str()), IFSelect_RetDone);
}

TEST_F(CadImportTest, AnalyticSphereImportsAsExactRationalNurbs) {
  const double R = 123.0;
  const gp_Pnt centre(10, -20, 30);
  // A patch away from the poles (longitude 0.3..1.9, latitude -0.4..1.1), and a polar cap with the pole.
  Handle(Geom_SphericalSurface) sphere = new Geom_SphericalSurface(gp_Ax3(centre, gp_Dir(0, 0, 1)), R);
  const TopoDS_Face patch = BRepBuilderAPI_MakeFace(sphere, 0.3, 1.9, -0.4, 1.1, 1e-7);
  const TopoDS_Shape cap = BRepPrimAPI_MakeSphere(gp_Ax2(centre, gp_Dir(0, 0, 1)), R, 0.6, 0.5 * kPi).Shape();
  const Vec3 c(centre.X(), centre.Y(), centre.Z());
  int index = 0, spheres = 0, planes = 0;
  for (const TopoDS_Shape& shape : {TopoDS_Shape(patch), cap}) {
    const std::string path = file("sphere" + std::to_string(index++) + ".step");
    writeFaceStep(shape, path);
    const ImportedModel m = importCadFile(path);
    for (const ImportedFace& f : m.faces) {
      const ParamDomain d = f.surface->domain();
      if (f.source_type == "plane") {
        // The cap solid's flat face at latitude 0.6: a plane trimmed by the circle of radius R cos 0.6.
        ++planes;
        ASSERT_TRUE(f.trim.has_value());
        for (const Vec2& uv : f.trim->loop()) {
          const Vec3 p = f.surface->evaluate(uv.x, uv.y).p - c;
          EXPECT_NEAR(std::hypot(p.x, p.y), R * std::cos(0.6), kExactRelTol * R);
          EXPECT_NEAR(p.z, R * std::sin(0.6), kExactRelTol * R);
        }
        continue;
      }
      ++spheres;
      EXPECT_EQ(f.source_type, "sphere");
      EXPECT_FALSE(f.trim.has_value()) << "a face bounded by iso-lines is untrimmed";
      const std::vector<double>& w = f.surface->definition().weights;
      EXPECT_TRUE(std::any_of(w.begin(), w.end(), [](double x) { return x != 1.0; })) << "an exact sphere is rational";
      double worst_r = 0, worst_angle = 0;
      for (int i = 0; i <= 12; ++i)
        for (int j = 0; j <= 12; ++j) {
          const double u = d.u0 + (d.u1 - d.u0) * i / 12, v = d.v0 + (d.v1 - d.v0) * j / 12;
          const SurfaceDerivs e = f.surface->evaluate(u, v);
          worst_r = std::max(worst_r, std::abs(glm::length(e.p - c) - R));
          if (i == 0 || i == 12 || j == 0 || j == 12) continue;  // normals at interior points (poles excluded)
          worst_angle = std::max(worst_angle, angleBetween(glm::cross(e.du, e.dv), e.p - c));
        }
      EXPECT_LT(worst_r, kExactRelTol * R) << path;
      EXPECT_LT(worst_angle, kExactRelTol) << path << ": normals radial and outward";
    }
  }
  EXPECT_EQ(spheres, 2);
  EXPECT_EQ(planes, 1);
}

TEST_F(CadImportTest, ReversedFaceSwapsUVSoTheNormalFollowsTheFace) {
  // A sphere patch: as a forward face its normal is outward, as a reversed face inward.
  const double R = 50;
  Handle(Geom_SphericalSurface) sphere = new Geom_SphericalSurface(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), R);
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(sphere, 0.2, 1.4, -0.3, 0.9, 1e-7);
  for (const bool reversed : {false, true}) {
    const std::string path = file(reversed ? "reversed.step" : "forward.step");
    writeFaceStep(reversed ? face.Reversed() : TopoDS_Shape(face), path);
    const ImportedModel m = importCadFile(path);
    ASSERT_EQ(m.faces.size(), 1u);
    const ParamDomain d = m.faces[0].surface->domain();
    double worst = 0;
    for (int i = 1; i < 8; ++i)
      for (int j = 1; j < 8; ++j) {
        const double u = d.u0 + (d.u1 - d.u0) * i / 8, v = d.v0 + (d.v1 - d.v0) * j / 8;
        const SurfaceDerivs e = m.faces[0].surface->evaluate(u, v);
        worst = std::max(worst, angleBetween(glm::cross(e.du, e.dv), reversed ? -e.p : e.p));
      }
    EXPECT_LT(worst, kExactRelTol) << (reversed ? "inward normal for a reversed face" : "outward normal");
  }
}

double distanceToSegment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
  return glm::length(p - (a + t * ab));
}

TEST_F(CadImportTest, TrimOnAConvertedCylinderIsMappedOntoTheNurbs) {
  // A cylinder (u = angle, v = height) trimmed by a hexagon of straight pcurves in its own (u, v). The exact
  // rational B-spline of a cylinder is not angle-parameterised, so the loop must be mapped through 3D
  // points. (A circular pcurve is not used here: OCCT's STEP writer turns it into a rational B-spline whose
  // parameter no longer matches the edge's 3D curve, and the reader's shape healing then re-approximates
  // the pcurve to ~1e-6: a property of the exchange, not of the import.)
  const double R = 80, uc = 0.8, vc = 15, half_angle = 0.5, half_height = 10;
  Handle(Geom_CylindricalSurface) cyl = new Geom_CylindricalSurface(gp_Ax3(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), R);
  std::vector<Vec2> hex;  // (angle, height)
  for (int k = 0; k < 6; ++k)
    hex.emplace_back(uc + half_angle * std::cos(k * kPi / 3), vc + half_height * std::sin(k * kPi / 3));
  std::vector<TopoDS_Vertex> verts;
  for (const Vec2& h : hex) verts.push_back(BRepBuilderAPI_MakeVertex(cyl->Value(h.x, h.y)));
  BRepBuilderAPI_MakeWire mw;
  for (int k = 0; k < 6; ++k) {
    const Vec2 a = hex[std::size_t(k)], b = hex[std::size_t((k + 1) % 6)];
    Handle(Geom2d_TrimmedCurve) seg = GCE2d_MakeSegment(gp_Pnt2d(a.x, a.y), gp_Pnt2d(b.x, b.y)).Value();
    mw.Add(BRepBuilderAPI_MakeEdge(seg, cyl, verts[std::size_t(k)], verts[std::size_t((k + 1) % 6)],
                                   seg->FirstParameter(), seg->LastParameter())
               .Edge());
  }
  TopoDS_Face face = BRepBuilderAPI_MakeFace(cyl, mw.Wire(), true);
  BRepLib::BuildCurves3d(face, 1e-9);
  const std::string path = file("cylinder.step");
  writeFaceStep(face, path);
  const ImportedModel m = importCadFile(path);
  ASSERT_EQ(m.faces.size(), 1u);
  const ImportedFace& f = m.faces[0];
  EXPECT_EQ(f.source_type, "cylinder");
  ASSERT_TRUE(f.trim.has_value());
  // Back to the unrolled cylinder (R * angle, height) through 3D.
  auto unrolled = [&](Vec2 uv) {
    const Vec3 p = f.surface->evaluate(uv.x, uv.y).p;
    EXPECT_NEAR(std::hypot(p.x, p.y), R, kExactRelTol * R);
    return Vec2(R * std::atan2(p.y, p.x), p.z);
  };
  auto distanceToHexagon = [&](Vec2 q) {
    double d = kInf;
    for (int k = 0; k < 6; ++k) {
      const Vec2 a = hex[std::size_t(k)], b = hex[std::size_t((k + 1) % 6)];
      d = std::min(d, distanceToSegment(q, Vec2(R * a.x, a.y), Vec2(R * b.x, b.y)));
    }
    return d;
  };
  const std::vector<Vec2>& loop = f.trim->loop();
  double worst = 0;
  for (const Vec2& uv : loop) worst = std::max(worst, distanceToHexagon(unrolled(uv)));
  EXPECT_LT(worst, kOnCurveRelTol * R);
  for (const Vec2& corner : hex) {
    double nearest = kInf;
    for (const Vec2& uv : loop) nearest = std::min(nearest, glm::length(unrolled(uv) - Vec2(R * corner.x, corner.y)));
    EXPECT_LT(nearest, kOnCurveRelTol * R) << "corner (" << corner.x << ", " << corner.y << ")";
  }
  // Straight in the cylinder's (u, v), slightly curved in the B-spline's: a small, reported chord error.
  EXPECT_GT(f.trim_chord_error, 0.0);
  EXPECT_LT(f.trim_chord_error, 1e-4 * R);
  std::cout << "[ measured ] cylinder trim: vertices within " << worst << " mm of the hexagon, chord error "
            << f.trim_chord_error << " mm\n";
}

TEST_F(CadImportTest, UnitsMillimetresAndMetresKeepTheFilesNumbers) {
  const NurbsSurface mm = testSurface();
  const NurbsSurface m = scaled(mm, 1e-3);
  for (const bool step : {true, false}) {
    const std::string ext = step ? ".step" : ".igs";
    const std::string pmm = file("mm" + ext), pm = file("m" + ext);
    if (step) {
      writeStep(pmm, mm, std::nullopt, "mm");
      writeStep(pm, m, std::nullopt, "m");
    } else {
      writeIges(pmm, mm, std::nullopt, "mm");
      writeIges(pm, m, std::nullopt, "m");
    }
    const ImportedModel a = importCadFile(pmm), b = importCadFile(pm);
    EXPECT_EQ(a.unit_name, "mm");
    EXPECT_DOUBLE_EQ(a.unit_to_metres, 1e-3);
    EXPECT_EQ(b.unit_name, "m");
    EXPECT_DOUBLE_EQ(b.unit_to_metres, 1.0);
    const double tol = step ? kStepRelTol : kIgesRelTol;
    EXPECT_LT(compareOnGrid(mm, *a.faces[0].surface, sizeOf(mm)).position, tol) << ext << " numbers stay in mm";
    EXPECT_LT(compareOnGrid(m, *b.faces[0].surface, sizeOf(m)).position, tol) << ext << " numbers stay in m";
    const NurbsSurface a_in_m = scaled(*a.faces[0].surface, a.unit_to_metres);
    EXPECT_LT(compareOnGrid(a_in_m, *b.faces[0].surface, sizeOf(m)).position, tol) << ext;
  }
  EXPECT_THROW(writeStep(file("x.step"), mm, std::nullopt, "inch"), Error);
}

void expectErrorNaming(const std::string& path, const std::string& what) {
  try {
    importCadFile(path);
    ADD_FAILURE() << path << ": expected pvrr::Error (" << what << ")";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
  }
}

TEST_F(CadImportTest, BrokenFilesGiveErrorsNamingTheFile) {
  expectErrorNaming(file("missing.step"), "not found");
  spit(file("empty.step"), "");
  expectErrorNaming(file("empty.step"), "empty");
  spit(file("empty.igs"), "");
  expectErrorNaming(file("empty.igs"), "empty");
  spit(file("model.txt"), "hello");
  expectErrorNaming(file("model.txt"), "unknown CAD file type");

  writeStep(file("good.step"), testSurface(), std::nullopt, "mm");
  const std::string good = slurp(file("good.step"));
  spit(file("truncated.step"), good.substr(0, good.size() / 2));
  expectErrorNaming(file("truncated.step"), "truncated");
  spit(file("garbage.step"), "this is not a STEP file\n");
  expectErrorNaming(file("garbage.step"), "STEP");
  // Looks like STEP at both ends, nonsense inside.
  spit(file("hollow.step"), "ISO-10303-21;\nHEADER;\n#1 = ((( nonsense\nENDSEC;\nEND-ISO-10303-21;\n");
  expectErrorNaming(file("hollow.step"), "hollow.step");

  writeIges(file("good.igs"), testSurface(), std::nullopt, "mm");
  const std::string igs = slurp(file("good.igs"));
  spit(file("truncated.igs"), igs.substr(0, igs.size() / 2));
  expectErrorNaming(file("truncated.igs"), "truncated");
  std::string binary(4096, '\0');
  for (std::size_t i = 0; i < binary.size(); ++i) binary[i] = char((i * 7919u) % 251u);
  spit(file("binary.igs"), binary);
  expectErrorNaming(file("binary.igs"), "IGES");

  // A valid STEP file with only an edge: no surface.
  writeFaceStep(BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(10, 0, 0)).Edge(), file("edge.step"));
  expectErrorNaming(file("edge.step"), "no surface");
}

TEST_F(CadImportTest, StdoutStaysClean) {
  ::testing::internal::CaptureStdout();
  writeStep(file("a.step"), testSurface(), Outline::rectangle(60, 50, 10), "mm");
  writeIges(file("a.igs"), testSurface(), Outline::circle(40), "m");
  importCadFile(file("a.step"));
  importCadFile(file("a.igs"));
  spit(file("bad.step"), "ISO-10303-21;\nDATA;\n#1 = FOO(;\nENDSEC;\nEND-ISO-10303-21;\n");
  EXPECT_THROW(importCadFile(file("bad.step")), Error);
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "");
}

TEST_F(CadImportTest, WritersAreAtomicAndDeterministic) {
  const NurbsSurface s = testSurface();
  fs::create_directories(file("a"));
  fs::create_directories(file("b"));
  for (const std::string name : {"d.step", "d.igs"}) {
    const bool step = name.find(".step") != std::string::npos;
    const std::string a = file("a") + "/" + name, b = file("b") + "/" + name;
    for (const std::string& p : {a, b}) {
      if (step)
        writeStep(p, s, Outline::ellipse(50, 30), "mm");
      else
        writeIges(p, s, Outline::ellipse(50, 30), "mm");
    }
    const std::string ta = slurp(a), tb = slurp(b);
    EXPECT_FALSE(ta.empty());
    EXPECT_TRUE(ta == tb) << name << ": two writes of the same surface differ";
    for (const std::string& folder : {file("a"), file("b")})  // no temporary file left beside the outputs
      for (const auto& entry : fs::directory_iterator(folder))
        EXPECT_TRUE(entry.path().filename() == "d.step" || entry.path().filename() == "d.igs") << entry.path();
  }
  // Writing into a directory that does not exist fails cleanly, naming the file.
  const std::string bad = file("no/such/dir/x.step");
  try {
    writeStep(bad, s, std::nullopt, "mm");
    ADD_FAILURE() << "expected pvrr::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
  // A trim that leaves the surface's domain is refused.
  EXPECT_THROW(writeStep(file("t.step"), s, Outline::circle(500), "mm"), Error);
}

// ---- the shipped models ----

std::string modelPath(const std::string& name) { return std::string(PVRR_SOURCE_DIR) + "/models/" + name; }


// Fit quality of the generated surfaces: the 6 x 5 bicubic mirror represents the design's quadratic part
// and curvature jump exactly (double knot), leaving the sphere's quartic term, r^4 / (8 R^3) ~ 0.01 mm at the
// corners, mostly absorbed; 2 um bounds the residual. The 8 x 8 lens fit of R = 200 mm over 64 mm is
// similar.
constexpr double kMirrorFitMm = 2e-3;
constexpr double kLensFitMm = 2e-3;

TEST_F(CadImportTest, GeneratedMirrorAndLensFitTheirDesigns) {
  const GeneratedSurface mirror = carMirrorSurface();
  EXPECT_LT(mirror.fit_max_mm, kMirrorFitMm);
  const GeneratedSurface lens = lensFrontSurface();
  EXPECT_LT(lens.fit_max_mm, kLensFitMm);
  std::cout << "[ measured ] mirror fit rms " << mirror.fit_rms_mm << " mm, max " << mirror.fit_max_mm
            << " mm; lens fit rms " << lens.fit_rms_mm << " mm, max " << lens.fit_max_mm << " mm\n";
  // Vertex at the origin, tangent plane z = 0, normal +z.
  for (const GeneratedSurface* g : {&mirror, &lens}) {
    const SurfaceDerivs e = g->surface.evaluate(0, 0);
    EXPECT_NEAR(glm::length(e.p), 0.0, 1e-12);
    EXPECT_LT(angleBetween(glm::cross(e.du, e.dv), Vec3(0, 0, 1)), 1e-12);
  }
}

TEST_F(CadImportTest, ShippedCarMirrorStepLoadsAndMatchesItsDesign) {
  const std::string path = modelPath("car-mirror.step");
  const ImportedModel m = importCadFile(path);
  EXPECT_EQ(m.unit_name, "mm");
  ASSERT_EQ(m.faces.size(), 1u);
  const ImportedFace& f = m.faces[0];
  ASSERT_TRUE(f.trim.has_value());
  EXPECT_LT(std::abs(f.trim->width() - CarMirrorDesign::width_mm), 1e-6);
  EXPECT_LT(std::abs(f.trim->height() - CarMirrorDesign::height_mm), 1e-6);
  const NurbsSurface& s = *f.surface;
  EXPECT_EQ(s.definition().count_u * s.definition().count_v, 30);
  for (double w : s.definition().weights) EXPECT_EQ(w, 1.0) << "non-rational";
  double worst = 0;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const Vec2 uv(-100 + 10.0 * i, -75 + 7.5 * j);
      if (!f.trim->contains(uv)) continue;
      const Vec3 p = s.evaluate(uv.x, uv.y).p;
      EXPECT_NEAR(p.x, uv.x, 1e-9);  // x(u) = u, y(v) = v
      EXPECT_NEAR(p.y, uv.y, 1e-9);
      worst = std::max(worst, std::abs(p.z - CarMirrorDesign::z(p.x, p.y)));
    }
  EXPECT_LT(worst, kMirrorFitMm);
  // Convex towards the driver: curvature +1/R (surface.h sign convention), stronger in the outer band.
  const Curvature centre = s.curvature(0, 0), band = s.curvature(85, 0);
  EXPECT_NEAR(centre.k1, 1 / CarMirrorDesign::main_radius_mm, 0.02 / CarMirrorDesign::main_radius_mm);
  EXPECT_NEAR(centre.k2, 1 / CarMirrorDesign::main_radius_mm, 0.02 / CarMirrorDesign::main_radius_mm);
  EXPECT_NEAR(band.k1, 1 / CarMirrorDesign::band_radius_mm, 0.05 / CarMirrorDesign::band_radius_mm);
  // Regenerating gives the same model (the shipped file is current; byte determinism of the writers on one
  // machine is WritersAreAtomicAndDeterministic's).
  writeCarMirrorStep(file("car-mirror.step"));
  expectSameModel(file("car-mirror.step"), path);
  EXPECT_LT(fs::file_size(path), 100u * 1024u);
}

TEST_F(CadImportTest, ShippedLensIgesLoadsAndMatchesItsDesign) {
  const std::string path = modelPath("lens-front.igs");
  const ImportedModel m = importCadFile(path);
  EXPECT_EQ(m.unit_name, "mm");
  ASSERT_EQ(m.faces.size(), 1u);
  const ImportedFace& f = m.faces[0];
  ASSERT_TRUE(f.trim.has_value());
  const double radius = 0.5 * LensFrontDesign::diameter_mm;
  for (const Vec2& p : f.trim->loop()) EXPECT_NEAR(glm::length(p), radius, kIgesRelTol * 100);
  double worst = 0;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const Vec2 uv(-30 + 3.0 * i, -30 + 3.0 * j);
      if (glm::length(uv) > radius) continue;
      const Vec3 p = f.surface->evaluate(uv.x, uv.y).p;
      worst = std::max(worst, std::abs(p.z - LensFrontDesign::z(p.x, p.y)));
    }
  EXPECT_LT(worst, kLensFitMm + kIgesRelTol * 100);
  const Curvature c = f.surface->curvature(0, 0);
  EXPECT_NEAR(c.mean(), 1 / LensFrontDesign::radius_mm, 0.01 / LensFrontDesign::radius_mm);
  writeLensIges(file("lens-front.igs"));
  expectSameModel(file("lens-front.igs"), path);
  EXPECT_LT(fs::file_size(path), 100u * 1024u);
}

}  // namespace
}  // namespace pvrr::cad
