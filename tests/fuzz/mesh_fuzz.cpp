// libFuzzer target: the checks of environment OBJ and PLY files (app/mesh_check.h) that stand between a
// user's file and VTK's readers. The same input goes to both; each accepts it or throws a pvrr::Error.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "app/mesh_check.h"
#include "pvrr/base/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  for (int format = 0; format < 2; ++format) {
    try {
      if (format == 0) pvrr::app::checkObjText(text, "fuzz.obj");
      else pvrr::app::checkPlyData(text, "fuzz.ply");
    } catch (const pvrr::Error&) {
    } catch (const std::exception& e) {
      std::fprintf(stderr, "mesh_fuzz: not a pvrr::Error: %s\n", e.what());
      std::abort();
    }
  }
  return 0;
}
