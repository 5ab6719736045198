// STEP and IGES export of one (optionally trimmed) NURBS face through OpenCASCADE 7.6.
//
// Conventions (see cad/cad_import.h for the contract): the surface's numbers are taken to be in `unit` and
// written unconverted (the writer's "system" length unit is set to the file's own). Trim loops become
// closed (u, v) pcurves, counter-clockwise; header fields are fixed so the files are reproducible byte for
// byte.
#include <APIHeaderSection_MakeHeader.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepLib.hxx>
#include <GCE2d_MakeSegment.hxx>
#include <Geom2d_Circle.hxx>
#include <Geom2d_Ellipse.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Writer.hxx>
#include <IGESData_GlobalSection.hxx>
#include <IGESData_IGESModel.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Writer.hxx>
#include <StepBasic_Product.hxx>
#include <StepData_StepModel.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Ax22d.hxx>
#include <gp_Pnt2d.hxx>

#include <algorithm>
#include <filesystem>

#include "cad/cad_import.h"
#include "cad/occt_common.h"
#include "pvrr/base/atomic_file.h"
#include "pvrr/base/error.h"

namespace pvrr::cad {
namespace {

namespace fs = std::filesystem;
using occt::LengthUnit;
using occt::poleSize;

// 3D curves built for the writers' trim edges (only other CAD systems use them; we read the pcurves),
// relative to the model size.
constexpr double kCurve3dRelTol = 1e-7;

LengthUnit writeUnit(const std::string& unit, const std::string& path) {
  if (unit == "mm") return {"mm", 1};
  if (unit == "m") return {"m", 1000};
  throw Error(path + ": cannot write in unit \"" + unit + "\": expected \"mm\" or \"m\"");
}

// Distinct knots and multiplicities from a full knot vector (exact comparison: repeated knots are copies).
void splitKnots(const std::vector<double>& flat, TColStd_Array1OfReal& knots, TColStd_Array1OfInteger& mults) {
  std::vector<double> k;
  std::vector<int> m;
  for (double t : flat) {
    if (!k.empty() && t == k.back()) {
      ++m.back();
    } else {
      k.push_back(t);
      m.push_back(1);
    }
  }
  knots.Resize(1, int(k.size()), false);
  mults.Resize(1, int(m.size()), false);
  for (std::size_t i = 0; i < k.size(); ++i) {
    knots(int(i) + 1) = k[i];
    mults(int(i) + 1) = m[i];
  }
}

Handle(Geom_BSplineSurface) toOcct(const NurbsDefinition& d) {
  TColgp_Array2OfPnt poles(1, d.count_u, 1, d.count_v);
  TColStd_Array2OfReal weights(1, d.count_u, 1, d.count_v);
  for (int i = 0; i < d.count_u; ++i)
    for (int j = 0; j < d.count_v; ++j) {
      const std::size_t k = std::size_t(i) * std::size_t(d.count_v) + std::size_t(j);
      poles(i + 1, j + 1) = gp_Pnt(d.points[k].x, d.points[k].y, d.points[k].z);
      weights(i + 1, j + 1) = d.weights.empty() ? 1.0 : d.weights[k];
    }
  TColStd_Array1OfReal ku(1, 1), kv(1, 1);
  TColStd_Array1OfInteger mu(1, 1), mv(1, 1);
  splitKnots(d.knots_u, ku, mu);
  splitKnots(d.knots_v, kv, mv);
  const bool rational = std::any_of(d.weights.begin(), d.weights.end(), [](double w) { return w != 1.0; });
  if (!rational) return new Geom_BSplineSurface(poles, ku, kv, mu, mv, d.degree_u, d.degree_v);
  return new Geom_BSplineSurface(poles, weights, ku, kv, mu, mv, d.degree_u, d.degree_v);
}


// The trim loop as closed (u, v) pcurves on `surf`, counter-clockwise (outer boundary).
TopoDS_Wire trimWire(const Outline& trim, const Handle(Geom_Surface)& surf, const std::string& path) {
  const Vec2 c = trim.centre();
  std::vector<Handle(Geom2d_Curve)> curves;
  std::vector<std::pair<double, double>> ranges;
  auto segment = [&](Vec2 a, Vec2 b) {
    if (glm::length(b - a) <= 0) return;
    GCE2d_MakeSegment ms(gp_Pnt2d(a.x, a.y), gp_Pnt2d(b.x, b.y));
    if (!ms.IsDone()) throw Error(path + ": degenerate trim segment");
    Handle(Geom2d_Curve) seg = Handle(Geom2d_TrimmedCurve)(ms.Value());
    curves.push_back(seg);
    ranges.emplace_back(seg->FirstParameter(), seg->LastParameter());
  };
  switch (trim.shape()) {
    case Outline::Shape::Rectangle: {
      const double hw = 0.5 * trim.width(), hh = 0.5 * trim.height();
      const double r = std::min({trim.cornerRadius(), hw, hh});
      // Counter-clockwise from the bottom edge; each corner a quarter circle.
      const Vec2 corner_centre[4] = {c + Vec2(hw - r, -hh + r), c + Vec2(hw - r, hh - r), c + Vec2(-hw + r, hh - r),
                                     c + Vec2(-hw + r, -hh + r)};
      const Vec2 side_start[4] = {c + Vec2(-hw + r, -hh), c + Vec2(hw, -hh + r), c + Vec2(hw - r, hh),
                                  c + Vec2(-hw, hh - r)};
      const Vec2 side_end[4] = {c + Vec2(hw - r, -hh), c + Vec2(hw, hh - r), c + Vec2(-hw + r, hh),
                                c + Vec2(-hw, -hh + r)};
      for (int k = 0; k < 4; ++k) {
        segment(side_start[k], side_end[k]);
        if (r > 0) {
          const Vec2 cc = corner_centre[k];
          Handle(Geom2d_Circle) circ = new Geom2d_Circle(gp_Ax22d(gp_Pnt2d(cc.x, cc.y), gp_Dir2d(1, 0)), r);
          const double a0 = -0.5 * kPi + 0.5 * kPi * k;
          curves.push_back(circ);
          ranges.emplace_back(a0, a0 + 0.5 * kPi);
        }
      }
      break;
    }
    case Outline::Shape::Circle:
    case Outline::Shape::Ellipse: {
      const double a = 0.5 * trim.width(), b = 0.5 * trim.height();
      if (a == b) {
        curves.push_back(new Geom2d_Circle(gp_Ax22d(gp_Pnt2d(c.x, c.y), gp_Dir2d(1, 0)), a));
      } else if (a > b) {
        curves.push_back(new Geom2d_Ellipse(gp_Ax22d(gp_Pnt2d(c.x, c.y), gp_Dir2d(1, 0)), a, b));
      } else {
        curves.push_back(new Geom2d_Ellipse(gp_Ax22d(gp_Pnt2d(c.x, c.y), gp_Dir2d(0, 1), gp_Dir2d(-1, 0)), b, a));
      }
      ranges.emplace_back(0.0, 2 * kPi);
      break;
    }
    case Outline::Shape::Polygon: {
      std::vector<Vec2> p = trim.loop();
      if (p.size() < 3) throw Error(path + ": trim polygon has fewer than 3 points");
      double a2 = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec2 u = p[i], w = p[(i + 1) % p.size()];
        a2 += u.x * w.y - u.y * w.x;
      }
      if (a2 < 0) std::reverse(p.begin(), p.end());
      for (std::size_t i = 0; i < p.size(); ++i) segment(p[i], p[(i + 1) % p.size()]);
      break;
    }
  }
  // Shared vertices: each curve's end vertex is the next curve's start vertex.
  std::vector<TopoDS_Vertex> verts;
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const gp_Pnt2d uv = curves[k]->Value(ranges[k].first);
    verts.push_back(BRepBuilderAPI_MakeVertex(surf->Value(uv.X(), uv.Y())));
  }
  BRepBuilderAPI_MakeWire mw;
  for (std::size_t k = 0; k < curves.size(); ++k) {
    BRepBuilderAPI_MakeEdge me(curves[k], surf, verts[k], verts[(k + 1) % curves.size()], ranges[k].first,
                               ranges[k].second);
    if (!me.IsDone()) throw Error(path + ": cannot build trim edge " + std::to_string(k));
    mw.Add(me.Edge());
  }
  if (!mw.IsDone()) throw Error(path + ": cannot build the trim wire");
  return mw.Wire();
}

TopoDS_Face makeFace(const NurbsSurface& s, const std::optional<Outline>& trim, const std::string& path) {
  Handle(Geom_BSplineSurface) bs = toOcct(s.definition());
  if (!trim) {
    BRepBuilderAPI_MakeFace mf(bs, Precision::Confusion());
    if (!mf.IsDone()) throw Error(path + ": cannot build a face from the surface");
    return mf.Face();
  }
  const ParamDomain dom = s.domain();
  const double tol = 1e-12 * std::max(dom.u1 - dom.u0, dom.v1 - dom.v0);
  for (int k = 0; k < 256; ++k) {
    const double th = 2 * kPi * k / 256;
    const Vec2 p = trim->centre() + trim->boundaryRadius(th) * Vec2(std::cos(th), std::sin(th));
    if (!dom.contains(p.x, p.y, tol))
      throw Error(path + ": the trim outline (" + trim->describe() + ") leaves the surface's parameter domain");
  }
  const TopoDS_Wire wire = trimWire(*trim, bs, path);
  BRepBuilderAPI_MakeFace mf(bs, wire, true);
  if (!mf.IsDone()) throw Error(path + ": cannot build the trimmed face");
  TopoDS_Face face = mf.Face();
  BRepLib::BuildCurves3d(face, kCurve3dRelTol * poleSize(bs));
  return face;
}

// Fixed header values make the files reproducible byte for byte.
constexpr const char* kStepTimeStamp = "2000-01-01T00:00:00";
constexpr const char* kIgesDate = "20000101.000000";
constexpr const char* kAuthor = "pvrr";

// Writes the face of `s` (trimmed by `trim`) to `path` all or nothing, under OCCT's translation lock:
// `translate(tmp, face, u)` fills the temporary file; OCCT's exceptions become one line naming the file.
template <typename Translate>
void writeFace(const std::string& path, const NurbsSurface& s, const std::optional<Outline>& trim,
               const std::string& unit, const char* format, Translate&& translate) {
  const LengthUnit u = writeUnit(unit, path);
  std::lock_guard<std::mutex> lock(occt::translationMutex());
  occt::silence();
  writeAtomic(
      path,
      [&](const std::string& tmp) {
        try {
          translate(tmp, makeFace(s, trim, path), u);
        } catch (const Standard_Failure& f) {
          throw Error(path + ": OpenCASCADE failed to write " + format + " (" + occt::failureMessage(f) + ")");
        }
      },
      MissingFolder::Fail);
}

}  // namespace

NurbsSurface scaled(const NurbsSurface& s, double factor) {
  NurbsDefinition d = s.definition();
  for (Vec3& p : d.points) p *= factor;
  return NurbsSurface(std::move(d), s.describe());
}

void writeStep(const std::string& path, const NurbsSurface& s, const std::optional<Outline>& trim,
               const std::string& unit) {
  writeFace(path, s, trim, unit, "STEP", [&](const std::string& tmp, const TopoDS_Face& face, const LengthUnit& u) {
    Interface_Static::SetCVal("write.step.unit", unit == "mm" ? "MM" : "M");
    Interface_Static::SetIVal("write.surfacecurve.mode", 1);  // write the pcurves
    STEPControl_Writer writer;
    // Our numbers are already in the file's unit: no conversion on the way out.
    writer.Model()->SetLocalLengthUnit(u.mm);
    if (writer.Transfer(face, STEPControl_AsIs) != IFSelect_RetDone)
      throw Error(path + ": OpenCASCADE could not translate the face to STEP");
    // OCCT names the product "Open CASCADE STEP translator 7.6 <n>" with a per-process counter; the
    // file's stem keeps the output reproducible.
    const Handle(StepData_StepModel) model = writer.Model();
    const Handle(TCollection_HAsciiString) product =
        new TCollection_HAsciiString(fs::path(path).stem().string().c_str());
    for (int i = 1; i <= model->NbEntities(); ++i)
      if (const Handle(StepBasic_Product) p = Handle(StepBasic_Product)::DownCast(model->Value(i))) {
        p->SetId(product);
        p->SetName(product);
      }
    APIHeaderSection_MakeHeader header(model);
    header.SetName(new TCollection_HAsciiString(fs::path(path).filename().string().c_str()));
    header.SetTimeStamp(new TCollection_HAsciiString(kStepTimeStamp));
    header.SetAuthorValue(1, new TCollection_HAsciiString(kAuthor));
    header.SetOrganizationValue(1, new TCollection_HAsciiString(kAuthor));
    header.SetOriginatingSystem(new TCollection_HAsciiString("pvrr (OpenCASCADE 7.6)"));
    header.SetAuthorisation(new TCollection_HAsciiString(""));
    if (writer.Write(tmp.c_str()) != IFSelect_RetDone) throw Error(path + ": cannot write the STEP file");
  });
}

void writeIges(const std::string& path, const NurbsSurface& s, const std::optional<Outline>& trim,
               const std::string& unit) {
  writeFace(path, s, trim, unit, "IGES", [&](const std::string& tmp, const TopoDS_Face& face, const LengthUnit& u) {
    Interface_Static::SetCVal("write.iges.header.author", kAuthor);
    Interface_Static::SetCVal("write.iges.header.company", kAuthor);
    Interface_Static::SetCVal("write.iges.header.product", "pvrr");
    Interface_Static::SetCVal("write.iges.header.receiver", "");
    // Mode 0: faces as trimmed surfaces (entity 144), which every IGES reader understands.
    IGESControl_Writer writer(unit == "mm" ? "MM" : "M", 0);
    IGESData_GlobalSection gs = writer.Model()->GlobalSection();
    gs.SetCascadeUnit(u.mm);  // our numbers are already in the file's unit
    gs.SetDate(new TCollection_HAsciiString(kIgesDate));
    gs.SetLastChangeDate(new TCollection_HAsciiString(kIgesDate));
    gs.SetFileName(new TCollection_HAsciiString(fs::path(path).filename().string().c_str()));
    gs.SetAuthorName(new TCollection_HAsciiString(kAuthor));
    gs.SetCompanyName(new TCollection_HAsciiString(kAuthor));
    writer.Model()->SetGlobalSection(gs);
    if (!writer.AddShape(face)) throw Error(path + ": OpenCASCADE could not translate the face to IGES");
    writer.ComputeModel();
    if (!writer.Write(tmp.c_str())) throw Error(path + ": cannot write the IGES file");
  });
}

}  // namespace pvrr::cad
