// glTF 2.0 environment meshes (.gltf, .glb) through VTK's vtkGLTFReader, after app/gltf_check.h.
// Every primitive the file's scene places becomes a material part (MeshPart): VTK applies the node
// transforms and records each primitive's material in its field data (BaseColorMultiplier,
// BaseColorTextureIndex); the base colour texture is the image VTK decoded.
#include <vtkDataArray.h>
#include <vtkDataObjectTreeIterator.h>
#include <vtkFieldData.h>
#include <vtkGLTFReader.h>
#include <vtkImageData.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>

#include <filesystem>
#include <map>

#include "app/gltf_check.h"
#include "app/vtk_mesh_support.h"
#include "pvrr/base/error.h"

namespace fs = std::filesystem;

namespace pvrr::app {

namespace {

// A texture image as VTK decoded it (rows bottom-up, 1 to 4 components of 8 or 16 bits) -> pvrr's texture
// (sRGB RGB8, rows top-down). glTF's base colour textures are sRGB-encoded, as pvrr's.
Texture textureFromVtk(vtkImageData* image, const std::string& where) {
  int dims[3] = {0, 0, 0};
  if (image) image->GetDimensions(dims);
  vtkDataArray* s = image ? image->GetPointData()->GetScalars() : nullptr;
  if (!s || dims[0] <= 0 || dims[1] <= 0 || dims[2] != 1 || s->GetNumberOfTuples() != vtkIdType(dims[0]) * dims[1])
    throw Error(where + ": the base colour texture could not be decoded");
  const int comps = s->GetNumberOfComponents();
  const double scale = s->GetDataType() == VTK_UNSIGNED_SHORT ? 1.0 / 257.0 : 1.0;
  if (comps < 1 || comps > 4 || (s->GetDataType() != VTK_UNSIGNED_CHAR && s->GetDataType() != VTK_UNSIGNED_SHORT))
    throw Error(where + ": the base colour texture is not an 8- or 16-bit grey or colour image");
  Texture t;
  t.width = dims[0];
  t.height = dims[1];
  t.rgb.resize(size_t(t.width) * size_t(t.height) * 3);
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      const vtkIdType src = vtkIdType(t.height - 1 - y) * t.width + x;  // VTK's row 0 is the image's bottom
      for (int c = 0; c < 3; ++c) {
        const int from = comps >= 3 ? c : 0;  // grey (and grey + alpha) to RGB; alpha is not used
        t.rgb[(size_t(y) * size_t(t.width) + size_t(x)) * 3 + size_t(c)] =
            uint8_t(std::lround(s->GetComponent(src, from) * scale));
      }
    }
  return t;
}

// An integer or a 4-vector stored by VTK's reader in a primitive's field data; `fallback` when absent.
double fieldValue(vtkPolyData* pd, const char* name, int component, double fallback) {
  vtkDataArray* a = vtkDataArray::SafeDownCast(pd->GetFieldData()->GetAbstractArray(name));
  if (!a || a->GetNumberOfTuples() < 1 || a->GetNumberOfComponents() * a->GetNumberOfTuples() <= component) return fallback;
  return a->GetNumberOfComponents() > component ? a->GetComponent(0, component) : a->GetComponent(component, 0);
}

// Appends `part` (one primitive) to `m` as a MeshPart. glTF's texture v runs down the image, pvrr's up.
void appendPart(MeshData& m, MeshData part, MeshPart info) {
  const uint32_t base = uint32_t(m.positions.size());
  const size_t n = part.positions.size();
  info.first_triangle = m.triangles.size();
  info.triangle_count = part.triangles.size();
  m.positions.insert(m.positions.end(), part.positions.begin(), part.positions.end());
  // All parts keep normals and texture coordinates only if every part has them (else none are used).
  if (part.normals.size() == n) m.normals.insert(m.normals.end(), part.normals.begin(), part.normals.end());
  for (size_t v = 0; v < n; ++v) m.uvs.push_back(v < part.uvs.size() ? Vec2(part.uvs[v].x, 1.0 - part.uvs[v].y) : Vec2(0));
  for (const auto& t : part.triangles) m.triangles.push_back(t + glm::u32vec3(base));
  m.parts.push_back(std::move(info));
}

}  // namespace

MeshData readGltfMesh(const std::string& path) {
  const fs::path folder = fs::path(path).parent_path();
  const auto read_uri = [&](const std::string& uri) {
    const std::string file = (folder / uri).string();
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) throw Error("no such file " + file);
    return readWholeFile(file);
  };
  checkGltfData(readWholeFile(path), path, read_uri);

  ScopedVtkCapture vtk_output;
  vtkNew<vtkGLTFReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkMultiBlockDataSet* out = reader->GetOutput();
  if (!out) throw Error(path + ": VTK could not read the file" + vtk_output.suffix());
  std::map<int, Texture> textures;
  MeshData m;
  size_t with_normals = 0;
  vtkSmartPointer<vtkDataObjectTreeIterator> it;
  it.TakeReference(out->NewTreeIterator());
  it->VisitOnlyLeavesOn();
  for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem()) {
    vtkPolyData* pd = vtkPolyData::SafeDownCast(it->GetCurrentDataObject());
    if (!pd || pd->GetNumberOfPolys() == 0) continue;  // points or lines: the checks allow none
    const std::string where = path + ": primitive " + std::to_string(m.parts.size());
    MeshData part = meshFromPolyData(pd, where, vtk_output);
    with_normals += part.normals.size() == part.positions.size() ? 1 : 0;
    MeshPart info;
    info.name = "primitive" + std::to_string(m.parts.size());
    for (int c = 0; c < 3; ++c) info.base_color[c] = fieldValue(pd, "BaseColorMultiplier", c, 1.0);
    const int tex = int(fieldValue(pd, "BaseColorTextureIndex", 0, -1));
    if (tex >= 0) {
      if (tex >= reader->GetNumberOfTextures()) throw Error(where + ": VTK has no texture " + std::to_string(tex) + vtk_output.suffix());
      if (!textures.count(tex)) textures[tex] = textureFromVtk(reader->GetGLTFTexture(tex).Image, where);
      info.texture = textures[tex];
    }
    appendPart(m, std::move(part), std::move(info));
  }
  if (m.triangles.empty()) throw Error(path + ": no triangles could be read" + vtk_output.suffix());
  if (with_normals != m.parts.size()) m.normals.clear();  // computed from the faces for the whole file
  return m;
}

}  // namespace pvrr::app
