// The pvrr command as a user runs it: exit codes, messages that name the file and the JSON path, no partial
// output files, and outputs that parse.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/run_pvrr.h"

namespace fs = std::filesystem;

namespace {

using Result = pvrr::test::CliResult;

Result pvrr(const std::string& args) { return pvrr::test::runPvrr(args); }

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("pvrr-cli-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(Cli, NoArgumentsIsAUsageError) {
  Result r = pvrr("");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("usage"), std::string::npos);
}

TEST_F(Cli, UnknownCommandSuggestsTheNearest) {
  Result r = pvrr("rendr");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("did you mean \"render\""), std::string::npos) << r.err;
}

TEST_F(Cli, UnknownOptionSuggestsTheNearest) {
  Result r = pvrr("render --sise 10x10");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
}

TEST_F(Cli, MissingSceneFileIsNamed) {
  const std::string out = path("x.png");
  Result r = pvrr("render models/no-such-scene.json --out '" + out + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no-such-scene.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Cli, BadOverrideNamesFileAndJsonPath) {
  const std::string out = path("x.png");
  Result r = pvrr("render models/spectacle-lens.json --set 'elements[0].material.n_d=\"abc\"' --out '" + out + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("spectacle-lens.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("elements[0].material"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(fs::is_empty(dir_));  // no temporary left either
}

TEST_F(Cli, BrokenJsonGivesLineAndColumn) {
  const std::string scene = path("broken.json");
  std::ofstream(scene) << "{\n  \"version\": 1,\n  \"observer\": {\n";
  Result r = pvrr("render '" + scene + "' --out '" + path("x.png") + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("broken.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("x.png")));
}

TEST_F(Cli, RenderWritesThePngAndStats) {
  const std::string out = path("car.png"), stats = path("stats.json");
  Result r = pvrr("render --size 64x48 --gl osmesa --out '" + out + "' --stats '" + stats + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out));
  EXPECT_NE(r.out.find("frame time"), std::string::npos);
  std::ifstream in(stats);
  nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_GT(j["frame_ms"].get<double>(), 0);
  bool has_second_pass = false;
  for (const auto& s : j["stages"]) {
    EXPECT_TRUE(s.contains("name") && s.contains("ms") && s.contains("ran") && s.contains("reason"));
    if (s["name"] == "second-pass") has_second_pass = s["ran"].get<bool>();
    if (s["name"] == "refraction") {
      EXPECT_FALSE(s["ran"].get<bool>());  // the car mirror scene has no lens
      EXPECT_NE(s["reason"].get<std::string>().find("no lens"), std::string::npos);
    }
  }
  EXPECT_TRUE(has_second_pass);
}

TEST_F(Cli, GlInfoOnBothBackends) {
  for (const char* b : {"osmesa", "egl"}) {
    Result r = pvrr(std::string("gl-info --gl ") + b);
    ASSERT_EQ(r.code, 0) << b << ": " << r.err;
    EXPECT_NE(r.out.find("GL_VERSION"), std::string::npos);
    EXPECT_NE(r.out.find("GL_RENDERER"), std::string::npos);
    EXPECT_NE(r.out.find(b == std::string("egl") ? "egl" : "osmesa"), std::string::npos) << r.out;
    // GL 3.3's minimum is 16 units (impostor mode's several elements need up to 21: three mirrors and a lens).
    const std::string units = "GL_MAX_TEXTURE_IMAGE_UNITS: ";
    const size_t u = r.out.find(units);
    ASSERT_NE(u, std::string::npos) << r.out;
    EXPECT_GE(std::stoi(r.out.substr(u + units.size())), 16) << r.out;
  }
  EXPECT_EQ(pvrr("gl-info --gl vulkan").code, 1);
}

TEST_F(Cli, TracePrintsThePathAsJson) {
  Result r = pvrr("trace models/plane-mirror.json --pixel 400,300");
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j["segments"].is_array());
  ASSERT_FALSE(j["segments"].empty());
  for (const auto& s : j["segments"]) {
    EXPECT_EQ(s["origin"].size(), 3u);
    EXPECT_TRUE(s.contains("event") && s.contains("n1") && s.contains("n2"));
  }
  const std::string last = j["segments"].back()["event"];
  EXPECT_TRUE(last == "diffuse" || last == "escape") << last;
  EXPECT_EQ(pvrr("trace models/plane-mirror.json --pixel 1,2 --ray 0,0,0,1,0,0").code, 1);
}

TEST_F(Cli, VerticesCsvHasTheDocumentedColumns) {
  const std::string out = path("v.csv");
  Result r = pvrr("vertices models/car-mirror.json --out '" + out + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(out);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "element,patch,vertex,channel,px,py,pz,nx,ny,nz,dx,dy,dz,status,hx,hy,hz,s,t");
  int rows = 0;
  for (std::string line; std::getline(in, line);) ++rows;
  EXPECT_GE(rows, 49);
  std::ifstream js(path("v.json"));
  nlohmann::json j = nlohmann::json::parse(js);
  EXPECT_EQ(j["elements"][0]["patches"][0]["view_matrix"].size(), 16u);
}

TEST_F(Cli, RaytraceModeRenders) {
  const std::string out = path("rt.png");
  Result r = pvrr("render models/plane-mirror.json --mode raytrace --size 48x36 --out '" + out + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out));
}

// --mode and --modes parse through the render mode's name table (pvrr/scene/render_desc.h); the message lists
// the raster modes, then raytrace, as it always has. Sweep and compare take raster modes only.
TEST_F(Cli, UnknownModesGiveOneMessage) {
  const std::string expected = "mode: expected one of pvrr, raster, envmap, impostor, raytrace; got ";
  Result r = pvrr("render models/plane-mirror.json --mode bogus --size 8x6 --out '" + path("m.png") + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, expected + "\"bogus\"\n");
  EXPECT_FALSE(fs::exists(path("m.png")));
  r = pvrr("sweep models/plane-mirror.json --modes pvrr,raytrace --out '" + dir_.string() + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, expected + "\"raytrace\"\n");
  r = pvrr("compare models/plane-mirror.json --modes pvrr,Envmap --out '" + dir_.string() + "'");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, expected + "\"Envmap\"\n");
}

TEST_F(Cli, SweepWritesCsvAndPlotsAndPlotRedraws) {
  Result r = pvrr("sweep models/plane-mirror.json --tessellation 3,5 --map-size 128 --modes pvrr --size 64x48 --frames 1 --out '" +
               dir_.string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(path("sweep.csv"));
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("mode,tessellation,map_size,vertices,frame_ms,median_arcmin,p95_arcmin,max_arcmin,psnr_db", 0), 0u);
  int rows = 0;
  for (std::string line; std::getline(in, line);) ++rows;
  EXPECT_EQ(rows, 2);
  for (const char* f : {"error_vs_time.png", "error_vs_time.svg", "error_vs_vertices.png"}) EXPECT_TRUE(fs::exists(path(f))) << f;
  fs::remove(path("error_vs_time.png"));
  Result p = pvrr("plot '" + path("sweep.csv") + "'");
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_TRUE(fs::exists(path("error_vs_time.png")));
  std::ofstream(path("bad.csv")) << "nonsense\n";
  Result bad = pvrr("plot '" + path("bad.csv") + "'");
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find("bad.csv:1"), std::string::npos) << bad.err;
}

TEST_F(Cli, MeshExportsObjWithNormals) {
  Result r = pvrr("mesh models/car-mirror.step --tessellation 9 --out '" + path("m.obj") + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(path("m.obj"));
  int v = 0, vn = 0, f = 0;
  for (std::string line; std::getline(in, line);) {
    v += line.rfind("v ", 0) == 0;
    vn += line.rfind("vn ", 0) == 0;
    f += line.rfind("f ", 0) == 0 && line.find("//") != std::string::npos;
  }
  EXPECT_EQ(v, 81);
  EXPECT_EQ(vn, 81);
  EXPECT_GT(f, 100);
  for (const char* ext : {"ply", "vtp"}) {
    const std::string out = path(std::string("m.") + ext);
    Result o = pvrr("mesh models/saddle-mirror.json --element saddle-mirror --tessellation 5 --out '" + out + "'");
    ASSERT_EQ(o.code, 0) << o.err;
    EXPECT_GT(fs::file_size(out), 100u) << ext;
  }
  std::ofstream(path("broken.step")) << "ISO-10303-21;\nHEADER;\n";
  Result bad = pvrr("mesh '" + path("broken.step") + "' --out '" + path("b.obj") + "'");
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find("broken.step"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(path("b.obj")));
}

}  // namespace
