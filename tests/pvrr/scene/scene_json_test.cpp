// Scene files: the shipped scenes load, every class of bad input gives a complete message, units convert,
// --set overrides apply and are validated.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "pvrr/base/error.h"
#include "cad/model_generator.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr {
namespace {

namespace fs = std::filesystem;

// Lengths in the desc are converted with one multiplication by 1e-3 (mm) or 1 (m): relative rounding of a
// few ulps at most.
constexpr double kUnitTol = 1e-12;
// The shipped scenes give radii to 5-6 significant digits: powers computed from them match the nominal
// dioptres to better than this.
constexpr double kPowerTol_D = 0.005;

const std::string kName = "scenes/test.json";

// A small valid scene: a convex mirror and an attached lens.
const std::string kBase = R"({
  "version": 1,
  "observer": {"eye": [0, 1.2, 0], "target": [0, 1.2, -1], "fov_y_deg": 50},
  "environment": [
    {"type": "box", "name": "crate", "centre": [0, 0.5, -3], "size": [1, 1, 1]}
  ],
  "elements": [
    {"name": "m", "type": "mirror", "pose": {"position": [0, 1.2, -1], "normal": [0, 0, 1]},
     "outline": {"shape": "circle", "diameter": 0.2}, "surface": {"type": "sphere", "radius": 1.4},
     "material": {"reflectance": 0.9}},
    {"name": "l", "type": "lens", "attached_to_observer": true,
     "pose": {"position": [0, 0, -0.012], "normal": [0, 0, 1]},
     "outline": {"shape": "ellipse", "width": 0.05, "height": 0.04},
     "front": {"type": "sphere", "radius": -0.07}, "back": {"type": "sphere", "radius": -0.12},
     "centre_thickness": 0.002, "material": {"n_d": 1.5, "V_d": 58}}
  ]
})";

// kBase with one unique fragment replaced.
std::string edited(const std::string& from, const std::string& to, std::string text = kBase) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "fragment not in the scene: " << from;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "fragment not unique: " << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

SceneDesc parse(const std::string& text, const std::vector<std::string>& overrides = {}) {
  return parseScene(text, kName, "", overrides);
}

// The message of the pvrr::Error the scene raises ("" and a test failure when it raises none).
std::string errorOf(const std::string& text, const std::vector<std::string>& overrides = {},
                    const std::string& base_dir = "") {
  try {
    parseScene(text, kName, base_dir, overrides);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for the scene";
  return "";
}

fs::path models() { return fs::path(PVRR_SOURCE_DIR) / "models"; }

// A fresh temporary folder for tests that need files.
fs::path tempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("pvrr_scene_json_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void touch(const fs::path& p) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << "placeholder\n";
}

// ---------------------------------------------------------------------------------------------------------
// Shipped scenes

TEST(SceneJson, EveryShippedSceneLoadsAndValidates) {
  for (const char* name :
       {"car-mirror", "plane-mirror", "concave-mirror", "spectacle-lens", "reading-lens", "progressive-lens"}) {
    const fs::path path = models() / (std::string(name) + ".json");
    ASSERT_TRUE(fs::exists(path)) << path;
    SceneDesc s;
    try {
      s = loadScene(path.string());
    } catch (const Error& e) {
      // car-mirror.json names car-mirror.step, made by another tool: only its absence is tolerated.
      const bool step_missing = std::string(name) == "car-mirror" && !fs::exists(models() / "car-mirror.step");
      EXPECT_TRUE(step_missing) << e.what();
      EXPECT_NE(std::string(e.what()).find("car-mirror.step"), std::string::npos) << e.what();
      continue;
    }
    EXPECT_FALSE(s.description.empty()) << name;
    EXPECT_EQ(s.elements.size(), 1u) << name;
    EXPECT_FALSE(s.environment.empty()) << name;
    EXPECT_FALSE(s.lights.empty()) << name;
    EXPECT_EQ(s.render.output, "out/" + std::string(name) + ".png");
  }
}

TEST(SceneJson, CarMirrorIsAConvexCadMirrorShowingTheRoadBehind) {
  if (!fs::exists(models() / "car-mirror.step")) GTEST_SKIP() << "models/car-mirror.step not generated yet";
  const SceneDesc s = loadScene((models() / "car-mirror.json").string());
  const ElementDesc& m = s.elements.at(0);
  EXPECT_EQ(m.surface.type, SurfaceDesc::Type::Cad);
  EXPECT_EQ(fs::path(m.surface.file).filename(), "car-mirror.step");
  EXPECT_FALSE(m.outline.has_value());
  EXPECT_EQ(m.mirror_material.metal, "chromium");
  // The eye ray to the mirror's centre, reflected by the vertex normal, must head back along the road (+z)
  // and stay nearly level (it sees the street, not the sky or the car's own door).
  const Vec3 d = glm::normalize(m.pose.position - s.observer.eye);
  const Vec3 r = d - 2.0 * glm::dot(d, m.pose.normal) * m.pose.normal;
  EXPECT_GT(r.z, 0.95);
  EXPECT_LT(std::abs(r.y), 0.1);
  EXPECT_LT(r.x, 0.0);  // towards the driver's (left) side
  EXPECT_NEAR(glm::length(m.pose.position - s.observer.eye), 0.6, 0.1);
}

TEST(SceneJson, SpectacleLensHasMinusThreeDioptresBackVertexPower) {
  const SceneDesc s = loadScene((models() / "spectacle-lens.json").string());
  const ElementDesc& l = s.elements.at(0);
  ASSERT_EQ(l.type, ElementDesc::Type::Lens);
  EXPECT_TRUE(l.attached_to_observer);
  EXPECT_EQ(l.lens_material.name, "cr39");
  const double n = l.lens_material.n_d, t = l.centre_thickness_m;
  EXPECT_NEAR(n, 1.498, 1e-12);  // the catalogue value, through the library's dispersion law
  // Object-side surface power F1 (light enters there) and eye-side F2, in the usual optics sign convention:
  // pvrr radii are positive when convex towards the eye (cad/sag.h), so F1 = -(n - 1)/R_back and
  // F2 = (n - 1)/R_front.
  const double f1 = -(n - 1) / l.back.radius_m, f2 = (n - 1) / l.front.radius_m;
  EXPECT_NEAR(f1, 4.0, kPowerTol_D);
  EXPECT_NEAR(f1 / (1 - t / n * f1) + f2, -3.0, kPowerTol_D);
  EXPECT_NEAR(l.pose.position.z, -0.012, 1e-15);  // 12 mm vertex distance, in front (-z) of the eye
}

TEST(SceneJson, ReadingLensHasPlusTwoAndAHalfDioptres) {
  const SceneDesc s = loadScene((models() / "reading-lens.json").string());
  const ElementDesc& l = s.elements.at(0);
  const double n = l.lens_material.n_d, t = l.centre_thickness_m;
  EXPECT_NEAR(n, 1.586, 1e-12);
  const double f1 = -(n - 1) / l.back.radius_m, f2 = (n - 1) / l.front.radius_m;
  EXPECT_NEAR(f1 + f2 - t / n * f1 * f2, 2.5, kPowerTol_D);  // thick-lens equivalent power
  EXPECT_EQ(s.render.dispersion, DispersionMode::Rgb);
  // Held 25-30 cm above the page (the page's plane is y = 0.75 m).
  EXPECT_GT(l.pose.position.y - 0.75, 0.25 - 1e-9);
  EXPECT_LT(l.pose.position.y - 0.75, 0.30);
}

TEST(SceneJson, ConcaveMirrorPlacesObjectsEitherSideOfFocusAndCentre) {
  const SceneDesc s = loadScene((models() / "concave-mirror.json").string());
  const ElementDesc& m = s.elements.at(0);
  EXPECT_DOUBLE_EQ(m.surface.radius_m, -0.6);
  const double f = std::abs(m.surface.radius_m) / 2;
  bool inside_f = false, beyond_c = false;
  for (const EnvObjectDesc& o : s.environment) {
    const double dist = glm::dot(o.position - m.pose.position, m.pose.normal);
    inside_f |= o.name == "cube-inside-f" && dist > 0 && dist < f;
    beyond_c |= o.name == "head" && dist > 2 * f;
  }
  EXPECT_TRUE(inside_f);
  EXPECT_TRUE(beyond_c);
}

// ---------------------------------------------------------------------------------------------------------
// Each class of bad input names the file, the JSON path and what was expected.

void expectContains(const std::string& message, const std::string& part) {
  EXPECT_NE(message.find(part), std::string::npos) << "message: " << message << "\nexpected to contain: " << part;
}

// The raster shaders hold at most kMaxLightsPerKind lights of each kind: one more is refused, naming the
// counts, rather than dropped in GL while the tracer keeps it.
TEST(SceneJson, TooManyLightsOfOneKindAreRejected) {
  auto withLights = [](size_t dir, size_t point) {
    std::string lights = "\"lights\": [{\"type\": \"ambient\"}";
    for (size_t i = 0; i < dir; ++i) lights += ", {\"type\": \"directional\", \"direction\": [0, -1, 0]}";
    for (size_t i = 0; i < point; ++i) lights += ", {\"type\": \"point\", \"position\": [0, 2, 0]}";
    return edited("\"environment\": [", lights + "],\n  \"environment\": [");
  };
  EXPECT_EQ(parse(withLights(kMaxLightsPerKind, kMaxLightsPerKind)).lights.size(), 2 * kMaxLightsPerKind + 1);
  EXPECT_EQ(errorOf(withLights(kMaxLightsPerKind + 1, 0)),
            kName + ": lights: expected at most 32 directional and 32 point lights, got 33 directional and 0 point");
  EXPECT_EQ(errorOf(withLights(0, kMaxLightsPerKind + 1)),
            kName + ": lights: expected at most 32 directional and 32 point lights, got 0 directional and 33 point");
}

TEST(SceneJson, SyntaxErrorGivesLineAndColumn) {
  // The stray '}' is on line 3, column 15.
  const std::string text = "{\n  \"version\": 1,\n  \"observer\": }\n";
  const std::string m = errorOf(text);
  expectContains(m, kName + ":3:15: ");
  expectContains(m, "syntax error");
}

TEST(SceneJson, WrongTypeNamesPathAndExpectation) {
  const std::string m = errorOf(edited("\"fov_y_deg\": 50", "\"fov_y_deg\": \"wide\""));
  EXPECT_EQ(m, kName + ": observer.fov_y_deg: expected an angle (degrees) in (0, 180), got \"wide\"");
}

TEST(SceneJson, OutOfRangeNamesPathAndExpectation) {
  EXPECT_EQ(errorOf(edited("\"n_d\": 1.5", "\"n_d\": 0.9")),
            kName + ": elements[1].material.n_d: expected a number in (1, 3], got 0.9");
  EXPECT_EQ(errorOf(edited("\"n_d\": 1.5", "\"n_d\": \"abc\"")),
            kName + ": elements[1].material.n_d: expected a number in (1, 3], got \"abc\"");
  expectContains(errorOf(edited("\"reflectance\": 0.9", "\"reflectance\": 1.5")),
                 "elements[0].material.reflectance: expected a number in (0, 1], got 1.5");
}

TEST(SceneJson, UnknownKeySuggestsTheNearest) {
  EXPECT_EQ(errorOf(edited("\"position\": [0, 1.2, -1], \"normal\"", "\"position\": [0, 1.2, -1], \"normall\"")),
            kName + ": elements[0].pose.normall: unknown key; did you mean \"normal\"?");
  // Far from every key: the known keys are listed instead.
  expectContains(errorOf(edited("\"version\": 1,", "\"version\": 1, \"zzzzzzzz\": 0,")),
                 "zzzzzzzz: unknown key; expected one of \"version\", \"units\"");
  // Enumerated values suggest too.
  expectContains(errorOf(edited("\"reflectance\": 0.9", "\"metal\": \"aluminum\"")),
                 "elements[0].material.metal: expected one of \"silver\", \"aluminium\" or \"chromium\", got "
                 "\"aluminum\"; did you mean \"aluminium\"?");
}

TEST(SceneJson, NonFiniteNumberIsRejectedWithPosition) {
  // JSON has no NaN or Inf literal, but 1e999 overflows to infinity; it is on line 3, in observer.eye[1].
  const std::string m = errorOf(edited("\"eye\": [0, 1.2, 0]", "\"eye\": [0, 1e999, 0]"));
  expectContains(m, kName + ":3:");
  expectContains(m, "observer.eye[1]: expected a finite number, got 1e999");
}

TEST(SceneJson, NegativeOrZeroSizesAreRejected) {
  EXPECT_EQ(errorOf(edited("\"size\": [1, 1, 1]", "\"size\": [1, -2, 1]")),
            kName + ": environment[0].size: expected a size [x, y, z] with each > 0, got [1,-2,1]");
  expectContains(errorOf(edited("\"diameter\": 0.2", "\"diameter\": 0")),
                 "elements[0].outline.diameter: expected a length > 0, got 0");
  expectContains(errorOf(edited("\"centre_thickness\": 0.002", "\"centre_thickness\": -0.002")),
                 "elements[1].centre_thickness: expected a length > 0, got -0.002");
}

TEST(SceneJson, ZeroVectorIsRejected) {
  const std::string text = edited("\"position\": [0, 1.2, -1], \"normal\": [0, 0, 1]",
                                  "\"position\": [0, 1.2, -1], \"normal\": [0, 0, 0]");
  EXPECT_EQ(errorOf(text), kName + ": elements[0].pose.normal: expected a non-zero direction [x, y, z], got [0,0,0]");
}

TEST(SceneJson, MissingReferencedFileIsNamed) {
  const fs::path dir = tempDir("missing");
  const std::string text = edited(R"({"type": "box", "name": "crate", "centre": [0, 0.5, -3], "size": [1, 1, 1]})",
                                  R"({"type": "mesh", "file": "meshes/nothere.obj"})");
  const std::string m = errorOf(text, {}, dir.string());
  expectContains(m, kName + ": environment[0].file: expected an existing OBJ, PLY, glTF or STL mesh");
  expectContains(m, (dir / "meshes" / "nothere.obj").string());
  expectContains(m, "got \"meshes/nothere.obj\"");
  // With the file present, the stored path is resolved against the scene's folder.
  touch(dir / "meshes" / "nothere.obj");
  const SceneDesc s = parseScene(text, kName, dir.string());
  EXPECT_EQ(fs::path(s.environment[0].file), dir / "meshes" / "nothere.obj");
  fs::remove_all(dir);
}

TEST(SceneJson, CadFileIsResolvedRelativeToTheSceneFile) {
  const fs::path dir = tempDir("cad");
  touch(dir / "parts" / "glass.step");
  const std::string scene = edited(R"("surface": {"type": "sphere", "radius": 1.4})",
                                   R"("surface": {"type": "cad", "file": "glass.step", "face": 2})",
                                   edited(R"("outline": {"shape": "circle", "diameter": 0.2}, )", ""));
  std::ofstream(dir / "parts" / "scene.json") << scene;
  const SceneDesc s = loadScene((dir / "parts" / "scene.json").string());
  EXPECT_EQ(fs::path(s.elements[0].surface.file), dir / "parts" / "glass.step");
  EXPECT_EQ(s.elements[0].surface.face, 2);
  // A CAD face brings its own boundary: an outline beside it is an error.
  std::ofstream(dir / "parts" / "scene.json")
      << edited(R"("surface": {"type": "sphere", "radius": 1.4})", R"("surface": {"type": "cad", "file": "glass.step"})");
  try {
    loadScene((dir / "parts" / "scene.json").string());
    ADD_FAILURE() << "outline beside a cad surface accepted";
  } catch (const Error& e) {
    expectContains(e.what(), "elements[0].outline: expected no outline with a \"cad\" surface");
  }
  fs::remove_all(dir);
}

TEST(SceneJson, BadVersionIsRejected) {
  EXPECT_EQ(errorOf(edited("\"version\": 1", "\"version\": 2")),
            kName + ": version: expected 1 (the only scene format version this pvrr reads), got 2");
  EXPECT_EQ(errorOf(edited("\"version\": 1,", "")),
            kName + ": version: expected 1 (the only scene format version this pvrr reads), got nothing");
}

TEST(SceneJson, DegenerateObserverIsRejected) {
  EXPECT_EQ(errorOf(edited("\"target\": [0, 1.2, -1]", "\"target\": [0, 1.2, 0]")),
            kName + ": observer.target: expected a point different from observer.eye, got [0,1.2,0]");
  expectContains(errorOf(edited("\"target\": [0, 1.2, -1]", "\"target\": [0, 1.2, -1], \"up\": [0, 0, -2]")),
                 "observer.up: expected a direction not parallel to the view direction (target - eye)");
}

TEST(SceneJson, SurfaceMustBeDefinedOverTheOutline) {
  // A 0.2 m circle reaches 0.1 m from the vertex: a sphere of radius 0.08 m cannot span it.
  EXPECT_EQ(errorOf(edited("\"radius\": 1.4", "\"radius\": -0.08")),
            kName + ": elements[0].surface.radius: expected |radius| > 0.1 m (the outline reaches 0.1 m from the "
                    "vertex), got -0.08");
  expectContains(errorOf(edited("\"radius\": 1.4", "\"radius\": 0")), "elements[0].surface.radius: expected a non-zero radius");
}

TEST(SceneJson, ConflictingFormsAreRejected) {
  expectContains(errorOf(edited("\"reflectance\": 0.9", "\"reflectance\": 0.9, \"metal\": \"silver\"")),
                 "elements[0].material: expected exactly one of {\"reflectance\"}, {\"metal\"} or {\"n\", \"k\"}");
  expectContains(errorOf(edited("\"centre_thickness\": 0.002,", "\"centre_thickness\": 0.002, \"prescription\": "
                                                                "{\"sphere_d\": -3},")),
                 "elements[1].prescription: expected either \"prescription\" or \"front\" and \"back\", not both");
  // A lens surface may be analytic or a CAD face, not a subdivision cage.
  expectContains(errorOf(edited(R"({"type": "sphere", "radius": -0.07})", R"({"type": "subdivision", "file": "x.obj"})")),
                 "elements[1].front.type: expected one of \"plane\", \"sphere\", \"asphere\", \"toric\", "
                 "\"cylinder\" or \"cad\", got \"subdivision\"");
}

TEST(SceneJson, DuplicateKeyIsRejected) {
  expectContains(errorOf(edited("\"fov_y_deg\": 50", "\"fov_y_deg\": 50, \"fov_y_deg\": 60")),
                 kName + ": observer.fov_y_deg: expected each key once in an object, got \"fov_y_deg\" twice");
}

TEST(SceneJson, DuplicateElementNameIsRejected) {
  expectContains(errorOf(edited("{\"name\": \"l\"", "{\"name\": \"m\"")),
                 "elements[1].name: expected a name no other element has (names default to \"element<index>\"), got \"m\"");
  // A default name can collide with an explicit one.
  expectContains(errorOf(edited("{\"name\": \"l\", ", "{", edited("{\"name\": \"m\"", "{\"name\": \"element1\""))),
                 "elements[1].name: expected a name no other element has (names default to \"element<index>\"), got nothing");
}

// ---------------------------------------------------------------------------------------------------------
// Defaults and details

TEST(SceneJson, DefaultsAreFilledIn) {
  const SceneDesc s = parse(kBase);
  EXPECT_EQ(s.units, "m");
  EXPECT_EQ(s.elements[0].tessellation.n_u, 7);  // mirrors: 7 x 7 as in the paper
  EXPECT_EQ(s.elements[1].tessellation.n_u, 24);
  EXPECT_EQ(s.elements[0].patches_u, 1);
  ASSERT_EQ(s.lights.size(), 1u);  // no "lights": white ambient
  EXPECT_EQ(s.lights[0].type, LightDesc::Type::Ambient);
  EXPECT_EQ(s.render.mode, RenderMode::Pvrr);
  EXPECT_EQ(s.render.map_size, 1024);
  EXPECT_EQ(s.render.map_texels_per_pixel, 4.0);
  EXPECT_EQ(s.render.map_reuse_margin_deg, 2.0);
  EXPECT_EQ(s.render.max_depth, 4);
  EXPECT_EQ(s.render.output, "out/test.png");
  EXPECT_TRUE(s.elements[1].attached_to_observer);
  EXPECT_FALSE(s.elements[0].attached_to_observer);
  EXPECT_EQ(s.elements[1].lens_material.kind, LensMaterialDesc::Kind::Abbe);
  EXPECT_EQ(s.environment[0].rotation, Mat3(1.0));
}

TEST(SceneJson, SellmeierMaterialGivesCatalogueIndex) {
  // Schott N-BK7 (optics-facts.md): n_d = 1.51680, V_d = 64.17.
  const std::string text = edited("\"n_d\": 1.5, \"V_d\": 58",
                                  "\"sellmeier\": {\"B\": [1.03961212, 0.231792344, 1.01046945], "
                                  "\"C\": [0.00600069867, 0.0200179144, 103.560653]}");
  const LensMaterialDesc m = parse(text).elements[1].lens_material;
  EXPECT_EQ(m.kind, LensMaterialDesc::Kind::Sellmeier);
  EXPECT_NEAR(m.n_d, 1.51680, 1e-5);  // data sheet value to its 5 decimals
  EXPECT_NEAR(m.V_d, 64.17, 0.01);    // to its 2 decimals
}

TEST(SceneJson, RotationDegreesComposeXThenYThenZ) {
  // rotation_deg [90, 0, 90]: x first (y -> z), then z (x -> y): local y ends up along world z, local x
  // along world y.
  const std::string text = edited("\"size\": [1, 1, 1]", "\"size\": [1, 1, 1], \"rotation_deg\": [90, 0, 90]");
  const Mat3 r = parse(text).environment[0].rotation;
  constexpr double kTol = 1e-12;  // a few roundings of sin/cos of 90 degrees
  EXPECT_NEAR(glm::length(r * Vec3(0, 1, 0) - Vec3(0, 0, 1)), 0.0, kTol);
  EXPECT_NEAR(glm::length(r * Vec3(1, 0, 0) - Vec3(0, 1, 0)), 0.0, kTol);
}

TEST(SceneJson, PrescriptionIsDescribed) {
  std::string text = edited(R"("front": {"type": "sphere", "radius": -0.07}, "back": {"type": "sphere", "radius": -0.12},)",
                            R"("prescription": {"sphere_d": -2.5, "cylinder_d": -0.75, "axis_deg": 90},)");
  text = edited("\"centre_thickness\": 0.002", "\"min_edge_thickness\": 0.0015", text);
  const ElementDesc e = parse(text).elements[1];
  ASSERT_TRUE(e.prescription.has_value());
  EXPECT_DOUBLE_EQ(e.prescription->sphere_d, -2.5);
  EXPECT_DOUBLE_EQ(e.prescription->cylinder_d, -0.75);
  EXPECT_DOUBLE_EQ(e.prescription->axis_deg, 90);
  EXPECT_FALSE(e.prescription->base_curve_d.has_value());
  EXPECT_DOUBLE_EQ(e.min_edge_thickness_m, 0.0015);
  EXPECT_EQ(e.centre_thickness_m, 0.0);
}

TEST(SceneJson, TessellationForms) {
  const auto tess = [](const std::string& value) {
    return parse(edited("\"material\": {\"reflectance\": 0.9}", "\"material\": {\"reflectance\": 0.9}, \"tessellation\": " + value))
        .elements[0]
        .tessellation;
  };
  EXPECT_EQ(tess("9").n_v, 9);
  EXPECT_EQ(tess("{\"u\": 5, \"v\": 11}").n_v, 11);
  const TessellationDesc a = tess("{\"tolerance\": 0.0001, \"angle_deg\": 2}");
  EXPECT_EQ(a.mode, TessellationDesc::Mode::Adaptive);
  EXPECT_DOUBLE_EQ(a.chordal_tolerance_m, 0.0001);
  expectContains(errorOf(edited("\"material\": {\"reflectance\": 0.9}", "\"material\": {\"reflectance\": 0.9}, "
                                                                     "\"tessellation\": 1")),
                 "elements[0].tessellation: expected an integer in [2, 1024], got 1");
  expectContains(errorOf(edited("\"material\": {\"reflectance\": 0.9}", "\"material\": {\"reflectance\": 0.9}, "
                                                                     "\"tessellation\": 5, \"patches\": [5, 1]")),
                 "elements[0].patches: expected [pu, pv] with 1 <= pu <= 4 and 1 <= pv <= 4");
}

TEST(SceneJson, TexturesAreValidated) {
  const auto withMaterial = [](const std::string& material) {
    return edited("\"size\": [1, 1, 1]", "\"size\": [1, 1, 1], \"material\": " + material);
  };
  const SceneDesc s = parse(withMaterial(R"({"texture": {"procedural": "eye-chart", "rows": 6}, "texture_scale": [0.5, 0.25]})"));
  const MaterialDesc& m = s.environment[0].material;
  ASSERT_TRUE(m.texture.has_value());
  EXPECT_EQ(m.texture->kind, TextureDesc::Kind::EyeChart);
  EXPECT_EQ(m.texture->rows, 6);
  EXPECT_EQ(m.color, Vec3(1.0));  // a texture's multiplier defaults to white
  EXPECT_FALSE(m.texture_fit);
  EXPECT_EQ(m.texture_scale_m, Vec2(0.5, 0.25));
  expectContains(errorOf(withMaterial(R"({"texture": {"procedural": "checker", "resolution": 2048}})")),
                 "environment[0].material.texture.resolution: expected an integer in [8, 1024], got 2048");
  expectContains(errorOf(withMaterial(R"({"texture": {"procedural": "eye-chart", "rows": 12, "resolution": 64}})")),
                 "environment[0].material.texture.rows: expected an integer in [1, ");
  expectContains(errorOf(withMaterial(R"({"texture": {"procedural": "brick"}})")),
                 "environment[0].material.texture.procedural: expected one of \"checker\", \"eye-chart\", \"page\", "
                 "\"bricks\", \"road\", \"windows\", \"sky\" or \"sign\", got \"brick\"; did you mean \"bricks\"?");
  expectContains(errorOf(withMaterial(R"({"texture": {"procedural": "sky", "lanes": 2}})")),
                 "environment[0].material.texture.lanes: unknown key");
  expectContains(errorOf(withMaterial(R"({"texture": {"image": "wall.png"}})")),
                 "environment[0].material.texture.image: expected an existing PNG image");
  expectContains(errorOf(withMaterial(R"({"color": [0.5, 1.5, 0]})")),
                 "environment[0].material.color: expected a colour [r, g, b] with each in [0, 1], got [0.5,1.5,0]");
}

// ---------------------------------------------------------------------------------------------------------
// Units

TEST(SceneJson, MillimetreSceneEqualsMetreScene) {
  const std::string metres = R"({
    "version": 1, "units": "m",
    "observer": {"eye": [0.1, 1.2, 0.3], "target": [0, 1.2, -1]},
    "environment": [
      {"type": "quad", "centre": [0, 1, -2], "normal": [0, 0, 1], "size": [0.6, 0.9],
       "material": {"texture": {"procedural": "checker"}, "texture_scale": [0.2, 0.3]}},
      {"type": "sphere", "centre": [0.5, 0.5, -1.5], "radius": 0.25},
      {"type": "box", "centre": [1, 0.5, -1.5], "size": [0.5, 1, 0.25]}
    ],
    "lights": [{"type": "point", "position": [0, 2.5, 0], "intensity": 3}],
    "elements": [
      {"name": "a", "type": "mirror", "pose": {"position": [0, 1.2, -1], "normal": [0, 0, 1]},
       "outline": {"shape": "rectangle", "width": 0.2, "height": 0.15, "corner_radius": 0.02},
       "surface": {"type": "asphere", "radius": 1.2, "conic": -0.5, "coefficients": [0.5, -2.0]},
       "tessellation": {"tolerance": 0.0001}},
      {"name": "b", "type": "lens", "pose": {"position": [0, 0, -0.012], "normal": [0, 0, 1]},
       "outline": {"shape": "circle", "diameter": 0.05},
       "front": {"type": "toric", "radius_a": -0.07, "radius_b": -0.08, "axis_deg": 30},
       "back": {"type": "sphere", "radius": -0.12}, "min_edge_thickness": 0.001, "centre_thickness": 0.002,
       "material": {"name": "trivex"}}
    ]
  })";
  // The same scene in millimetres: every length x 1000; A4 (length^-3) x 1e-9, A6 (length^-5) x 1e-15.
  const std::string millimetres = R"({
    "version": 1, "units": "mm",
    "observer": {"eye": [100, 1200, 300], "target": [0, 1200, -1000]},
    "environment": [
      {"type": "quad", "centre": [0, 1000, -2000], "normal": [0, 0, 1], "size": [600, 900],
       "material": {"texture": {"procedural": "checker"}, "texture_scale": [200, 300]}},
      {"type": "sphere", "centre": [500, 500, -1500], "radius": 250},
      {"type": "box", "centre": [1000, 500, -1500], "size": [500, 1000, 250]}
    ],
    "lights": [{"type": "point", "position": [0, 2500, 0], "intensity": 3}],
    "elements": [
      {"name": "a", "type": "mirror", "pose": {"position": [0, 1200, -1000], "normal": [0, 0, 1]},
       "outline": {"shape": "rectangle", "width": 200, "height": 150, "corner_radius": 20},
       "surface": {"type": "asphere", "radius": 1200, "conic": -0.5, "coefficients": [0.5e-9, -2.0e-15]},
       "tessellation": {"tolerance": 0.1}},
      {"name": "b", "type": "lens", "pose": {"position": [0, 0, -12], "normal": [0, 0, 1]},
       "outline": {"shape": "circle", "diameter": 50},
       "front": {"type": "toric", "radius_a": -70, "radius_b": -80, "axis_deg": 30},
       "back": {"type": "sphere", "radius": -120}, "min_edge_thickness": 1, "centre_thickness": 2,
       "material": {"name": "trivex"}}
    ]
  })";
  const SceneDesc m = parse(metres), mm = parse(millimetres);
  EXPECT_DOUBLE_EQ(mm.unit_m, 1e-3);
  const auto near = [](double a, double b) { return std::abs(a - b) <= kUnitTol * std::max(1.0, std::abs(a)); };
  const auto nearV = [&](const Vec3& a, const Vec3& b) { return near(a.x, b.x) && near(a.y, b.y) && near(a.z, b.z); };
  EXPECT_TRUE(nearV(m.observer.eye, mm.observer.eye));
  EXPECT_TRUE(nearV(m.observer.target, mm.observer.target));
  for (size_t i = 0; i < m.environment.size(); ++i) {
    EXPECT_TRUE(nearV(m.environment[i].position, mm.environment[i].position)) << i;
    EXPECT_TRUE(nearV(m.environment[i].size, mm.environment[i].size)) << i;
    EXPECT_TRUE(near(m.environment[i].radius_m, mm.environment[i].radius_m)) << i;
  }
  EXPECT_TRUE(near(m.environment[0].material.texture_scale_m.y, mm.environment[0].material.texture_scale_m.y));
  EXPECT_TRUE(nearV(m.lights[0].position, mm.lights[0].position));
  const ElementDesc &a = m.elements[0], &b = mm.elements[0];
  EXPECT_TRUE(near(a.outline->width_m, b.outline->width_m));
  EXPECT_TRUE(near(a.outline->corner_radius_m, b.outline->corner_radius_m));
  EXPECT_TRUE(near(a.surface.radius_m, b.surface.radius_m));
  ASSERT_EQ(b.surface.coefficients.size(), 2u);
  EXPECT_TRUE(near(a.surface.coefficients[0], b.surface.coefficients[0]));
  EXPECT_TRUE(near(a.surface.coefficients[1], b.surface.coefficients[1]));
  EXPECT_TRUE(near(a.tessellation.chordal_tolerance_m, b.tessellation.chordal_tolerance_m));
  const ElementDesc &c = m.elements[1], &d = mm.elements[1];
  EXPECT_TRUE(nearV(c.pose.position, d.pose.position));
  EXPECT_TRUE(near(c.front.radius_a_m, d.front.radius_a_m));
  EXPECT_TRUE(near(c.front.radius_b_m, d.front.radius_b_m));
  EXPECT_TRUE(near(c.centre_thickness_m, d.centre_thickness_m));
  EXPECT_TRUE(near(c.min_edge_thickness_m, d.min_edge_thickness_m));
  EXPECT_DOUBLE_EQ(c.front.axis_deg, d.front.axis_deg);  // angles are not lengths
  EXPECT_DOUBLE_EQ(m.lights[0].intensity, mm.lights[0].intensity);
}

TEST(SceneJson, UnitsMustBeKnown) {
  EXPECT_EQ(errorOf(edited("\"version\": 1,", "\"version\": 1, \"units\": \"cm\",")),
            kName + ": units: expected one of \"m\" or \"mm\", got \"cm\"");
}

// ---------------------------------------------------------------------------------------------------------
// --set overrides

TEST(SceneJson, OverridesTakeEffect) {
  const SceneDesc s = parse(kBase, {"render.map_size=512",             // number, in a section the file lacks
                                    "observer.eye=[0, 1.5, 0.5]",      // array
                                    "render.mode=raster",              // not JSON: a string
                                    "elements[0].pose.position=[0, 1.3, -1]",  // nested
                                    "elements[1].tessellation=9",      // array index
                                    "render.map_size=256"});           // later overrides win
  EXPECT_EQ(s.render.map_size, 256);
  EXPECT_EQ(s.observer.eye, Vec3(0, 1.5, 0.5));
  EXPECT_EQ(s.render.mode, RenderMode::Raster);
  EXPECT_EQ(s.elements[0].pose.position, Vec3(0, 1.3, -1));
  EXPECT_EQ(s.elements[1].tessellation.n_u, 9);
  EXPECT_EQ(s.elements[0].tessellation.n_u, 7);
}

TEST(SceneJson, OverridesAreInTheFileUnits) {
  const std::string mm = edited("\"version\": 1,", "\"version\": 1, \"units\": \"mm\",",
                                edited("\"eye\": [0, 1.2, 0], \"target\": [0, 1.2, -1]",
                                       "\"eye\": [0, 1200, 0], \"target\": [0, 1200, -1000]"));
  const SceneDesc s = parseScene(mm, kName, "", {"observer.eye=[0,1500,0]"});
  EXPECT_DOUBLE_EQ(s.observer.eye.y, 1.5);
}

TEST(SceneJson, OverridesAreValidatedLikeTheFile) {
  EXPECT_EQ(errorOf(kBase, {"render.map_size=abc"}),
            kName + ": render.map_size: expected an integer in [16, 16384], got \"abc\" (from --set render.map_size=abc)");
  EXPECT_EQ(errorOf(kBase, {"elements[0].pose.normal=[0,0,0]"}),
            kName + ": elements[0].pose.normal: expected a non-zero direction [x, y, z], got [0,0,0] (from --set "
                    "elements[0].pose.normal=[0,0,0])");
  expectContains(errorOf(kBase, {"observer.target=[0,1.2,0]"}), "observer.target: expected a point different");
  EXPECT_EQ(parse(kBase, {"render.map_texels_per_pixel=0"}).render.map_texels_per_pixel, 0.0);
  expectContains(errorOf(kBase, {"render.map_texels_per_pixel=-1"}), "render.map_texels_per_pixel: expected a number in [0, 10000]");
  EXPECT_EQ(parse(kBase, {"render.map_reuse_margin_deg=0"}).render.map_reuse_margin_deg, 0.0);
  expectContains(errorOf(kBase, {"render.map_reuse_margin_deg=11"}), "render.map_reuse_margin_deg: expected a number in [0, 10]");
  EXPECT_EQ(parse(kBase).render.impostor_iterations, 8);
  EXPECT_EQ(parse(kBase, {"render.impostor_iterations=0"}).render.impostor_iterations, 0);
  expectContains(errorOf(kBase, {"render.impostor_iterations=65"}), "render.impostor_iterations: expected an integer in [0, 64]");
  EXPECT_EQ(parse(kBase).render.impostor_layers, 2);
  EXPECT_EQ(parse(kBase, {"render.impostor_layers=1"}).render.impostor_layers, 1);
  expectContains(errorOf(kBase, {"render.impostor_layers=3"}), "render.impostor_layers: expected an integer in [1, 2]");
}

TEST(SceneJson, OverrideOfAnUnknownPathFailsNamingIt) {
  EXPECT_EQ(errorOf(kBase, {"render.map_sizee=512"}),
            kName + ": render.map_sizee: unknown key; did you mean \"map_size\"? (from --set render.map_sizee=512)");
  expectContains(errorOf(kBase, {"observer.eyes=[0,1,0]"}), "observer.eyes: unknown key; did you mean \"eye\"?");
  expectContains(errorOf(kBase, {"elements[5].tessellation=9"}),
                 kName + ": --set elements[5].tessellation=9: elements[5]: expected an index < 2");
  expectContains(errorOf(kBase, {"observer.eye.x=1"}),
                 "--set observer.eye.x=1: observer.eye: expected an object to hold \"x\", got [0,1.2,0]");
  expectContains(errorOf(kBase, {"render.map_size"}), "--set render.map_size: expected PATH=VALUE");
  expectContains(errorOf(kBase, {"render..map_size=1"}), "expected a path like elements[0].pose.position");
}

TEST(SceneJson, EditDistanceCountsTranspositionsOnce) {
  EXPECT_EQ(editDistance("kitten", "sitting"), 3);
  EXPECT_EQ(editDistance("", "abc"), 3);
  EXPECT_EQ(editDistance("normal", "normal"), 0);
  EXPECT_EQ(editDistance("nromal", "normal"), 1);
  EXPECT_EQ(editDistance("diametre", "diameter"), 1);
}

TEST(SceneJson, DocumentationExampleIsValid) {
  // docs/scene-format.md ends with a complete example in a ```json block: it must load.
  std::ifstream in(fs::path(PVRR_SOURCE_DIR) / "docs" / "scene-format.md");
  ASSERT_TRUE(in.good());
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t start = doc.rfind("```json\n");
  ASSERT_NE(start, std::string::npos);
  const size_t end = doc.find("```", start + 8);
  ASSERT_NE(end, std::string::npos);
  const std::string example = doc.substr(start + 8, end - start - 8);
  const fs::path dir = tempDir("doc");
  for (const char* f : {"textures/wood.png", "meshes/bench.obj", "car-mirror.step"}) touch(dir / f);
  const SceneDesc s = parseScene(example, "scene-format.md", dir.string());
  EXPECT_EQ(s.units, "mm");
  EXPECT_EQ(s.environment.size(), 6u);
  EXPECT_EQ(s.lights.size(), 3u);
  EXPECT_EQ(s.elements.size(), 4u);
  EXPECT_DOUBLE_EQ(s.observer.eye.y, 1.2);
  fs::remove_all(dir);
}

TEST(SceneJson, LoadSceneReportsAMissingSceneFile) {
  try {
    loadScene("/nonexistent/scene.json");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/scene.json: cannot open the scene file");
  }
}

// ---------------------------------------------------------------------------------------------------------
// Lens surfaces from CAD files

TEST(SceneJson, ProgressiveLensHasANurbsBackAndIsPlanoForDistance) {
  const SceneDesc s = loadScene((models() / "progressive-lens.json").string());
  const ElementDesc& l = s.elements.at(0);
  EXPECT_EQ(l.type, ElementDesc::Type::Lens);
  EXPECT_TRUE(l.attached_to_observer);
  EXPECT_EQ(l.front.type, SurfaceDesc::Type::Sphere);
  EXPECT_EQ(l.back.type, SurfaceDesc::Type::Cad);
  EXPECT_EQ(fs::path(l.back.file), models() / "progressive-back.igs");
  EXPECT_EQ(l.back.face, 0);
  // Distance zone (the base sphere at the vertex): back vertex power F1 / (1 - (t/n) F1) + F2 = 0.
  using D = cad::ProgressiveBackDesign;
  const double n = l.lens_material.n_d, t = l.centre_thickness_m;
  EXPECT_DOUBLE_EQ(n, D::n_d);
  const double f1 = -(n - 1) / (D::base_radius_mm * 1e-3), f2 = (n - 1) / l.front.radius_m;
  EXPECT_NEAR(f1 / (1 - t / n * f1) + f2, 0.0, kPowerTol_D);
  // Built: the back is the file's NURBS surface as a sag graph in metres, its vertex at -t.
  const Scene scene = buildScene(s);
  const Element& e = scene.elements.at(0);
  EXPECT_NE(e.lens.back->describe().find("progressive-back.igs face 0"), std::string::npos) << e.lens.back->describe();
  EXPECT_EQ(e.lens.back->zVertex(), -t);
  EXPECT_NEAR(e.lens.back->evaluate(0, 0).p.z, -t, 1e-15);
  // Against the design, in metres, within the bicubic fit's error (0.5 um, tests/cad/lens_test.cpp).
  EXPECT_NEAR(e.lens.back->evaluate(0.0, 0.01).p.z + t, D::z(0, 10) * 1e-3, 1e-6);
  EXPECT_NEAR(e.lens.back->evaluate(0.012, -0.015).p.z + t, D::z(12, -15) * 1e-3, 1e-6);
  EXPECT_GT(e.lens.minimumThickness(), 0.001);
}

// The scene kBase with its lens's back surface replaced by a CAD face, resolved against models/.
std::string cadBackScene(const std::string& back, const std::string& front = R"({"type": "sphere", "radius": -0.07})",
                         const std::string& thickness = "0.002") {
  return edited(R"("front": {"type": "sphere", "radius": -0.07}, "back": {"type": "sphere", "radius": -0.12},
     "centre_thickness": 0.002)",
                R"("front": )" + front + R"(, "back": )" + back + R"(,
     "centre_thickness": )" + thickness);
}

// The message of the pvrr::Error that building the scene raises.
std::string buildErrorOf(const std::string& text, const std::string& base_dir) {
  const SceneDesc desc = parseScene(text, kName, base_dir);
  try {
    buildScene(desc);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error building the scene";
  return "";
}

TEST(SceneJson, LensCadSurfaceIsParsedAndBuilt) {
  const std::string text = cadBackScene(R"({"type": "cad", "file": "progressive-back.igs"})");
  const SceneDesc s = parseScene(text, kName, models().string());
  EXPECT_EQ(s.elements[1].back.type, SurfaceDesc::Type::Cad);
  EXPECT_EQ(s.elements[1].back.face, 0);
  const Scene scene = buildScene(s);
  EXPECT_EQ(scene.elements[1].lens.back->zVertex(), -0.002);
  // A lens surface cannot be a subdivision cage (only analytic and CAD surfaces are graphs over the lens).
  expectContains(errorOf(cadBackScene(R"({"type": "subdivision", "file": "freeform-mirror-cage.obj"})"), {},
                         models().string()),
                 kName + ": elements[1].back.type: expected one of");
}

TEST(SceneJson, LensCadSurfaceErrorsNameThePathAndTheFile) {
  const fs::path dir = tempDir("lens_cad");
  fs::copy_file(models() / "progressive-back.igs", dir / "progressive-back.igs");
  // Missing file: at parse time.
  std::string m = errorOf(cadBackScene(R"({"type": "cad", "file": "nothere.igs"})"), {}, dir.string());
  expectContains(m, kName + ": elements[1].back.file: expected an existing STEP or IGES file");
  expectContains(m, (dir / "nothere.igs").string());
  // A face index beyond the file's faces.
  m = buildErrorOf(cadBackScene(R"({"type": "cad", "file": "progressive-back.igs", "face": 1})"), dir.string());
  expectContains(m, kName + ": elements[1].back.face: ");
  expectContains(m, (dir / "progressive-back.igs").string());
  expectContains(m, "face 1 requested, the file has 1 face(s)");
  // A valid STEP file without any surface (one point).
  std::ofstream(dir / "point.step")
      << "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\nFILE_NAME('point.step','2024-01-01T00:00:00',"
         "(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n"
         "#1=CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;\nEND-ISO-10303-21;\n";
  m = buildErrorOf(cadBackScene(R"({"type": "cad", "file": "point.step"})"), dir.string());
  expectContains(m, kName + ": elements[1].back.file: ");
  expectContains(m, (dir / "point.step").string());
  // Surfaces crossing: the add raises the back towards the eye by ~0.8 mm at the bottom; 0.3 mm is too thin.
  m = buildErrorOf(cadBackScene(R"({"type": "cad", "file": "progressive-back.igs"})",
                                R"({"type": "sphere", "radius": -0.123668})", "0.0003"),
                   dir.string());
  expectContains(m, kName + ": elements[1] (l): the surfaces cross or touch inside the outline");
  expectContains(m, "progressive-back.igs face 0");
  // An outline reaching beyond the 56 x 46 mm blank.
  m = buildErrorOf(edited(R"("width": 0.05, "height": 0.04)", R"("width": 0.07, "height": 0.04)",
                          cadBackScene(R"({"type": "cad", "file": "progressive-back.igs"})")),
                   dir.string());
  expectContains(m, kName + ": elements[1] (l): back surface");
  expectContains(m, "progressive-back.igs face 0");
  expectContains(m, "is undefined at (x, y)");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pvrr
