// Checks of glTF 2.0 environment meshes (.gltf text, .glb binary) before VTK's vtkGLTFReader reads them.
// VTK's reader trusts the file: it reads accessors beyond their buffers, follows node cycles, takes NaN as a
// coordinate. These checks read the container, the JSON and every accessor the way glTF 2.0 defines them and
// throw a pvrr::Error naming the file and the place ("car.glb: accessors[3]: element 5: component 1 is not a
// finite number"). No VTK here, so the fuzz target (tests/fuzz/gltf_fuzz.cpp) can run them alone.
#pragma once
#include <cstddef>
#include <functional>
#include <string>

namespace pvrr::app {

// Returns the bytes of an external file a glTF document names by `uri` (a buffer's or an image's; data: URIs
// are decoded by the checks), or throws a pvrr::Error.
using GltfUriReader = std::function<std::string(const std::string& uri)>;

struct GltfCounts {
  size_t primitives = 0, triangles = 0;
};

// `data` is the whole file, `path` names it in messages. Checks: the GLB header and chunks (magic "glTF",
// version 2, the lengths), the JSON, asset.version 2.x, no required extension, every buffer's bytes,
// bufferView and accessor within its buffer, float accessors finite, every index (nodes, meshes, materials,
// textures, images, samplers, skins, accessors) in range, the node graph a forest, mesh primitives triangle
// lists (mode 4) whose indices are below their POSITION count, NORMAL a VEC3 and TEXCOORD_n a VEC2, no skins
// or morph targets, base colour factors finite in [0, 1], images
// PNG decodable by libpng (JPEG refused), and at least one triangle.
GltfCounts checkGltfData(const std::string& data, const std::string& path, const GltfUriReader& read_uri);

}  // namespace pvrr::app
