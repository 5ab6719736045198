// Golden images: every shipped scene (models/*.json) in every raster mode at 160 x 120, drawn as `pvrr
// compare` draws its accuracy frames (the scene's render settings, seen points on, a fresh renderer per mode),
// compared with tests/golden/images/SCENE-MODE.png (support/golden.h: thresholds, diff images, and
// PVRR_UPDATE_GOLDEN=1 to rewrite them). The references were drawn by OSMesa (llvmpipe); the test runs on OSMesa
// and EGL. A new scene fails here until its references are written.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <string>
#include <tuple>
#include <vector>

#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "support/gl_backends.h"
#include "support/golden.h"
#include "support/scenes.h"

namespace pvrr {
namespace gl {
// The backend's name in test names and messages (gtest prints a parameter's bytes otherwise).
void PrintTo(GlBackend b, std::ostream* os) { *os << glBackendName(b); }
}  // namespace gl

namespace {

// Small enough that the 32 pictures of one backend take about 13 s on llvmpipe (2 cores), large enough that each
// element covers thousands of pixels.
constexpr int kWidth = 160, kHeight = 120;

// The shipped scenes' names (models/*.json), sorted.
std::vector<std::string> shippedSceneNames() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(PVRR_SOURCE_DIR) + "/models"))
    if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

using Param = std::tuple<gl::GlBackend, std::string>;
class GoldenTest : public ::testing::TestWithParam<Param> {};

TEST_P(GoldenTest, EveryRasterModeMatchesItsReference) {
  const auto& [backend, name] = GetParam();
  const auto ctx = test::glContextOrFail(backend);
  if (!ctx) return;
  const Scene s = test::shippedScene(name, {"observer.image_size=[" + std::to_string(kWidth) + "," +
                                                std::to_string(kHeight) + "]"});
  const RayScene rays(s);
  for (const RenderMode mode : {RenderMode::Raster, RenderMode::Pvrr, RenderMode::Envmap, RenderMode::Impostor}) {
    gl::Renderer r(s, rays, gl::rendererOptionsFor(s));  // as pvrr render and compare set it up
    const gl::RasterFrame f = r.render(mode);
    ASSERT_EQ(f.width, kWidth);
    ASSERT_EQ(f.height, kHeight);
    const ::testing::AssertionResult match =
        test::matchesGolden(name + "-" + nameOf(mode), srgbPicture(f));
    EXPECT_TRUE(match);
    if (match) std::printf("%s\n", match.message());  // the differences within the thresholds, for the log
  }
}

INSTANTIATE_TEST_SUITE_P(ShippedScenes, GoldenTest,
                         ::testing::Combine(::testing::Values(gl::GlBackend::OsMesa, gl::GlBackend::Egl),
                                            ::testing::ValuesIn(shippedSceneNames())),
                         [](const ::testing::TestParamInfo<Param>& info) {
                           std::string n = std::get<1>(info.param);
                           std::replace(n.begin(), n.end(), '-', '_');
                           return std::string(std::get<0>(info.param) == gl::GlBackend::OsMesa ? "OsMesa_" : "Egl_") + n;
                         });

}  // namespace
}  // namespace pvrr
