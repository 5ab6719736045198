// libFuzzer target: the checks of STL environment meshes (app/stl_check.h) that stand between a user's .stl
// file and VTK's vtkSTLReader. The input is accepted or refused with a pvrr::Error.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "app/stl_check.h"
#include "pvrr/base/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    (void)pvrr::app::checkStlData(bytes, "fuzz.stl");
  } catch (const pvrr::Error&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stl_fuzz: not a pvrr::Error: %s\n", e.what());
    std::abort();
  }
  return 0;
}
