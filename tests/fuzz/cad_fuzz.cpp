// libFuzzer target: STEP and IGES import through OpenCASCADE (pvrr::cad::importCadFile), the faces' conversion
// to rational B-splines and their trim loops. The input is the file, written to a temporary file (the importer
// takes a path) named .step when its first 64 bytes hold "ISO-10303" (a STEP file's first line), else .igs.
// An imported model or a pvrr::Error are the only expected outcomes.
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
  const std::string head(reinterpret_cast<const char*>(data), size < 64 ? size : 64);
  static const std::string stem = "/tmp/pvrr-cad-fuzz-" + std::to_string(::getpid());
  const std::string path = stem + (head.find("ISO-10303") != std::string::npos ? ".step" : ".igs");
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  try {
    (void)pvrr::cad::importCadFile(path);
  } catch (const pvrr::Error&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cad_fuzz: not a pvrr::Error: %s\n", e.what());
    std::abort();
  }
  return 0;
}
