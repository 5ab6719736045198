// The scene format's name tables (render_desc.h, scene_desc.h): every value round-trips through its table,
// the lists come out in the order today's messages name them, unknown names give those messages, and the
// render settings' defaults are written once (the description, the parser and the runtime scene agree).
#include <gtest/gtest.h>

#include "pvrr/base/error.h"
#include "pvrr/method/vertex_stage.h"
#include "pvrr/scene/render_desc.h"
#include "pvrr/scene/scene.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_desc.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr {
namespace {

const std::string kName = "scenes/names.json";

// Every enumerator of E, numbered from 0 to `last`, is in E's table exactly once, and its name parses back.
template <class E>
void expectComplete(E last) {
  const auto& table = nameTable(E{});
  ASSERT_EQ(table.size(), size_t(last) + 1) << nameList<E>();
  EXPECT_TRUE(namesAreUnique(table)) << nameList<E>();
  for (size_t i = 0; i <= size_t(last); ++i) {
    const E value = static_cast<E>(i);
    const std::string name = nameOf(value);
    EXPECT_NE(name, "?") << "enumerator " << i << " has no name in " << nameList<E>();
    EXPECT_EQ(parseName<E>(name), value) << name;
  }
}

TEST(SceneNames, EveryValueRoundTripsThroughItsTable) {
  expectComplete(RenderMode::Impostor);
  expectComplete(DispersionMode::Spectral);
  expectComplete(TextureDesc::Kind::Sign);
  expectComplete(LightDesc::Type::Ambient);
  expectComplete(EnvObjectDesc::Type::Quad);
  expectComplete(SurfaceDesc::Type::Subdivision);
  expectComplete(OutlineDesc::Shape::Circle);
  expectComplete(ElementDesc::Type::Lens);
  expectComplete(VertexStatus::Tir);
}

// The orders the messages have always listed the choices in (docs/scene-format.md, pvrr help).
TEST(SceneNames, ListsAreInTheMessagesOrder) {
  EXPECT_EQ(nameList<RenderMode>(), "pvrr, raster, raytrace, envmap, impostor");
  EXPECT_EQ(nameListIf<RenderMode>(isRasterMode), "pvrr, raster, envmap, impostor");
  EXPECT_EQ(nameList<DispersionMode>(), "off, rgb, spectral");
  EXPECT_EQ(nameList<TextureDesc::Kind>(), "image, checker, eye-chart, page, bricks, road, windows, sky, sign");
  EXPECT_EQ(nameList<LightDesc::Type>(), "directional, point, ambient");
  EXPECT_EQ(nameList<EnvObjectDesc::Type>(), "mesh, ground, box, sphere, quad");
  EXPECT_EQ(nameList<SurfaceDesc::Type>(), "plane, sphere, asphere, toric, cylinder, cad, subdivision");
  EXPECT_EQ(nameList<OutlineDesc::Shape>(), "rectangle, ellipse, circle");
  EXPECT_EQ(nameList<ElementDesc::Type>(), "mirror, lens");
  EXPECT_EQ(nameList<VertexStatus>(), "hit, escape, tir");
}

// A valid scene with one of each kind of section; `render` is the render section ("" for none).
std::string scene(const std::string& render = "", const std::string& light_type = "directional",
                  const std::string& env_type = "box", const std::string& element_type = "mirror",
                  const std::string& shape = "circle", const std::string& surface_type = "sphere") {
  return R"({
  "version": 1,
  "observer": {"eye": [0, 1.2, 0], "target": [0, 1.2, -1]},
  "lights": [{"type": ")" + light_type + R"(", "direction": [0, -1, 0]}],
  "environment": [{"type": ")" + env_type + R"(", "centre": [0, 0.5, -3], "size": [1, 1, 1]}],
  "elements": [
    {"name": "m", "type": ")" + element_type + R"(", "pose": {"position": [0, 1.2, -1], "normal": [0, 0, 1]},
     "outline": {"shape": ")" + shape + R"(", "diameter": 0.2},
     "surface": {"type": ")" + surface_type + R"(", "radius": 1.4}}
  ])" + (render.empty() ? "" : ",\n  \"render\": " + render) + "\n}";
}

// `text` with its one `from` replaced by `to`.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

std::string errorOf(const std::string& text) {
  try {
    parseScene(text, kName, "", {});
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for the scene";
  return "";
}

TEST(SceneNames, ScenesNameEveryValue) {
  for (const auto& [mode, name] : kRenderModeNames)
    EXPECT_EQ(parseScene(scene(std::string(R"({"mode": ")") + name + "\"}"), kName, "").render.mode, mode);
  for (const auto& [dispersion, name] : kDispersionModeNames)
    EXPECT_EQ(parseScene(scene(std::string(R"({"dispersion": ")") + name + "\"}"), kName, "").render.dispersion,
              dispersion);
}

TEST(SceneNames, UnknownNamesGiveTheDocumentedMessages) {
  EXPECT_EQ(errorOf(scene(R"({"mode": "rastr"})")),
            kName + ": render.mode: expected one of \"pvrr\", \"raster\", \"raytrace\", \"envmap\" or \"impostor\", "
                    "got \"rastr\"; did you mean \"raster\"?");
  EXPECT_EQ(errorOf(scene(R"({"dispersion": "full"})")),
            kName + ": render.dispersion: expected one of \"off\", \"rgb\" or \"spectral\", got \"full\"");
  EXPECT_EQ(errorOf(scene("", "spot")),
            kName + ": lights[0].type: expected one of \"directional\", \"point\" or \"ambient\", got \"spot\"");
  EXPECT_EQ(errorOf(scene("", "directional", "cube")),
            kName + ": environment[0].type: expected one of \"mesh\", \"ground\", \"box\", \"sphere\" or \"quad\", "
                    "got \"cube\"");
  EXPECT_EQ(errorOf(scene("", "directional", "box", "prism")),
            kName + ": elements[0].type: expected one of \"mirror\" or \"lens\", got \"prism\"");
  EXPECT_EQ(errorOf(scene("", "directional", "box", "mirror", "square")),
            kName + ": elements[0].outline.shape: expected one of \"rectangle\", \"ellipse\" or \"circle\", got "
                    "\"square\"");
  EXPECT_EQ(errorOf(scene("", "directional", "box", "mirror", "circle", "paraboloid")),
            kName + ": elements[0].surface.type: expected one of \"plane\", \"sphere\", \"asphere\", \"toric\", "
                    "\"cylinder\", \"cad\" or \"subdivision\", got \"paraboloid\"");
  // Not an object: the alternatives in the same order.
  EXPECT_EQ(errorOf(replaced(scene(), R"({"type": "directional", "direction": [0, -1, 0]})", "3")),
            kName + ": lights[0]: expected a light {\"type\": \"directional\" | \"point\" | \"ambient\", ...}, got 3");
  EXPECT_EQ(errorOf(replaced(scene(), R"({"type": "box", "centre": [0, 0.5, -3], "size": [1, 1, 1]})", "\"box\"")),
            kName + ": environment[0]: expected an environment object {\"type\": \"mesh\" | \"ground\" | \"box\" | "
                    "\"sphere\" | \"quad\", ...}, got \"box\"");
  EXPECT_EQ(errorOf(replaced(scene(), R"({"shape": "circle", "diameter": 0.2})", "0.2")),
            kName + ": elements[0].outline: expected an outline {\"shape\": \"rectangle\" | \"ellipse\" | \"circle\", "
                    "...}, got 0.2");
  EXPECT_EQ(errorOf(replaced(scene(), "\"elements\": [", "\"elements\": [true, ")),
            kName + ": elements[0]: expected an element {\"type\": \"mirror\" | \"lens\", ...}, got true");
}

// Each field of the render settings, compared.
void expectSameSettings(const RenderDesc& a, const RenderDesc& b, const std::string& what) {
  EXPECT_EQ(a.mode, b.mode) << what;
  EXPECT_EQ(a.map_size, b.map_size) << what;
  EXPECT_EQ(a.map_texels_per_pixel, b.map_texels_per_pixel) << what;
  EXPECT_EQ(a.map_reuse_margin_deg, b.map_reuse_margin_deg) << what;
  EXPECT_EQ(a.impostor_iterations, b.impostor_iterations) << what;
  EXPECT_EQ(a.impostor_layers, b.impostor_layers) << what;
  EXPECT_EQ(a.output, b.output) << what;
  EXPECT_EQ(a.max_depth, b.max_depth) << what;
  EXPECT_EQ(a.dispersion, b.dispersion) << what;
  EXPECT_EQ(a.spectral_samples, b.spectral_samples) << what;
  EXPECT_EQ(a.background, b.background) << what;
}

TEST(SceneNames, RenderDefaultsAreWrittenOnce) {
  // The scene format's defaults (docs/scene-format.md).
  const RenderDesc d;
  EXPECT_EQ(d.mode, RenderMode::Pvrr);
  EXPECT_EQ(d.map_size, 1024);
  EXPECT_EQ(d.map_texels_per_pixel, 4);
  EXPECT_EQ(d.map_reuse_margin_deg, 2);
  EXPECT_EQ(d.impostor_iterations, 8);
  EXPECT_EQ(d.impostor_layers, 2);
  EXPECT_EQ(d.max_depth, 4);
  EXPECT_EQ(d.dispersion, DispersionMode::Off);
  EXPECT_EQ(d.spectral_samples, 16);
  EXPECT_EQ(d.background, Vec3(0.55, 0.7, 0.9));

  expectSameSettings(RenderSettings{}, d, "the runtime scene's defaults");
  // The parser's defaults: no render section, or an empty one. Only the output is filled in.
  RenderDesc with_output = d;
  with_output.output = "out/names.png";
  expectSameSettings(parseScene(scene(), kName, "").render, with_output, "no render section");
  expectSameSettings(parseScene(scene("{}"), kName, "").render, with_output, "an empty render section");
  // The build carries every field over.
  const SceneDesc desc = parseScene(scene(R"({"mode": "impostor", "map_size": 512, "map_texels_per_pixel": 2,
      "map_reuse_margin_deg": 1, "impostor_iterations": 5, "impostor_layers": 1, "output": "x/y.png",
      "max_depth": 6, "dispersion": "spectral", "spectral_samples": 9, "background": [0.1, 0.2, 0.3]})"),
                                    kName, "");
  expectSameSettings(buildScene(desc).render, desc.render, "built");
  expectSameSettings(buildScene(parseScene(scene(), kName, "")).render, with_output, "built with the defaults");
}

TEST(SceneNames, DispersionChannelsByNameUseTheTable) {
  const Scene s = buildScene(parseScene(scene(), kName, ""));
  EXPECT_EQ(dispersionChannels(s, 0, "rgb", 16).size(), dispersionChannels(s, 0, DispersionMode::Rgb, 16).size());
  try {
    dispersionChannels(s, 0, "spectrum", 16);
    ADD_FAILURE() << "no error for an unknown dispersion mode";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "render.dispersion: expected one of off, rgb, spectral; got \"spectrum\"");
  }
}

}  // namespace
}  // namespace pvrr
