// The fuzz targets' seed corpora (tests/fuzz/corpus/<target>, with the inputs of past findings) replayed in
// the ordinary build: each input is accepted or refused with a pvrr::Error, never anything else. The
// fuzzers themselves need clang (scripts/fuzz); this keeps their findings fixed under scripts/test.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/gltf_check.h"
#include "app/mesh_check.h"
#include "app/stl_check.h"
#include "cad/cad_import.h"
#include "pvrr/base/error.h"
#include "pvrr/base/image.h"
#include "pvrr/scene/scene_json.h"

namespace fs = std::filesystem;

namespace {

std::vector<fs::path> corpus(const std::string& target) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(PVRR_SOURCE_DIR) / "tests/fuzz/corpus" / target))
    if (e.is_regular_file()) files.push_back(e.path());
  return files;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs `f`; a pvrr::Error is a refusal (fine), any other exception fails the test naming the input.
template <class F>
void acceptedOrRefused(const fs::path& input, F&& f) {
  try {
    f();
  } catch (const pvrr::Error&) {
  } catch (const std::exception& e) {
    ADD_FAILURE() << input << ": not a pvrr::Error: " << e.what();
  }
}

TEST(FuzzCorpus, SceneInputsAreParsedOrRefusedWithAnError) {
  const auto files = corpus("scene");
  EXPECT_GE(files.size(), 5u);
  for (const fs::path& p : files) {
    // The scene target's format: lines "#set PATH=VALUE" first, then the JSON text (tests/fuzz/scene_fuzz.cpp).
    std::string text = slurp(p);
    std::vector<std::string> overrides;
    while (text.compare(0, 5, "#set ") == 0) {
      const size_t nl = text.find('\n');
      overrides.push_back(text.substr(5, nl == std::string::npos ? std::string::npos : nl - 5));
      text = nl == std::string::npos ? std::string() : text.substr(nl + 1);
    }
    acceptedOrRefused(p, [&] { (void)pvrr::parseScene(text, "fuzz.json", PVRR_SOURCE_DIR "/models", overrides); });
  }
}

TEST(FuzzCorpus, ShippedScenesAmongTheSeedsParse) {
  for (const fs::path& p : corpus("scene"))
    if (fs::exists(fs::path(PVRR_SOURCE_DIR) / "models" / p.filename())) {
      EXPECT_NO_THROW((void)pvrr::parseScene(slurp(p), p.string(), PVRR_SOURCE_DIR "/models")) << p;
    }
}

TEST(FuzzCorpus, MeshInputsAreCheckedOrRefusedWithAnError) {
  const auto files = corpus("mesh");
  EXPECT_GE(files.size(), 3u);
  for (const fs::path& p : files) {
    const std::string data = slurp(p);
    acceptedOrRefused(p, [&] { pvrr::app::checkObjText(data, "fuzz.obj"); });
    acceptedOrRefused(p, [&] { pvrr::app::checkPlyData(data, "fuzz.ply"); });
    // The seeds are valid files of their own format.
    if (p.extension() == ".obj") {
      EXPECT_NO_THROW(pvrr::app::checkObjText(data, p.string())) << p;
    }
    if (p.extension() == ".ply") {
      EXPECT_NO_THROW(pvrr::app::checkPlyData(data, p.string())) << p;
    }
  }
}

TEST(FuzzCorpus, GltfInputsAreCheckedOrRefusedWithAnError) {
  const auto files = corpus("gltf");
  EXPECT_GE(files.size(), 2u);
  const pvrr::app::GltfUriReader no_files = [](const std::string& uri) -> std::string {
    throw pvrr::Error("no such file " + uri);
  };
  for (const fs::path& p : files) {
    const std::string data = slurp(p);
    acceptedOrRefused(p, [&] { (void)pvrr::app::checkGltfData(data, "fuzz.glb", no_files); });
    if (p.extension() == ".glb" || p.extension() == ".gltf") {  // the seeds are valid, self-contained files
      EXPECT_NO_THROW((void)pvrr::app::checkGltfData(data, p.string(), no_files)) << p;
    }
  }
}

TEST(FuzzCorpus, StlInputsAreCheckedOrRefusedWithAnError) {
  const auto files = corpus("stl");
  EXPECT_GE(files.size(), 2u);
  for (const fs::path& p : files) {
    const std::string data = slurp(p);
    acceptedOrRefused(p, [&] { (void)pvrr::app::checkStlData(data, "fuzz.stl"); });
    if (p.extension() == ".stl") {
      EXPECT_NO_THROW((void)pvrr::app::checkStlData(data, p.string())) << p;
    }
  }
}

TEST(FuzzCorpus, CageInputsLoadOrAreRefusedWithAnError) {
  const auto files = corpus("cage");
  EXPECT_GE(files.size(), 2u);
  for (const fs::path& p : files) acceptedOrRefused(p, [&] { (void)pvrr::cad::loadSubdivisionCage(p.string()); });
}

TEST(FuzzCorpus, CadInputsImportOrAreRefusedWithAnError) {
  const auto files = corpus("cad");
  EXPECT_GE(files.size(), 2u);
  for (const fs::path& p : files) {
    // The cad target names its temporary file .step when the input's first 64 bytes hold "ISO-10303", else .igs
    // (tests/fuzz/cad_fuzz.cpp); the seeds and findings keep such a name.
    acceptedOrRefused(p, [&] { (void)pvrr::cad::importCadFile(p.string()); });
    if (p.filename().string().rfind("finding-", 0) != 0) {
      EXPECT_FALSE(pvrr::cad::importCadFile(p.string()).faces.empty()) << p;  // the seeds are valid files
    } else {
      // The findings crashed OpenCASCADE (SIGSEGV): now one line naming the file.
      try {
        (void)pvrr::cad::importCadFile(p.string());
        ADD_FAILURE() << p << ": accepted";
      } catch (const pvrr::Error& e) {
        EXPECT_NE(std::string(e.what()).find(p.string() + ": not a valid "), std::string::npos) << e.what();
      }
    }
  }
}

TEST(FuzzCorpus, PngInputsReadOrAreRefusedWithAnError) {
  const auto files = corpus("png");
  EXPECT_GE(files.size(), 5u);
  for (const fs::path& p : files) {
    acceptedOrRefused(p, [&] { (void)pvrr::readPng(p.string()); });
    if (p.filename().string().rfind("finding-", 0) != 0) {
      EXPECT_GT(pvrr::readPng(p.string()).width, 0) << p;  // the seeds are valid PNGs
    }
  }
}

}  // namespace
