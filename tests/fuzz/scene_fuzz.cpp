// libFuzzer target: the scene JSON parser with --set overrides (pvrr::parseScene). Input: optional lines
// "#set PATH=VALUE" (each one override, in order), then the JSON text. The only way out of the parser for
// any input is a SceneDesc or a pvrr::Error; anything else (another exception, a sanitizer report) is a
// finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "pvrr/base/error.h"
#include "pvrr/scene/scene_json.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> overrides;
  while (text.compare(0, 5, "#set ") == 0) {
    const size_t nl = text.find('\n');
    overrides.push_back(text.substr(5, nl == std::string::npos ? std::string::npos : nl - 5));
    text = nl == std::string::npos ? std::string() : text.substr(nl + 1);
  }
  try {
    // Relative file names resolve against models/, so the seed scenes' CAD files and cages exist.
    (void)pvrr::parseScene(text, "fuzz.json", PVRR_SOURCE_DIR "/models", overrides);
  } catch (const pvrr::Error&) {
    // an input error: the expected way to refuse
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scene_fuzz: not a pvrr::Error: %s\n", e.what());
    std::abort();
  }
  return 0;
}
