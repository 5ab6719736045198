#include "app/vtk_mesh_support.h"

#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkTriangleFilter.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "pvrr/base/error.h"

namespace pvrr::app {

namespace {

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

const std::string& capturedText(vtkOutputWindow* w) { return static_cast<CapturedVtkOutput*>(w)->text; }

}  // namespace

ScopedVtkCapture::ScopedVtkCapture()
    : previous_(vtkOutputWindow::GetInstance()), window_(vtkSmartPointer<CapturedVtkOutput>::New()) {
  vtkOutputWindow::SetInstance(window_);
}

ScopedVtkCapture::~ScopedVtkCapture() { vtkOutputWindow::SetInstance(previous_); }

std::string ScopedVtkCapture::reason() const {
  std::string t = capturedText(window_);
  while (!t.empty() && (t.back() == '\n' || t.back() == ' ')) t.pop_back();
  const size_t nl = t.rfind('\n');
  if (nl != std::string::npos) t = t.substr(nl + 1);
  const size_t obj = t.find("): ");
  if (obj != std::string::npos) t = t.substr(obj + 3);
  return t;
}

bool ScopedVtkCapture::any() const { return !capturedText(window_).empty(); }

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the mesh file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error(path + ": cannot read the mesh file");
  return ss.str();
}

MeshData meshFromPolyData(vtkPolyData* pd, const std::string& path, const ScopedVtkCapture& vtk_output) {
  if (!pd || pd->GetNumberOfPoints() == 0 || pd->GetNumberOfPolys() == 0)
    throw Error(path + ": no triangles could be read" + vtk_output.suffix());
  // Defence behind the format checks: every face of what VTK read refers to one of its points.
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
  if (auto* n = t->GetPointData()->GetNormals(); n && n->GetNumberOfComponents() == 3)
    for (vtkIdType i = 0; i < n->GetNumberOfTuples(); ++i) {
      double* v = n->GetTuple3(i);
      m.normals.emplace_back(v[0], v[1], v[2]);
    }
  if (auto* tc = t->GetPointData()->GetTCoords(); tc && tc->GetNumberOfComponents() == 2)
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

}  // namespace pvrr::app
