// glTF 2.0 and STL environment meshes (app/gltf_reader.cpp, app/stl_reader.cpp and their checks): what the
// shipped car body and cone read as, the one-line refusals of broken files, and the car rendered in raster
// and pvrr modes against the reference tracer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/gltf_check.h"
#include "app/report.h"
#include "app/stl_check.h"
#include "pvrr/base/error.h"
#include "run_pvrr.h"

namespace fs = std::filesystem;

namespace pvrr::app {
namespace {

const std::string kModels = PVRR_SOURCE_DIR "/models/";

// Expected from scripts/make-car-body: three primitives (body and cabin boxes of 12 triangles, four
// 16-sided wheels of 64 triangles each) and the cone's two closed frusta of 12 triangles.
constexpr size_t kBodyTriangles = 12, kCabinTriangles = 12, kWheelTriangles = 4 * 64, kConeTriangles = 24;

std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// The message is one line and contains each of `parts`.
void expectOneLine(const std::string& m, std::initializer_list<std::string> parts) {
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  for (const std::string& p : parts) EXPECT_NE(m.find(p), std::string::npos) << "missing \"" << p << "\" in: " << m;
}

TEST(MeshFormats, CarBodyGlbReadsItsPrimitivesWithTheirMaterials) {
  const MeshData m = readMeshFile(kModels + "car-body.glb");
  ASSERT_EQ(m.parts.size(), 3u);
  EXPECT_EQ(m.parts[0].triangle_count, kBodyTriangles);
  EXPECT_EQ(m.parts[1].triangle_count, kCabinTriangles);
  EXPECT_EQ(m.parts[2].triangle_count, kWheelTriangles);
  EXPECT_EQ(m.triangles.size(), kBodyTriangles + kCabinTriangles + kWheelTriangles);
  // glTF floats: the factors round-trip through float.
  constexpr double kFloatTol = 1e-6;
  EXPECT_NEAR(m.parts[0].base_color.r, 0.8, kFloatTol);
  EXPECT_NEAR(m.parts[0].base_color.g, 0.1, kFloatTol);
  EXPECT_NEAR(m.parts[1].base_color.b, 0.3, kFloatTol);
  EXPECT_NEAR(m.parts[2].base_color.r, 0.05, kFloatTol);
  EXPECT_FALSE(m.parts[1].texture.has_value());
  // The body's 4 x 4 texture, rows top-down as in the PNG: two white rows over two grey (sRGB 128) rows.
  ASSERT_TRUE(m.parts[0].texture.has_value());
  const Texture& t = *m.parts[0].texture;
  ASSERT_EQ(t.width, 4);
  ASSERT_EQ(t.height, 4);
  EXPECT_EQ(t.rgb[0], 255);
  EXPECT_EQ(t.rgb[size_t(3 * 4 * 3)], 128);  // row 3 (the bottom), first pixel, red
  // glTF's v runs down the image, pvrr's up: the body's lower edge (y = 0.25 m, glTF v = 0.875) takes
  // v = 0.125, the centre of the image's bottom row (grey); its upper edge (y = 0.95 m) v = 0.875, the top
  // row (white).
  ASSERT_EQ(m.uvs.size(), m.positions.size());
  ASSERT_EQ(m.normals.size(), m.positions.size());
  int checked = 0;
  for (size_t k = 0; k < 3 * kBodyTriangles; ++k) {
    const uint32_t v = m.triangles[k / 3][int(k % 3)];
    if (std::abs(m.normals[v].y) > 0.5) continue;  // the side faces carry the texture's rows
    const double y = m.positions[v].y;
    if (std::abs(y - 0.25) > 1e-6 && std::abs(y - 0.95) > 1e-6) continue;
    EXPECT_NEAR(m.uvs[v].y, y < 0.5 ? 0.125 : 0.875, kFloatTol);
    ++checked;
  }
  EXPECT_GE(checked, 16);
}

TEST(MeshFormats, GltfTextAndGlbReadTheSameMesh) {
  const MeshData a = readMeshFile(kModels + "car-body.glb");
  const MeshData b = readMeshFile(kModels + "car-body.gltf");
  ASSERT_EQ(a.positions.size(), b.positions.size());
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.triangles, b.triangles);
  ASSERT_EQ(b.parts.size(), 3u);
  EXPECT_EQ(a.parts[0].texture->rgb, b.parts[0].texture->rgb);
}

TEST(MeshFormats, StlConeReadsWithoutMaterialParts) {
  const MeshData m = readMeshFile(kModels + "traffic-cone.stl");
  EXPECT_EQ(m.triangles.size(), kConeTriangles);
  EXPECT_TRUE(m.parts.empty());
  double top = 0, min_x = 1;
  for (const Vec3& p : m.positions) top = std::max(top, p.y), min_x = std::min(min_x, p.x);
  EXPECT_NEAR(top, 0.53, 1e-6);    // the frustum's top (float coordinates)
  EXPECT_NEAR(min_x, -0.2, 1e-6);  // the plate's half width
}

// ------------------------------------------------------------------------------------------------------------
// Broken glTF: the car body's bytes edited in place.

struct Glb {
  std::string bytes;
  nlohmann::json doc;
  size_t bin_start = 0;  // offset of the BIN chunk's data in `bytes`
  size_t accessorByte(int accessor, size_t element, size_t component = 0) const {
    const auto& a = doc["accessors"][size_t(accessor)];
    const auto& v = doc["bufferViews"][a["bufferView"].get<size_t>()];
    const size_t size = a["componentType"].get<int>() == 5126 || a["componentType"].get<int>() == 5125 ? 4 : 2;
    const size_t comps = a["type"] == "VEC3" ? 3 : a["type"] == "VEC2" ? 2 : 1;
    return bin_start + v.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0)) + (element * comps + component) * size;
  }
};

Glb carGlb() {
  Glb g;
  g.bytes = test::slurp(kModels + "car-body.glb");
  uint32_t json_length = 0;
  std::memcpy(&json_length, g.bytes.data() + 12, 4);
  g.doc = nlohmann::json::parse(g.bytes.substr(20, json_length));
  g.bin_start = 20 + json_length + 8;
  return g;
}

const GltfUriReader kNoFiles = [](const std::string& uri) -> std::string { throw Error("no such file " + uri); };

TEST(MeshFormats, ShippedGlbPassesTheChecks) {
  const GltfCounts c = checkGltfData(carGlb().bytes, "car.glb", kNoFiles);
  EXPECT_EQ(c.primitives, 3u);
  EXPECT_EQ(c.triangles, kBodyTriangles + kCabinTriangles + kWheelTriangles);
}

TEST(MeshFormats, TruncatedGlbIsRefusedInOneLine) {
  const std::string cut = carGlb().bytes.substr(0, 100);
  expectOneLine(messageOf([&] { checkGltfData(cut, "car.glb", kNoFiles); }),
                {"car.glb: ", "says " + std::to_string(carGlb().bytes.size()) + " bytes, the file has 100"});
  expectOneLine(messageOf([&] { checkGltfData(cut.substr(0, 10), "car.glb", kNoFiles); }), {"car.glb: ", "cut short"});
}

TEST(MeshFormats, WrongMagicIsRefusedInOneLine) {
  std::string b = carGlb().bytes;
  b[3] = 'X';
  expectOneLine(messageOf([&] { checkGltfData(b, "car.glb", kNoFiles); }), {"car.glb: not a glTF file"});
}

TEST(MeshFormats, NanInAnAccessorIsRefusedInOneLine) {
  Glb g = carGlb();
  const int position = g.doc["meshes"][0]["primitives"][1]["attributes"]["POSITION"].get<int>();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&g.bytes[g.accessorByte(position, 5, 1)], &nan, 4);
  expectOneLine(messageOf([&] { checkGltfData(g.bytes, "car.glb", kNoFiles); }),
                {"car.glb: accessors[" + std::to_string(position) + "]: element 5: component 1 is not a finite number"});
}

TEST(MeshFormats, IndexOutOfRangeIsRefusedInOneLine) {
  Glb g = carGlb();
  const int indices = g.doc["meshes"][0]["primitives"][0]["indices"].get<int>();
  const uint32_t big = 9999;
  std::memcpy(&g.bytes[g.accessorByte(indices, 7)], &big, 4);
  expectOneLine(messageOf([&] { checkGltfData(g.bytes, "car.glb", kNoFiles); }),
                {"car.glb: meshes[0].primitives[0].indices: element 7: vertex index 9999 is out of range (POSITION has 24 vertices)"});
}

// A damaged texture made VTK's PNG reader crash the process (libpng: "IHDR: CRC error", then SIGSEGV).
TEST(MeshFormats, DamagedOrJpegTextureIsRefusedInOneLine) {
  Glb g = carGlb();
  const auto& view = g.doc["bufferViews"][g.doc["images"][0]["bufferView"].get<size_t>()];
  const size_t png = g.bin_start + view.value("byteOffset", size_t(0));
  std::string damaged = g.bytes;
  damaged[png + 20] ^= 0x5A;  // inside IHDR: its CRC no longer matches
  expectOneLine(messageOf([&] { checkGltfData(damaged, "car.glb", kNoFiles); }),
                {"car.glb: images[0]: the PNG image cannot be read (libpng: IHDR: CRC error)"});
  std::string jpeg = g.bytes;
  jpeg.replace(png, 3, "\xFF\xD8\xFF");
  expectOneLine(messageOf([&] { checkGltfData(jpeg, "car.glb", kNoFiles); }),
                {"car.glb: images[0]: a JPEG image; pvrr reads PNG textures only"});
}

TEST(MeshFormats, GltfStructureErrorsNameTheJsonPath) {
  const nlohmann::json base = carGlb().doc;
  const auto refusal = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json d = base;
    d["buffers"][0]["uri"] = "car.bin";
    edit(d);
    const GltfUriReader bin = [&](const std::string&) {
      const Glb g = carGlb();
      return g.bytes.substr(g.bin_start);
    };
    return messageOf([&] { checkGltfData(d.dump(), "car.gltf", bin); });
  };
  expectOneLine(refusal([](nlohmann::json&) {}), {"(no error)"});
  expectOneLine(refusal([](nlohmann::json& d) { d["nodes"].push_back({{"children", {1}}}); d["nodes"][0]["children"] = {1}; }),
                {"car.gltf: nodes[1].children[0]: node 1 has a second parent"});
  expectOneLine(refusal([](nlohmann::json& d) { d["nodes"].push_back({{"children", {0}}}); d["nodes"][0]["children"] = {1}; }),
                {"car.gltf: nodes[0]: the node is its own ancestor"});
  expectOneLine(refusal([](nlohmann::json& d) { d["meshes"][0]["primitives"][2]["mode"] = 1; }),
                {"car.gltf: meshes[0].primitives[2].mode: only triangle lists"});
  expectOneLine(refusal([](nlohmann::json& d) { d["meshes"][0]["primitives"][0]["material"] = 7; }),
                {"car.gltf: meshes[0].primitives[0].material: 7 is out of range (the file has 3 materials)"});
  expectOneLine(refusal([](nlohmann::json& d) { d["accessors"][0]["count"] = 100000; }),
                {"car.gltf: accessors[0]: 100000 elements of 12 bytes from byte 0 run past the end of bufferViews[0]"});
  expectOneLine(refusal([](nlohmann::json& d) { d["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"][0] = 2; }),
                {"car.gltf: materials[0].pbrMetallicRoughness.baseColorFactor: expected numbers in [0, 1]"});
  expectOneLine(refusal([](nlohmann::json& d) {
                  d["accessors"][d["meshes"][0]["primitives"][0]["attributes"]["NORMAL"].get<size_t>()]["type"] = "VEC2";
                }),
                {"car.gltf: meshes[0].primitives[0].attributes.NORMAL: expected a VEC3 float accessor"});
  expectOneLine(refusal([](nlohmann::json& d) { d["skins"] = {{{"joints", {0}}}}; }),
                {"car.gltf: skins: skinned meshes are not read by pvrr"});
  expectOneLine(refusal([](nlohmann::json& d) { d["meshes"][0]["primitives"][1]["targets"] = nlohmann::json::array(); }),
                {"car.gltf: meshes[0].primitives[1].targets: morph targets are not read by pvrr"});
  expectOneLine(refusal([](nlohmann::json& d) { d["extensionsRequired"] = {"KHR_draco_mesh_compression"}; }),
                {"car.gltf: extensionsRequired: the file needs the extension \"KHR_draco_mesh_compression\""});
  expectOneLine(refusal([](nlohmann::json& d) { d["meshes"] = nlohmann::json::array(); d["nodes"][0].erase("mesh"); }),
                {"car.gltf: the file holds no triangles"});
  expectOneLine(messageOf([] { checkGltfData("{\"asset\": {\"version\": \"2.0\"", "x.gltf", kNoFiles); }),
                {"x.gltf: the glTF JSON is not valid"});
}

TEST(MeshFormats, BrokenStlIsRefusedInOneLine) {
  const std::string cone = test::slurp(kModels + "traffic-cone.stl");
  EXPECT_EQ(checkStlData(cone, "cone.stl"), kConeTriangles);
  expectOneLine(messageOf([&] { checkStlData(cone.substr(0, 300), "cone.stl"); }),
                {"cone.stl: the binary STL header declares 24 triangles (1284 bytes), the file has 300 bytes"});
  std::string nan = cone;
  const float bad = std::numeric_limits<float>::infinity();
  std::memcpy(&nan[84 + 50 * 7 + 12 + 12 * 2], &bad, 4);
  expectOneLine(messageOf([&] { checkStlData(nan, "cone.stl"); }), {"cone.stl: triangle 7: vertex 2 is not finite"});
  const std::string ascii = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\n"
                            "endloop\nendfacet\nendsolid t\n";
  expectOneLine(messageOf([&] { checkStlData(ascii, "t.stl"); }), {"t.stl:5: triangle 0: vertex 1 is not finite"});
  expectOneLine(messageOf([&] { checkStlData("solid t\nfacet normal 0 0 1\nouter loop\n", "t.stl"); }),
                {"t.stl:3: expected \"vertex\", the file ends"});
  expectOneLine(messageOf([&] { checkStlData("hello", "t.stl"); }), {"t.stl: not an STL file"});
  EXPECT_EQ(checkStlData("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                         "endloop\nendfacet\nendsolid t\n", "t.stl"),
            1u);
}

// The CLI's contract for a broken glTF in a scene: exit 1, one line naming the scene, the object and the file.
TEST(MeshFormats, SceneWithATruncatedGlbIsRefusedByRender) {
  const fs::path dir = test::freshTestDir("truncated-glb");
  std::ofstream(dir / "car.glb", std::ios::binary) << carGlb().bytes.substr(0, 1000);
  std::string scene = test::slurp(PVRR_SOURCE_DIR "/tests/data/car-body-scene.json");
  const std::string shipped = "../../models/car-body.glb";
  scene.replace(scene.find(shipped), shipped.size(), "car.glb");
  for (size_t at; (at = scene.find("../../models/")) != std::string::npos;) scene.replace(at, 6, PVRR_SOURCE_DIR "/");
  std::ofstream(dir / "scene.json") << scene;
  const std::string out = (dir / "x.png").string();
  const test::CliResult r = test::runPvrr("render '" + (dir / "scene.json").string() + "' --out '" + out + "'");
  test::expectOneLineError(r, "scene.json: environment[1] (car-ahead): ");
  EXPECT_NE(r.err.find("car.glb: the binary glTF header says"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

// ------------------------------------------------------------------------------------------------------------
// The car rendered: the raster and pvrr modes against the reference tracer on the pixels that see a car.

struct CarPixels {
  std::vector<size_t> both;  // pixels where the reference and the mode both see a car
  size_t ref_count = 0, mode_count = 0;
};

// Whether `p` lies in the bounding box of a part of a car (the meshes named car-*), above the road.
bool onACar(const Scene& s, const Vec3& p) {
  constexpr double kMargin = 1e-3;  // a seen point on a face, reconstructed from float depth
  if (p.y < kMargin) return false;  // the road under a car
  for (const EnvMesh& m : s.meshes) {
    if (m.name.rfind("car-", 0) != 0) continue;
    Vec3 lo(1e30), hi(-1e30);
    for (const glm::vec3& v : m.positions) lo = glm::min(lo, m.anchor + Vec3(v)), hi = glm::max(hi, m.anchor + Vec3(v));
    if (glm::all(glm::greaterThanEqual(p, lo - kMargin)) && glm::all(glm::lessThanEqual(p, hi + kMargin))) return true;
  }
  return false;
}

// `direct_only`: the pixels that see no mirror in the reference (the raster mode draws mirrors as plain surfaces).
CarPixels carPixels(const Scene& s, const Frame& ref, const Frame& f, bool direct_only) {
  CarPixels c;
  for (size_t i = 0; i < ref.seen.size(); ++i) {
    if (direct_only && ref.element[i] >= 0) continue;
    const bool r = onACar(s, ref.seen[i]), m = onACar(s, f.seen[i]);
    c.ref_count += r;
    c.mode_count += m;
    if (r && m) c.both.push_back(i);
  }
  return c;
}

TEST(MeshFormats, CarBodyRendersLikeTheReferenceInRasterAndPvrrModes) {
  LoadedScene ls = loadScene(PVRR_SOURCE_DIR "/tests/data/car-body-scene.json", {});
  ASSERT_EQ(ls.scene.meshes.size(), 1u + 3u + 3u + 1u);  // road, two cars of three parts, cone
  const RenderedFrame ref = renderFrame(ls, RenderMode::Raytrace, "", nullptr);
  // The reference sees both cars: the one ahead directly, the one behind in the mirror.
  size_t via_mirror = 0;
  for (size_t i = 0; i < ref.seen.size(); ++i) via_mirror += ref.element[i] == 0 && onACar(ls.scene, ref.seen[i]);
  EXPECT_GT(via_mirror, 50u);
  // The body's texture in the reference: on the car ahead's rear face (z = -7 + 2.1 m, rotated 20 deg about y)
  // the upper half (white texel rows) is brighter than the lower half (grey: sRGB 128 = 0.216 linear).
  {
    const Vec3 centre(1.6, 0, -7), normal(std::sin(radians(20)), 0, std::cos(radians(20)));
    double upper = 0, lower = 0;
    int n_upper = 0, n_lower = 0;
    for (size_t i = 0; i < ref.seen.size(); ++i) {
      const Vec3 p = ref.seen[i];
      if (std::abs(glm::dot(p - centre, normal) - 2.1) > 1e-3) continue;
      if (p.y > 0.85 && p.y < 0.93) upper += ref.color[i].r, ++n_upper;
      if (p.y > 0.27 && p.y < 0.35) lower += ref.color[i].r, ++n_lower;
    }
    ASSERT_GT(n_upper, 5);
    ASSERT_GT(n_lower, 5);
    // Both bands lie between texel centres of one colour (the side faces span v = 0.125..0.875), under the same
    // light at the same normal: the ratio is that of the texels' linear values, 1 / srgbToLinear(128 / 255).
    const double grey = std::pow((128.0 / 255.0 + 0.055) / 1.055, 2.4);
    constexpr double kRatioTol = 0.02;  // measured 4.6326 against 4.6327: float texture and shading arithmetic
    EXPECT_NEAR((upper / n_upper) / (lower / n_lower), 1.0 / grey, kRatioTol);
  }
  RenderSession session;
  for (RenderMode mode : {RenderMode::Raster, RenderMode::Pvrr}) {
    const RenderedFrame f = renderFrame(ls, mode, "auto", &session);
    const CarPixels c = carPixels(ls.scene, ref, f, mode == RenderMode::Raster);
    SCOPED_TRACE(std::string(nameOf(mode)));
    ASSERT_GT(c.both.size(), 500u);
    // Silhouette pixels may see the car in one image only (rasterisation vs. the ray at the pixel centre);
    // the pvrr mode's reflection is a warped map, whose edge pixels differ more (measured: raster 0 %, pvrr 2.6 %).
    constexpr double kCountTol = 0.05;
    EXPECT_NEAR(double(c.mode_count), double(c.ref_count), kCountTol * double(c.ref_count));
    // Colours on the pixels that see a car in both: the same material, lights and texture. Most pixels
    // agree to a few code values (interpolated vertex normals vs. the tracer's, float vs. double); edge
    // pixels where the two see different faces of a car may differ fully.
    std::vector<double> diff;
    for (size_t i : c.both) {
      const Vec3 d = glm::abs(f.color[i] - ref.color[i]);
      diff.push_back(std::max({d.r, d.g, d.b}));
    }
    std::sort(diff.begin(), diff.end());
    // Linear RGB. Measured (osmesa, 160 x 120): median 1e-8, 90th percentile 4e-4 in both modes.
    constexpr double kMedianTol = 1e-3, kP90Tol = 0.01;
    EXPECT_LT(diff[diff.size() / 2], kMedianTol);
    EXPECT_LT(diff[diff.size() * 9 / 10], kP90Tol);
  }
}

}  // namespace
}  // namespace pvrr::app
