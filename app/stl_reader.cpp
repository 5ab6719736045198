// STL environment meshes through VTK's vtkSTLReader, after app/stl_check.h. STL has no normals per vertex
// (the scene build computes them from the faces; VTK merges the corners that coincide), no texture
// coordinates and no material: the scene object's material applies.
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkSTLReader.h>

#include "app/stl_check.h"
#include "app/vtk_mesh_support.h"

namespace pvrr::app {

MeshData readStlMesh(const std::string& path) {
  checkStlData(readWholeFile(path), path);
  ScopedVtkCapture vtk_output;
  vtkNew<vtkSTLReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  return meshFromPolyData(reader->GetOutput(), path, vtk_output);
}

}  // namespace pvrr::app
