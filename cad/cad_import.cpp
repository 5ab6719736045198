// STEP and IGES import through OpenCASCADE 7.6 (export: cad_export.cpp).
//
// Conventions (see cad/cad_import.h for the contract):
// - Numbers are in the FILE's length unit on import: the OCCT transfer is told that its "system" length unit
//   is the file's own (StepData_StepModel::SetLocalLengthUnit, IGESData_GlobalSection::SetCascadeUnit), so no
//   unit conversion happens at all. On export the same is done in reverse: the surface's numbers are taken
//   to be in `unit` and written unconverted.
// - A face whose orientation is TopAbs_REVERSED has its u and v directions exchanged
//   (Geom_BSplineSurface::ExchangeUV, exact: only the pole array is transposed), so that du × dv of the
//   returned surface points along the face's outward normal. Its trim loop is exchanged likewise.
// - Analytic surfaces (plane, sphere, cylinder, cone, torus, revolution, extrusion, Bézier) are converted
//   exactly (GeomConvert) over the face's parameter bounds. Where the conversion changes the
//   parameterisation (rational arcs are not angle-parameterised), trim points are mapped onto the B-spline
//   by projecting their 3D points (ShapeAnalysis_Surface).
// - Trim loops: the outer wire's pcurves are sampled at kTrimSamples points in total, half spread by
//   parameter-plane length and half by ∫ sqrt(|curvature|) ds (which equalises the chord error). Inner
//   wires (holes) are not represented by the contract and are ignored.
#include "cad/cad_import.h"
#include "cad/occt_common.h"

#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <GeomConvert.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_BezierSurface.hxx>
#include <Geom_ConicalSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_OffsetSurface.hxx>
#include <Geom_Plane.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_SphericalSurface.hxx>
#include <Geom_SurfaceOfLinearExtrusion.hxx>
#include <Geom_SurfaceOfRevolution.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESData_GlobalSection.hxx>
#include <IGESData_IGESModel.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Reader.hxx>
#include <ShapeAnalysis_Surface.hxx>
#include <Standard_Failure.hxx>
#include <StepData_StepModel.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Pnt2d.hxx>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

#include "pvrr/base/atomic_file.h"
#include "pvrr/base/error.h"

namespace pvrr::cad {
namespace {

namespace fs = std::filesystem;
using occt::LengthUnit;
using occt::poleSize;
using occt::toVec;

// Total number of trim-loop samples per face (the loop handed to Outline::polygon).
constexpr int kTrimSamples = 1024;
// Sub-samples per trim sample used to measure pcurve length and curvature when distributing the samples.
constexpr int kMeasureSamplesPerEdge = 256;
// Relative tolerance (of the parameter range) for deciding that a pcurve runs along the parameter-domain
// boundary, i.e. that the face is not trimmed: far above the 1e-16 rounding of iso-line pcurves, far below
// any real trim (a trim that close to the boundary changes nothing visible).
constexpr double kNaturalBoundaryRelTol = 1e-9;
// Relative tolerance (of the model size) for deciding that an exact conversion kept the parameterisation.
constexpr double kSameParamRelTol = 1e-10;
// Relative tolerance (of the model size) for the projection of trim points onto a converted surface: the
// points lie on it exactly, so the projection must find them to near rounding.
constexpr double kProjectionRelTol = 1e-9;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// SI and conversion-based length unit names as STEP files spell them (OCCT returns them lower case, e.g.
// "millimetre"), plus the short forms.
std::optional<LengthUnit> unitFromName(const std::string& raw) {
  const std::string n = lower(raw);
  struct Entry {
    const char* key;
    LengthUnit unit;
  };
  static const Entry table[] = {
      {"millimetre", {"mm", 1}},  {"millimeter", {"mm", 1}},   {"mm", {"mm", 1}},
      {"centimetre", {"cm", 10}}, {"centimeter", {"cm", 10}},  {"cm", {"cm", 10}},
      {"metre", {"m", 1000}},     {"meter", {"m", 1000}},      {"m", {"m", 1000}},
      {"micrometre", {"um", 1e-3}}, {"micrometer", {"um", 1e-3}}, {"micron", {"um", 1e-3}},
      {"um", {"um", 1e-3}},       {"kilometre", {"km", 1e6}},  {"kilometer", {"km", 1e6}},
      {"km", {"km", 1e6}},        {"inch", {"in", 25.4}},      {"in", {"in", 25.4}},
      {"foot", {"ft", 304.8}},    {"feet", {"ft", 304.8}},     {"ft", {"ft", 304.8}},
      {"mil", {"mil", 0.0254}},   {"mile", {"mi", 1609344}},   {"mi", {"mi", 1609344}},
  };
  for (const Entry& e : table)
    if (n == e.key) return e.unit;
  return std::nullopt;
}

// IGES global section unit flag (IGES 5.3, table 3).
std::optional<LengthUnit> unitFromIgesFlag(int flag) {
  switch (flag) {
    case 1: return LengthUnit{"in", 25.4};
    case 2: return LengthUnit{"mm", 1};
    case 4: return LengthUnit{"ft", 304.8};
    case 5: return LengthUnit{"mi", 1609344};
    case 6: return LengthUnit{"m", 1000};
    case 7: return LengthUnit{"km", 1e6};
    case 8: return LengthUnit{"mil", 0.0254};
    case 9: return LengthUnit{"um", 1e-3};
    case 10: return LengthUnit{"cm", 10};
    case 11: return LengthUnit{"uin", 25.4e-6};
    default: return std::nullopt;
  }
}

std::string readTail(const std::string& path, std::size_t bytes) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  const std::streamoff start = size > std::streamoff(bytes) ? size - std::streamoff(bytes) : 0;
  in.seekg(start);
  std::string s(std::size_t(size - start), '\0');
  in.read(s.data(), std::streamsize(s.size()));
  return s;
}

void requireReadableFile(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path + ": file not found");
  if (!fs::is_regular_file(path, ec)) throw Error(path + ": not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open for reading");
  if (fs::file_size(path, ec) == 0) throw Error(path + ": file is empty");
}

// A STEP file ends with "END-ISO-10303-21;" (ISO 10303-21 §5); OCCT's parser accepts a file cut short and
// silently returns what it could read, so a truncated file is caught here.
void requireStepTrailer(const std::string& path) {
  const std::string tail = readTail(path, 512);
  if (tail.find("END-ISO-10303-21") == std::string::npos)
    throw Error(path + ": truncated or not a STEP file (no END-ISO-10303-21; trailer)");
}

// An ASCII IGES file ends with the Terminate section: its last line has 'T' in column 73.
void requireIgesTrailer(const std::string& path) {
  std::string tail = readTail(path, 400);
  while (!tail.empty() && (tail.back() == '\n' || tail.back() == '\r' || tail.back() == ' ')) tail.pop_back();
  const std::size_t nl = tail.find_last_of('\n');
  const std::string last = nl == std::string::npos ? tail : tail.substr(nl + 1);
  if (last.size() < 73 || last[72] != 'T')
    throw Error(path + ": truncated or not an IGES file (no Terminate section at the end)");
}

std::string surfaceTypeName(const Handle(Geom_Surface)& s) {
  if (s->IsKind(STANDARD_TYPE(Geom_BSplineSurface))) return "b-spline";
  if (s->IsKind(STANDARD_TYPE(Geom_BezierSurface))) return "bezier";
  if (s->IsKind(STANDARD_TYPE(Geom_Plane))) return "plane";
  if (s->IsKind(STANDARD_TYPE(Geom_SphericalSurface))) return "sphere";
  if (s->IsKind(STANDARD_TYPE(Geom_CylindricalSurface))) return "cylinder";
  if (s->IsKind(STANDARD_TYPE(Geom_ConicalSurface))) return "cone";
  if (s->IsKind(STANDARD_TYPE(Geom_ToroidalSurface))) return "torus";
  if (s->IsKind(STANDARD_TYPE(Geom_SurfaceOfRevolution))) return "revolution";
  if (s->IsKind(STANDARD_TYPE(Geom_SurfaceOfLinearExtrusion))) return "extrusion";
  if (s->IsKind(STANDARD_TYPE(Geom_OffsetSurface))) return "offset";
  return lower(s->DynamicType()->Name());
}

// Full knot vector (each knot repeated by its multiplicity) from OCCT's distinct knots + multiplicities.
std::vector<double> flatKnots(const TColStd_Array1OfReal& seq) {
  std::vector<double> k;
  k.reserve(std::size_t(seq.Length()));
  for (int i = seq.Lower(); i <= seq.Upper(); ++i) k.push_back(seq(i));
  return k;
}

NurbsDefinition toDefinition(const Handle(Geom_BSplineSurface)& bs) {
  NurbsDefinition d;
  d.degree_u = bs->UDegree();
  d.degree_v = bs->VDegree();
  d.count_u = bs->NbUPoles();
  d.count_v = bs->NbVPoles();
  d.knots_u = flatKnots(bs->UKnotSequence());
  d.knots_v = flatKnots(bs->VKnotSequence());
  const bool rational = bs->IsURational() || bs->IsVRational();
  d.points.resize(std::size_t(d.count_u) * std::size_t(d.count_v));
  if (rational) d.weights.resize(d.points.size());
  for (int i = 0; i < d.count_u; ++i)
    for (int j = 0; j < d.count_v; ++j) {
      const std::size_t k = std::size_t(i) * std::size_t(d.count_v) + std::size_t(j);
      d.points[k] = toVec(bs->Pole(i + 1, j + 1));
      if (rational) d.weights[k] = bs->Weight(i + 1, j + 1);
    }
  return d;
}

struct PcurveEdge {
  Handle(Geom2d_Curve) curve;
  double t0 = 0, t1 = 1;  // traversal order along the wire (t1 < t0 for a reversed edge)
};

struct SampledLoop {
  std::vector<Vec2> points;   // in the original surface's (u, v)
  std::vector<Vec2> mids;     // curve points at each chord's mid-parameter (chord k: points[k] -> points[k+1])
};

Vec2 at(const PcurveEdge& e, double s) {
  const gp_Pnt2d p = e.curve->Value(e.t0 + (e.t1 - e.t0) * s);
  return Vec2(p.X(), p.Y());
}

// Samples the loop: each edge contributes its start point and interior samples (its end is the next edge's
// start). Within an edge the samples are equally spaced in arc length of the parameter-plane curve.
SampledLoop sampleLoop(const std::vector<PcurveEdge>& edges) {
  struct Measure {
    std::vector<double> s;    // curve fraction of each sub-sample
    std::vector<double> len;  // cumulative length
    double curv = 0;          // ∫ sqrt(|κ|) ds
  };
  std::vector<Measure> ms(edges.size());
  double total_len = 0, total_curv = 0;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    Measure& m = ms[e];
    const int n = kMeasureSamplesPerEdge;
    std::vector<Vec2> p(std::size_t(n) + 1);
    for (int k = 0; k <= n; ++k) {
      m.s.push_back(double(k) / n);
      p[std::size_t(k)] = at(edges[e], double(k) / n);
    }
    m.len.push_back(0);
    for (int k = 1; k <= n; ++k) m.len.push_back(m.len.back() + glm::length(p[std::size_t(k)] - p[std::size_t(k) - 1]));
    for (int k = 1; k < n; ++k) {
      const Vec2 a = p[std::size_t(k)] - p[std::size_t(k) - 1], b = p[std::size_t(k) + 1] - p[std::size_t(k)];
      const double la = glm::length(a), lb = glm::length(b);
      if (la <= 0 || lb <= 0) continue;
      const double turn = std::abs(std::atan2(a.x * b.y - a.y * b.x, glm::dot(a, b)));
      const double ds = 0.5 * (la + lb);
      m.curv += std::sqrt(turn / ds) * ds;
    }
    total_len += m.len.back();
    total_curv += m.curv;
  }
  SampledLoop out;
  if (total_len <= 0) return out;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const Measure& m = ms[e];
    double share = m.len.back() / total_len;
    if (total_curv > 0) share = 0.5 * share + 0.5 * m.curv / total_curv;
    const int count = std::max(2, int(std::lround(share * kTrimSamples)));
    // Parameter fraction at arc-length fraction f (linear interpolation of the measured table).
    auto fractionAt = [&](double f) {
      const double target = f * m.len.back();
      const auto it = std::lower_bound(m.len.begin(), m.len.end(), target);
      if (it == m.len.begin()) return 0.0;
      if (it == m.len.end()) return 1.0;
      const std::size_t k = std::size_t(it - m.len.begin());
      const double l0 = m.len[k - 1], l1 = m.len[k];
      const double w = l1 > l0 ? (target - l0) / (l1 - l0) : 0.0;
      return m.s[k - 1] + w * (m.s[k] - m.s[k - 1]);
    };
    std::vector<double> s(std::size_t(count) + 1);
    for (int k = 0; k <= count; ++k) s[std::size_t(k)] = m.len.back() > 0 ? fractionAt(double(k) / count) : double(k) / count;
    s.front() = 0;
    s.back() = 1;
    for (int k = 0; k < count; ++k) {
      out.points.push_back(at(edges[e], s[std::size_t(k)]));
      out.mids.push_back(at(edges[e], 0.5 * (s[std::size_t(k)] + s[std::size_t(k) + 1])));
    }
  }
  return out;
}

double distanceToSegment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 ab = b - a;
  const double l2 = glm::dot(ab, ab);
  const double t = l2 > 0 ? std::clamp(glm::dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

// Area centroid of a simple closed polygon (falls back to the vertex mean for a degenerate one).
Vec2 polygonCentroid(const std::vector<Vec2>& p) {
  double a2 = 0;
  Vec2 c(0);
  Vec2 mean(0);
  for (const Vec2& q : p) mean += q;
  mean /= double(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2 u = p[i] - mean, w = p[(i + 1) % p.size()] - mean;
    const double cr = u.x * w.y - u.y * w.x;
    a2 += cr;
    c += (u + w) * cr;
  }
  if (std::abs(a2) <= 0) return mean;
  return mean + c / (3.0 * a2);
}

// True when the polar angle about `c` changes monotonically along the loop and winds exactly once.
bool starShapedAbout(const std::vector<Vec2>& p, Vec2 c) {
  double total = 0;
  int sign = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2 a = p[i] - c, b = p[(i + 1) % p.size()] - c;
    const double d = std::atan2(a.x * b.y - a.y * b.x, glm::dot(a, b));
    if (d == 0) continue;
    const int s = d > 0 ? 1 : -1;
    if (sign == 0) sign = s;
    if (s != sign) return false;
    total += d;
  }
  return std::abs(std::abs(total) - 2 * kPi) < 1e-6;
}

struct FaceContext {
  const std::string& path;
  int index;
  std::string where() const { return path + ": face " + std::to_string(index); }
};

ImportedFace convertFace(const TopoDS_Face& face, const FaceContext& ctx) {
  TopLoc_Location loc;
  Handle(Geom_Surface) s0 = BRep_Tool::Surface(face, loc);  // untransformed; pcurves live in its (u, v)
  if (s0.IsNull()) throw Error(ctx.where() + ": face has no surface");
  Handle(Geom_Surface) basis = s0;
  while (auto t = Handle(Geom_RectangularTrimmedSurface)::DownCast(basis)) basis = t->BasisSurface();

  ImportedFace out;
  out.source_type = surfaceTypeName(basis);

  double u0, u1, v0, v1;
  BRepTools::UVBounds(face, u0, u1, v0, v1);
  if (!(u1 > u0) || !(v1 > v0)) throw Error(ctx.where() + ": face has an empty parameter range");

  // Outer wire as pcurves in traversal order.
  std::vector<PcurveEdge> edges;
  const TopoDS_Wire outer = BRepTools::OuterWire(face);
  if (!outer.IsNull()) {
    for (BRepTools_WireExplorer ex(outer, face); ex.More(); ex.Next()) {
      const TopoDS_Edge& e = ex.Current();
      double f, l;
      Handle(Geom2d_Curve) c = BRep_Tool::CurveOnSurface(e, face, f, l);
      if (c.IsNull()) throw Error(ctx.where() + ": a boundary edge has no curve in the surface's (u, v)");
      PcurveEdge pe{c, f, l};
      if (ex.Orientation() == TopAbs_REVERSED) std::swap(pe.t0, pe.t1);
      edges.push_back(pe);
    }
  }

  // Natural boundary: every pcurve runs along an edge of the (u, v) bounding rectangle.
  const double tol_u = kNaturalBoundaryRelTol * (u1 - u0), tol_v = kNaturalBoundaryRelTol * (v1 - v0);
  bool natural = true;
  for (const PcurveEdge& e : edges) {
    for (int k = 0; k <= 16 && natural; ++k) {
      const Vec2 p = at(e, k / 16.0);
      const bool on = std::abs(p.x - u0) <= tol_u || std::abs(p.x - u1) <= tol_u || std::abs(p.y - v0) <= tol_v ||
                      std::abs(p.y - v1) <= tol_v;
      natural = on;
    }
  }

  // Exact B-spline over the face's parameter bounds.
  Handle(Geom_BSplineSurface) bs;
  bool same_param = true;
  if (auto b = Handle(Geom_BSplineSurface)::DownCast(basis)) {
    bs = Handle(Geom_BSplineSurface)::DownCast(b->Copy());
    double bu0, bu1, bv0, bv1;
    bs->Bounds(bu0, bu1, bv0, bv1);
    const bool inside = u0 >= bu0 - tol_u && u1 <= bu1 + tol_u && v0 >= bv0 - tol_v && v1 <= bv1 + tol_v;
    const bool sub = u0 > bu0 + tol_u || u1 < bu1 - tol_u || v0 > bv0 + tol_v || v1 < bv1 - tol_v;
    if ((natural && sub) || bs->IsUPeriodic() || bs->IsVPeriodic()) {
      if (!inside && !bs->IsUPeriodic() && !bs->IsVPeriodic())
        throw Error(ctx.where() + ": face's parameter range exceeds its B-spline surface");
      bs->Segment(std::max(u0, inside ? u0 : bu0), std::min(u1, inside ? u1 : bu1), std::max(v0, inside ? v0 : bv0),
                  std::min(v1, inside ? v1 : bv1));
    }
  } else {
    Handle(Geom_Surface) trimmed = new Geom_RectangularTrimmedSurface(basis, u0, u1, v0, v1);
    try {
      bs = GeomConvert::SurfaceToBSplineSurface(trimmed);
    } catch (const Standard_Failure& f) {
      throw Error(ctx.where() + ": cannot convert a " + out.source_type + " surface to a B-spline (" + occt::failureMessage(f) +
                  ")");
    }
    if (bs.IsNull()) throw Error(ctx.where() + ": cannot convert a " + out.source_type + " surface to a B-spline");
    double bu0, bu1, bv0, bv1;
    bs->Bounds(bu0, bu1, bv0, bv1);
    const double size = poleSize(bs);
    for (int i = 0; i <= 4 && same_param; ++i)
      for (int j = 0; j <= 4 && same_param; ++j) {
        const double u = u0 + (u1 - u0) * i / 4, v = v0 + (v1 - v0) * j / 4;
        same_param = std::abs(u - (bu0 + (bu1 - bu0) * i / 4)) <= tol_u &&
                     std::abs(v - (bv0 + (bv1 - bv0) * j / 4)) <= tol_v &&
                     bs->Value(u, v).Distance(basis->Value(u, v)) <= kSameParamRelTol * size;
      }
  }

  // A periodic B-spline (e.g. a full turn of a converted sphere) in the plain form: same geometry and
  // parameters, a clamped knot vector.
  if (bs->IsUPeriodic()) bs->SetUNotPeriodic();
  if (bs->IsVPeriodic()) bs->SetVNotPeriodic();

  if (!natural && !edges.empty()) {
    SampledLoop loop = sampleLoop(edges);
    if (loop.points.size() < 3) throw Error(ctx.where() + ": trim loop is degenerate");
    if (!same_param) {
      // Map (u, v) of the original surface onto the converted B-spline through the 3D points.
      Handle(ShapeAnalysis_Surface) sas = new ShapeAnalysis_Surface(bs);
      const double preci = kProjectionRelTol * poleSize(bs);
      auto mapAll = [&](std::vector<Vec2>& pts) {
        gp_Pnt2d prev;
        for (std::size_t k = 0; k < pts.size(); ++k) {
          const gp_Pnt p3 = basis->Value(pts[k].x, pts[k].y);
          const gp_Pnt2d q = k == 0 ? sas->ValueOfUV(p3, preci) : sas->NextValueOfUV(prev, p3, preci);
          if (sas->Gap() > 100 * preci)
            throw Error(ctx.where() + ": trim point could not be mapped onto the converted surface (gap " +
                        std::to_string(sas->Gap()) + ")");
          pts[k] = Vec2(q.X(), q.Y());
          prev = q;
        }
      };
      mapAll(loop.points);
      mapAll(loop.mids);
    }
    double chord_uv = 0, chord_3d = 0;
    for (std::size_t k = 0; k < loop.points.size(); ++k) {
      const Vec2 a = loop.points[k], b = loop.points[(k + 1) % loop.points.size()], m = loop.mids[k];
      chord_uv = std::max(chord_uv, distanceToSegment(m, a, b));
      const Vec2 c = 0.5 * (a + b);
      chord_3d = std::max(chord_3d, bs->Value(m.x, m.y).Distance(bs->Value(c.x, c.y)));
    }
    if (face.Orientation() == TopAbs_REVERSED)
      for (Vec2& p : loop.points) std::swap(p.x, p.y);
    const Vec2 centre = polygonCentroid(loop.points);
    if (!starShapedAbout(loop.points, centre))
      throw Error(ctx.where() + ": trim loop is not star-shaped about its centroid (not supported)");
    out.trim = Outline::polygon(loop.points, centre);
    out.trim_chord_error_uv = chord_uv;
    out.trim_chord_error = chord_3d;
  }

  if (!loc.IsIdentity()) bs->Transform(loc.Transformation());
  if (face.Orientation() == TopAbs_REVERSED) bs->ExchangeUV();
  out.surface = std::make_shared<NurbsSurface>(toDefinition(bs), ctx.where());
  return out;
}

ImportedModel facesOf(const TopoDS_Shape& shape, const std::string& path, const LengthUnit& unit) {
  ImportedModel model;
  model.unit_name = unit.name;
  model.unit_to_metres = unit.mm * 1e-3;
  int index = 0;
  for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next(), ++index)
    model.faces.push_back(convertFace(TopoDS::Face(ex.Current()), FaceContext{path, index}));
  if (model.faces.empty()) throw Error(path + ": contains no surface (no face to import)");
  return model;
}

ImportedModel importStep(const std::string& path) {
  requireStepTrailer(path);
  STEPControl_Reader reader;
  const IFSelect_ReturnStatus st = reader.ReadFile(path.c_str());
  if (st != IFSelect_RetDone) throw Error(path + ": not a readable STEP file (the parser failed)");
  TColStd_SequenceOfAsciiString lengths, angles, solids;
  reader.FileUnits(lengths, angles, solids);
  LengthUnit unit{"mm", 1};  // OCCT's assumption for a file that names no unit
  for (int i = 1; i <= lengths.Length(); ++i) {
    const auto u = unitFromName(lengths(i).ToCString());
    if (!u) throw Error(path + ": unknown STEP length unit \"" + std::string(lengths(i).ToCString()) + "\"");
    if (i > 1 && u->name != unit.name)
      throw Error(path + ": mixed length units (" + unit.name + " and " + u->name + ") are not supported");
    unit = *u;
  }
  reader.SetSystemLengthUnit(unit.mm);  // no conversion: numbers stay in the file's unit
  if (reader.TransferRoots() == 0 || reader.NbShapes() == 0)
    throw Error(path + ": contains no shape that could be transferred");
  return facesOf(reader.OneShape(), path, unit);
}

ImportedModel importIges(const std::string& path) {
  requireIgesTrailer(path);
  // Keep B-spline surfaces whole (the default splits them at C0/C1 knots into several faces).
  Interface_Static::SetIVal("read.iges.bspline.continuity", 0);
  IGESControl_Reader reader;
  const IFSelect_ReturnStatus st = reader.ReadFile(path.c_str());
  if (st != IFSelect_RetDone) throw Error(path + ": not a readable IGES file (the parser failed)");
  Handle(IGESData_IGESModel) model = reader.IGESModel();
  if (model.IsNull()) throw Error(path + ": not a readable IGES file");
  IGESData_GlobalSection gs = model->GlobalSection();
  LengthUnit unit;
  if (const auto u = unitFromIgesFlag(gs.UnitFlag())) {
    unit = *u;
  } else {
    const double mm = gs.UnitValue();  // OCCT returns it in millimetres
    if (!(mm > 0)) throw Error(path + ": IGES unit flag " + std::to_string(gs.UnitFlag()) + " is not supported");
    const Handle(TCollection_HAsciiString) name = gs.UnitName();
    unit = {name.IsNull() ? std::string("unit") : lower(name->ToCString()), mm};
  }
  gs.SetCascadeUnit(unit.mm);  // no conversion: numbers stay in the file's unit
  model->SetGlobalSection(gs);
  if (reader.TransferRoots() == 0 || reader.NbShapes() == 0)
    throw Error(path + ": contains no shape that could be transferred");
  return facesOf(reader.OneShape(), path, unit);
}

}  // namespace

// OpenCASCADE's STEP and IGES readers crash on some malformed files (fuzz findings, tests/fuzz/corpus/cad/
// finding-*: a STEP list with a broken reference leaves a null entity that the transfer dereferences; an IGES
// B-spline whose counts do not match its data crashes the parser itself), where no check of ours can run
// first. So the import runs once in a child process: when the child dies (a signal, or any exit but
// "imported" or "refused with a pvrr::Error"), the file is refused with one line; otherwise the import runs
// again here, where a refusal gives its own message. Costs one more read of the file (milliseconds for
// a lens or mirror face). The child restores the default crash signals (a sanitizer's handler would turn a
// crash into an ordinary exit) and leaves with _exit (no atexit handlers, no stdio buffers flushed twice).
static void requireImportSurvives(const std::string& path, bool step) {
  std::fflush(nullptr);
  const pid_t child = ::fork();
  if (child < 0) return;  // no process to spare: import in-process, as before
  if (child == 0) {
    for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) std::signal(sig, SIG_DFL);
    int code = 4;
    try {
      (void)(step ? importStep(path) : importIges(path));
      code = 0;
    } catch (const Error&) {
      code = 3;
    } catch (const Standard_Failure&) {
      code = 3;
    } catch (...) {
    }
    ::_exit(code);
  }
  // A child that never ends (a reader stuck on a lock another thread held at the fork) must not hang the
  // import: after kChildSeconds it is killed and the import runs in-process, as without the child.
  constexpr double kChildSeconds = 30;
  int status = 0;
  for (double waited = 0;; waited += 2e-3) {
    const pid_t r = ::waitpid(child, &status, WNOHANG);
    if (r == child || (r < 0 && errno != EINTR)) break;
    if (waited > kChildSeconds) {
      ::kill(child, SIGKILL);
      while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
      }
      return;
    }
    ::usleep(2000);
  }
  const std::string format = step ? "STEP" : "IGES";
  if (WIFSIGNALED(status))
    throw Error(path + ": not a valid " + format + " file: OpenCASCADE's reader crashed on it (" +
                ::strsignal(WTERMSIG(status)) + ")");
  if (!WIFEXITED(status) || (WEXITSTATUS(status) != 0 && WEXITSTATUS(status) != 3))
    throw Error(path + ": not a valid " + format + " file: OpenCASCADE's reader failed on it (exit status " +
                std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
}

ImportedModel importCadFile(const std::string& path) {
  const std::string ext = lower(fs::path(path).extension().string());
  const bool step = ext == ".step" || ext == ".stp";
  const bool iges = ext == ".iges" || ext == ".igs";
  if (!step && !iges) throw Error(path + ": unknown CAD file type \"" + ext + "\": expected .step, .stp, .iges or .igs");
  requireReadableFile(path);
  std::lock_guard<std::mutex> lock(occt::translationMutex());
  occt::silence();
  try {
    requireImportSurvives(path, step);
    return step ? importStep(path) : importIges(path);
  } catch (const Standard_Failure& f) {
    throw Error(path + ": OpenCASCADE failed to read the file (" + occt::failureMessage(f) + ")");
  }
}


}  // namespace pvrr::cad
