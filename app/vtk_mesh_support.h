// What the VTK mesh readers share (app/vtk_io.cpp for OBJ and PLY, app/gltf_reader.cpp, app/stl_reader.cpp):
// VTK's log caught while a reader runs, the file read whole for the checks that come before VTK, and VTK's
// polygons turned into a checked triangle mesh.
#pragma once
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>

#include <string>

#include "pvrr/scene/scene_build.h"

class vtkPolyData;

namespace pvrr::app {

// Collects what VTK would print (its errors and warnings go to a global output window, stderr by default)
// while an instance is alive, so that a reader's failure becomes one pvrr::Error instead of VTK's log lines.
class ScopedVtkCapture {
 public:
  ScopedVtkCapture();
  ~ScopedVtkCapture();
  ScopedVtkCapture(const ScopedVtkCapture&) = delete;
  ScopedVtkCapture& operator=(const ScopedVtkCapture&) = delete;
  // The last line of VTK's last message (the reason, without VTK's source file and object address).
  std::string reason() const;
  bool any() const;
  // " (VTK: reason)" when VTK said something, else "".
  std::string suffix() const { return any() ? " (VTK: " + reason() + ")" : ""; }

 private:
  vtkSmartPointer<vtkOutputWindow> previous_;
  vtkSmartPointer<vtkOutputWindow> window_;
};

std::string readWholeFile(const std::string& path);

// The polygons of `pd` as triangles (VTK's triangle filter), with its point normals and texture coordinates
// when it has them. Throws a pvrr::Error naming `path` when there are none, when a face refers to a missing
// point, or when a point is not finite. `vtk_output` adds VTK's reason to the message.
MeshData meshFromPolyData(vtkPolyData* pd, const std::string& path, const ScopedVtkCapture& vtk_output);

// The readers of the formats with their own files; `path` exists and is not a folder.
MeshData readGltfMesh(const std::string& path);  // .gltf, .glb (app/gltf_reader.cpp)
MeshData readStlMesh(const std::string& path);   // .stl (app/stl_reader.cpp)

}  // namespace pvrr::app
