// Hostile input (issue 26, item 3): every refusal is exit code 1 and one line on stderr naming the file and
// the place in it (JSON path, line, vertex or face), with nothing from VTK beside it and no output file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "app/run_pvrr.h"

namespace fs = std::filesystem;

namespace {

using pvrr::test::CliResult;

class InputCli : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = pvrr::test::freshTestDir(::testing::UnitTest::GetInstance()->current_test_info()->name()); }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& bytes) const {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p.string();
  }
  // A small scene whose one environment object is the mesh file `mesh` (beside the scene).
  std::string sceneWithMesh(const std::string& mesh) const {
    return write("scene.json", R"({
  "version": 1,
  "observer": {"eye": [0, 0, 2], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 45, "image_size": [32, 24]},
  "environment": [{"type": "mesh", "name": "thing", "file": ")" + mesh + R"(", "material": {"color": [0.5, 0.5, 0.5]}}],
  "lights": [{"type": "ambient", "color": [1, 1, 1]}],
  "elements": [{"name": "m", "type": "mirror", "pose": {"position": [0, 0, 0], "normal": [0, 0, 1], "up": [0, 1, 0]},
                "outline": {"shape": "rectangle", "width": 0.5, "height": 0.5}, "surface": {"type": "plane"},
                "tessellation": 5, "material": {"metal": "silver"}}]
})");
  }
  // Renders `scene` into the test folder; the PNG must not exist afterwards when the render failed.
  CliResult render(const std::string& scene) const {
    return pvrr::test::runPvrr("render '" + scene + "' --gl osmesa --out '" + out() + "'");
  }
  std::string out() const { return (dir_ / "out.png").string(); }

  // Exit code 1, exactly one line on stderr holding every piece of `parts`, no output file.
  void expectRefusal(const CliResult& r, std::initializer_list<std::string> parts) const {
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "expected one line, got:\n" << r.err;
    for (const std::string& p : parts) EXPECT_NE(r.err.find(p), std::string::npos) << "no \"" << p << "\" in: " << r.err;
    EXPECT_FALSE(fs::exists(out()));
  }

  fs::path dir_;
};

const char* kTriangle = "v 0 0 -1\nv 1 0 -1\nv 0 1 -1\n";

TEST_F(InputCli, PlyThatIsNotAPlyIsRefusedWithoutVtkNoise) {
  write("notply.ply", "hello, this is not a PLY file\n");
  expectRefusal(render(sceneWithMesh("notply.ply")),
                {"scene.json: environment[0] (thing): ", "notply.ply: not a PLY file"});
}

TEST_F(InputCli, PlyWithoutYAndZIsRefused) {
  // VTK's reader crashed (SIGSEGV) after its own error on this header.
  write("x-only.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nelement face 1\n"
                      "property list uchar int vertex_indices\nend_header\n0\n1\n2\n3 0 1 2\n");
  expectRefusal(render(sceneWithMesh("x-only.ply")), {"x-only.ply: the PLY vertex element has no property y"});
}

TEST_F(InputCli, TruncatedBinaryPlyIsRefused) {
  // VTK's reader aborted (a heap error) on data shorter than the header declares.
  write("short.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 300\nproperty float x\nproperty float y\n"
                     "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\nabc");
  expectRefusal(render(sceneWithMesh("short.ply")),
                {"short.ply: vertex 0: the data ends here (the header declares 300 vertices)"});
}

TEST_F(InputCli, PlyFaceIndexOutOfRangeIsRefused) {
  write("bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 -1\n1 0 -1\n0 1 -1\n3 0 1 9\n");
  expectRefusal(render(sceneWithMesh("bad.ply")),
                {"bad.ply: face 0: vertex index 9 is out of range (the file has 3 vertices)"});
}

TEST_F(InputCli, ObjFaceIndexOutOfRangeIsRefused) {
  // Accepted before, and the scene build wrote past the end of its normals array.
  write("bad.obj", std::string(kTriangle) + "f 1 2 3\nf 1 2 7\n");
  expectRefusal(render(sceneWithMesh("bad.obj")),
                {"environment[0] (thing): ", "bad.obj:5: face 1: vertex index 7 is out of range (the file has 3 vertices)"});
}

TEST_F(InputCli, ObjNormalIndexOutOfRangeIsRefused) {
  write("bad-vn.obj", std::string(kTriangle) + "vn 0 0 1\nf 1//1 2//1 3//2\n");
  expectRefusal(render(sceneWithMesh("bad-vn.obj")), {"bad-vn.obj:5: face 0: normal index 2 is out of range (the file has 1 normal)"});
}

TEST_F(InputCli, ObjNanCoordinateIsRefused) {
  // VTK's reader turns "nan" into 0.
  write("nan.obj", "v 0 0 -1\nv nan 0 -1\nv 0 1 -1\nf 1 2 3\n");
  expectRefusal(render(sceneWithMesh("nan.obj")), {"nan.obj:2: vertex 1: expected a finite number, got \"nan\""});
}

TEST_F(InputCli, ObjWithoutFacesIsRefused) {
  write("points.obj", kTriangle);
  expectRefusal(render(sceneWithMesh("points.obj")), {"points.obj: the file holds no faces"});
}

TEST_F(InputCli, MeshPathThatIsADirectoryIsRefused) {
  fs::create_directories(dir_ / "folder.obj");
  expectRefusal(render(sceneWithMesh("folder.obj")),
                {"scene.json: environment[0].file: expected an existing OBJ, PLY, glTF or STL mesh", "folder.obj"});
}

TEST_F(InputCli, ValidObjWithNegativeIndicesAndNormalsStillRenders) {
  write("ok.obj", "v 0 0 -1\nv 1 0 -1\nv 0 1 -1\nv 1 1 -1\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
                  "f -4/-3/-1 -3/-2/-1 -2/-1/-1\nf 2//1 4//1 3//1\n");
  const CliResult r = render(sceneWithMesh("ok.obj"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out()));
}

TEST_F(InputCli, ScenePathThatIsADirectoryIsRefused) {
  fs::create_directories(dir_ / "scene-folder");
  expectRefusal(render((dir_ / "scene-folder").string()), {"scene-folder: is a directory"});
}

TEST_F(InputCli, SceneThatIsNotUtf8NamesTheByte) {
  // Latin-1 "café": before, the message quoted the raw byte (itself not UTF-8).
  const std::string scene = write("latin1.json", "{\n  \"version\": 1,\n  \"description\": \"caf\xe9\"\n}\n");
  const CliResult r = render(scene);
  expectRefusal(r, {"latin1.json: byte 39 (line 3): not valid UTF-8"});
  EXPECT_EQ(r.err.find('\xe9'), std::string::npos);
}

TEST_F(InputCli, SceneInUtf16IsRefusedAtByteZero) {
  const std::string scene = write("utf16.json", std::string("\xff\xfe{\0}\0", 6));
  expectRefusal(render(scene), {"utf16.json: byte 0 (line 1): not valid UTF-8"});
}

TEST_F(InputCli, SetValueThatIsNotUtf8IsRefused) {
  // Found by tests/fuzz/scene_fuzz.cpp: the value was kept as a string the JSON library could not print, an
  // internal error (exit code 2).
  write("ok.obj", std::string(kTriangle) + "f 1 2 3\n");
  const CliResult r = pvrr::test::runPvrr("render '" + sceneWithMesh("ok.obj") + "' --set 'description=caf\xe9' --out '" + out() + "'");
  expectRefusal(r, {"scene.json: --set description=caf?: byte 15 is not valid UTF-8"});
}

TEST_F(InputCli, EyeOnTheMirrorSurfaceIsExplained) {
  // Before: "fitViewpoint: ray 12: expected a finite origin ...", naming neither the scene nor the cause.
  const std::string scene = write("eye-on-mirror.json", R"({
  "version": 1,
  "observer": {"eye": [0, 0, 0], "target": [0, 0, 1], "up": [0, 1, 0], "fov_y_deg": 45, "image_size": [32, 24]},
  "environment": [{"type": "sphere", "name": "ball", "centre": [0, 0, 3], "radius": 0.5, "material": {"color": [0.5, 0.5, 0.5]}}],
  "lights": [{"type": "ambient", "color": [1, 1, 1]}],
  "elements": [{"name": "m", "type": "mirror", "pose": {"position": [0, 0, 0], "normal": [0, 0, 1], "up": [0, 1, 0]},
                "outline": {"shape": "rectangle", "width": 0.5, "height": 0.5}, "surface": {"type": "plane"},
                "tessellation": 5, "material": {"metal": "silver"}}]
})");
  expectRefusal(render(scene), {"eye-on-mirror.json: observer.eye lies on the surface of elements[0] (m)"});
}

// Exit code 2 (an internal error) is reached by no input; a test-only environment variable forces it so that
// the path (one line, exit code 2, no output file) is exercised.
TEST_F(InputCli, InternalErrorIsExitCodeTwoAndOneLine) {
  ::setenv("PVRR_TEST_ONLY_FORCE_INTERNAL_ERROR", "1", 1);
  const CliResult r = render(sceneWithMesh("ok.obj"));
  ::unsetenv("PVRR_TEST_ONLY_FORCE_INTERNAL_ERROR");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("pvrr: internal error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("check failed"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out()));
}

}  // namespace
