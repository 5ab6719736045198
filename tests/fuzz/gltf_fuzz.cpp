// libFuzzer target: the checks of glTF 2.0 environment meshes (app/gltf_check.h) that stand between a user's
// .gltf or .glb file and VTK's vtkGLTFReader. External URIs are refused (the input is the whole world); the
// input is accepted or refused with a pvrr::Error.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "app/gltf_check.h"
#include "pvrr/base/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const pvrr::app::GltfUriReader no_files = [](const std::string& uri) -> std::string {
    throw pvrr::Error("no such file " + uri);
  };
  try {
    (void)pvrr::app::checkGltfData(bytes, "fuzz.glb", no_files);
  } catch (const pvrr::Error&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gltf_fuzz: not a pvrr::Error: %s\n", e.what());
    std::abort();
  }
  return 0;
}
