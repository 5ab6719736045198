// libFuzzer target: the OBJ quad-cage parser and grid analysis of subdivision surfaces
// (pvrr::cad::loadSubdivisionCage). The input is the OBJ file, written to a temporary file because the
// loader takes a path. A surface or a pvrr::Error are the only expected outcomes.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>

#include "cad/cad_import.h"
#include "pvrr/base/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = "/tmp/pvrr-cage-fuzz-" + std::to_string(::getpid()) + ".obj";
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  try {
    (void)pvrr::cad::loadSubdivisionCage(path);
  } catch (const pvrr::Error&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cage_fuzz: not a pvrr::Error: %s\n", e.what());
    std::abort();
  }
  return 0;
}
