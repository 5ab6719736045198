// Everything that talks to VTK: reading OBJ/PLY environment meshes, writing PLY and VTP.
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkOBJReader.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkPLYReader.h>
#include <vtkPLYWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkTriangleFilter.h>
#include <vtkXMLPolyDataWriter.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/mesh_check.h"
#include "app/report.h"
#include "pvrr/base/error.h"

namespace fs = std::filesystem;

namespace pvrr::app {

namespace {

std::string lowerExtension(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

vtkSmartPointer<vtkPolyData> toPolyData(const std::vector<Vec3>& pos, const std::vector<cad::Triangle>& tris) {
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  for (const Vec3& p : pos) pts->InsertNextPoint(p.x, p.y, p.z);
  vtkNew<vtkCellArray> polys;
  for (const auto& t : tris) {
    const vtkIdType ids[3] = {vtkIdType(t.x), vtkIdType(t.y), vtkIdType(t.z)};
    polys->InsertNextCell(3, ids);
  }
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  return pd;
}

vtkSmartPointer<vtkDoubleArray> vec3Array(const char* name, const std::vector<Vec3>& v) {
  auto a = vtkSmartPointer<vtkDoubleArray>::New();
  a->SetName(name);
  a->SetNumberOfComponents(3);
  for (const Vec3& x : v) a->InsertNextTuple3(x.x, x.y, x.z);
  return a;
}

// VTK writers take a file name: they write the temporary that writeAtomic renames into place.
template <class Writer>
void writeAtomicWith(Writer* w, const std::string& path) {
  writeAtomic(path, [&](const std::string& temp) {
    w->SetFileName(temp.c_str());
    if (w->Write() != 1 || !fs::exists(temp)) throw Error(path + ": VTK could not write the file");
  });
}

// Collects what VTK would print (its errors and warnings go to a global output window, stderr by default)
// while an instance is alive, so that a reader's failure becomes one pvrr::Error instead of VTK's log lines.
class CapturedVtkOutput : public vtkOutputWindow {
 public:
  static CapturedVtkOutput* New();
  vtkTypeMacro(CapturedVtkOutput, vtkOutputWindow);
  void DisplayText(const char* t) override { text += t ? t : ""; }
  void DisplayErrorText(const char* t) override { DisplayText(t); }
  void DisplayWarningText(const char* t) override { DisplayText(t); }
  void DisplayGenericWarningText(const char* t) override { DisplayText(t); }
  void DisplayDebugText(const char* t) override { DisplayText(t); }
  std::string text;
};
vtkStandardNewMacro(CapturedVtkOutput);

class ScopedVtkCapture {
 public:
  ScopedVtkCapture() : previous_(vtkOutputWindow::GetInstance()) {
    vtkOutputWindow::SetInstance(window_);
  }
  ~ScopedVtkCapture() { vtkOutputWindow::SetInstance(previous_); }
  ScopedVtkCapture(const ScopedVtkCapture&) = delete;
  ScopedVtkCapture& operator=(const ScopedVtkCapture&) = delete;
  // The last line of VTK's last message (the reason, without VTK's source file and object address).
  std::string reason() const {
    std::string t = window_->text;
    while (!t.empty() && (t.back() == '\n' || t.back() == ' ')) t.pop_back();
    const size_t nl = t.rfind('\n');
    if (nl != std::string::npos) t = t.substr(nl + 1);
    const size_t obj = t.find("): ");
    if (obj != std::string::npos) t = t.substr(obj + 3);
    return t;
  }
  bool any() const { return !window_->text.empty(); }

 private:
  vtkSmartPointer<vtkOutputWindow> previous_;
  vtkNew<CapturedVtkOutput> window_;
};

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the mesh file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error(path + ": cannot read the mesh file");
  return ss.str();
}

}  // namespace

MeshData readMeshFile(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path + ": no such file");
  if (fs::is_directory(path, ec)) throw Error(path + ": is a directory, expected an .obj or .ply mesh");
  const std::string ext = lowerExtension(path);
  // Our own checks first: VTK's readers accept bad indices and nan, and crash on some malformed PLY files.
  if (ext == ".obj") checkObjText(readWholeFile(path), path);
  else if (ext == ".ply") checkPlyData(readWholeFile(path), path);
  ScopedVtkCapture vtk_output;
  vtkSmartPointer<vtkPolyData> pd;
  if (ext == ".obj") {
    vtkNew<vtkOBJReader> r;
    r->SetFileName(path.c_str());
    r->Update();
    pd = r->GetOutput();
  } else if (ext == ".ply") {
    vtkNew<vtkPLYReader> r;
    r->SetFileName(path.c_str());
    r->Update();
    pd = r->GetOutput();
  } else {
    throw Error(path + ": expected an .obj or .ply mesh");
  }
  if (!pd || pd->GetNumberOfPoints() == 0 || pd->GetNumberOfPolys() == 0)
    throw Error(path + ": no triangles could be read" + (vtk_output.any() ? " (VTK: " + vtk_output.reason() + ")" : ""));
  // Defence behind the checks above: every face of what VTK read refers to one of its points.
  {
    vtkCellArray* faces = pd->GetPolys();
    faces->InitTraversal();
    vtkNew<vtkIdList> ids;
    for (vtkIdType f = 0; faces->GetNextCell(ids); ++f)
      for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k)
        if (ids->GetId(k) < 0 || ids->GetId(k) >= pd->GetNumberOfPoints())
          throw Error(path + ": face " + std::to_string(f) + ": vertex index " + std::to_string(ids->GetId(k)) +
                      " is out of range (the file has " + std::to_string(pd->GetNumberOfPoints()) + " vertices)");
  }
  vtkNew<vtkTriangleFilter> tri;
  tri->SetInputData(pd);
  tri->Update();
  vtkPolyData* t = tri->GetOutput();
  MeshData m;
  if (!t || t->GetNumberOfPoints() == 0 || t->GetNumberOfPolys() == 0) throw Error(path + ": no triangles could be read");
  for (vtkIdType i = 0; i < t->GetNumberOfPoints(); ++i) {
    double p[3];
    t->GetPoint(i, p);
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw Error(path + ": vertex " + std::to_string(i) + " is not finite");
    m.positions.emplace_back(p[0], p[1], p[2]);
  }
  if (auto* n = t->GetPointData()->GetNormals())
    for (vtkIdType i = 0; i < n->GetNumberOfTuples(); ++i) {
      double* v = n->GetTuple3(i);
      m.normals.emplace_back(v[0], v[1], v[2]);
    }
  if (auto* tc = t->GetPointData()->GetTCoords())
    for (vtkIdType i = 0; i < tc->GetNumberOfTuples(); ++i) {
      double* v = tc->GetTuple2(i);
      m.uvs.emplace_back(v[0], v[1]);
    }
  vtkCellArray* polys = t->GetPolys();
  polys->InitTraversal();
  vtkNew<vtkIdList> ids;
  while (polys->GetNextCell(ids))
    if (ids->GetNumberOfIds() == 3)
      m.triangles.emplace_back(uint32_t(ids->GetId(0)), uint32_t(ids->GetId(1)), uint32_t(ids->GetId(2)));
  return m;
}

void writeTessellation(const std::string& path, const cad::Tessellation& t) {
  const std::string ext = lowerExtension(path);
  if (ext == ".obj") {
    std::ostringstream os;
    os.precision(17);
    os << "# pvrr mesh: " << t.positions.size() << " vertices, normals from the exact surface\n";
    for (const Vec3& p : t.positions) os << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
    for (const Vec3& n : t.normals) os << "vn " << n.x << ' ' << n.y << ' ' << n.z << '\n';
    for (const auto& f : t.triangles)
      os << "f " << f.x + 1 << "//" << f.x + 1 << ' ' << f.y + 1 << "//" << f.y + 1 << ' ' << f.z + 1 << "//" << f.z + 1 << '\n';
    writeFileAtomic(path, os.str());
    return;
  }
  auto pd = toPolyData(t.positions, t.triangles);
  auto normals = vec3Array("Normals", t.normals);
  pd->GetPointData()->SetNormals(normals);
  if (ext == ".ply") {
    vtkNew<vtkPLYWriter> w;
    w->SetInputData(pd);
    w->SetFileTypeToBinary();
    writeAtomicWith(w.Get(), path);
  } else if (ext == ".vtp") {
    vtkNew<vtkXMLPolyDataWriter> w;
    w->SetInputData(pd);
    writeAtomicWith(w.Get(), path);
  } else {
    throw Error(path + ": expected an .obj, .ply or .vtp output file");
  }
}

void writeVerticesVtp(const std::string& path, const Scene& scene, const std::vector<ElementFrame>& frames) {
  std::vector<Vec3> pos, nrm, dir, hit;
  std::vector<double> s, t, err;
  std::vector<int> status, element, patch;
  std::vector<cad::Triangle> tris;
  for (const ElementFrame& f : frames) {
    const size_t channel = f.rays.size() / 2;  // the middle channel (the only one without dispersion)
    for (const PatchView& pv : f.views) {
      const cad::GridPatch& gp = f.grid_patches[size_t(pv.patch)];
      const uint32_t base = uint32_t(pos.size());
      for (size_t k = 0; k < gp.vertices.size(); ++k) {
        const uint32_t vi = gp.vertices[k];
        const VertexRay& r = f.rays[channel][vi];
        pos.push_back(f.world_pos[vi]);
        nrm.push_back(f.world_normal[vi]);
        dir.push_back(r.dir);
        hit.push_back(r.hit);
        s.push_back(pv.st[channel][k].x);
        t.push_back(pv.st[channel][k].y);
        status.push_back(int(r.status));
        element.push_back(f.element);
        patch.push_back(pv.patch);
        // Per-vertex image error of the fit: the angle at the viewpoint between the line to the hit point and
        // the ray (0 where the viewpoint lies on the ray, as for a plane mirror).
        err.push_back(arcminutes(angleBetween(r.hit - pv.fit.eye, r.dir)));
      }
      for (const auto& tr : gp.triangles) tris.emplace_back(tr.x + base, tr.y + base, tr.z + base);
    }
  }
  auto pd = toPolyData(pos, tris);
  pd->GetPointData()->SetNormals(vec3Array("Normals", nrm));
  pd->GetPointData()->AddArray(vec3Array("direction", dir));
  pd->GetPointData()->AddArray(vec3Array("hit", hit));
  auto scalar = [&](const char* name, const std::vector<double>& v) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    for (double x : v) a->InsertNextValue(x);
    pd->GetPointData()->AddArray(a);
  };
  auto integer = [&](const char* name, const std::vector<int>& v) {
    vtkNew<vtkIntArray> a;
    a->SetName(name);
    for (int x : v) a->InsertNextValue(x);
    pd->GetPointData()->AddArray(a);
  };
  vtkNew<vtkDoubleArray> tc;
  tc->SetName("texture_coordinates");
  tc->SetNumberOfComponents(2);
  for (size_t i = 0; i < s.size(); ++i) tc->InsertNextTuple2(s[i], t[i]);
  pd->GetPointData()->AddArray(tc);
  integer("status", status);  // 0 hit, 1 escape, 2 tir
  integer("element", element);
  integer("patch", patch);
  scalar("fit_angle_arcmin", err);
  (void)scene;
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetInputData(pd);
  writeAtomicWith(w.Get(), path);
}

}  // namespace pvrr::app
