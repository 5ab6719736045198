// Everything that talks to VTK: reading environment meshes (OBJ and PLY here; glTF and STL in their own
// files), writing PLY and VTP.
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkOBJReader.h>
#include <vtkPLYReader.h>
#include <vtkPLYWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPolyDataWriter.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/mesh_check.h"
#include "app/report.h"
#include "app/vtk_mesh_support.h"
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

}  // namespace

MeshData readMeshFile(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path + ": no such file");
  if (fs::is_directory(path, ec)) throw Error(path + ": is a directory, expected a mesh file (.obj, .ply, .gltf, .glb, .stl)");
  const std::string ext = lowerExtension(path);
  if (ext == ".gltf" || ext == ".glb") return readGltfMesh(path);
  if (ext == ".stl") return readStlMesh(path);
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
    throw Error(path + ": expected a mesh file (.obj, .ply, .gltf, .glb, .stl)");
  }
  return meshFromPolyData(pd, path, vtk_output);
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
