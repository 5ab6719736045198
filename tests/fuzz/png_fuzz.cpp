// libFuzzer target: PNG textures (pvrr::readPng, libpng's simplified API, with pvrr's size checks), as a
// scene's texture file is read. The input is the file, written to a temporary file (the reader takes a path).
// An image or a pvrr::Error are the only expected outcomes.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>

#include "pvrr/base/error.h"
#include "pvrr/base/image.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = "/tmp/pvrr-png-fuzz-" + std::to_string(::getpid()) + ".png";
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  try {
    const pvrr::ImageRGB8 image = pvrr::readPng(path);
    if (image.rgb.size() != size_t(image.width) * size_t(image.height) * 3) std::abort();
  } catch (const pvrr::Error&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "png_fuzz: not a pvrr::Error: %s\n", e.what());
    std::abort();
  }
  return 0;
}
