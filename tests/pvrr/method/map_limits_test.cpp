// Map sizes against the GL's limits and a memory budget before any pass runs (pvrr/method/map_limits.h).
#include <gtest/gtest.h>

#include <string>

#include "pvrr/base/error.h"
#include "pvrr/method/map_limits.h"
#include "support/scenes.h"

namespace pvrr {
namespace {

GlLimits roomyLimits() {
  GlLimits g;
  g.max_texture_size = g.max_cube_map_size = g.max_renderbuffer_size = 16384;
  g.memory_bytes = 1e15;
  g.memory_source = "test";
  return g;
}

// The error's text, or "" when checkMapLimits accepts.
std::string refusal(const Scene& s, RenderMode mode, const MapSizeSettings& m, const GlLimits& g) {
  try {
    checkMapLimits(s, mode, m, g);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(MapLimits, MemoryCountsEveryTargetByHand) {
  const Scene s = test::shippedScene("plane-mirror");  // one mirror, one patch, 800 x 600
  ASSERT_EQ(s.elements.size(), 1u);
  ASSERT_EQ(s.elements[0].patches_u * s.elements[0].patches_v, 1);
  const double frame_seen = 800.0 * 600.0 * (16 + 32 + 4), frame_colour = 800.0 * 600.0 * (8 + 4);
  const MapSizeSettings seen{1024, true, 512, 512}, colour{1024, false, 512, 512};
  const double n2 = 1024.0 * 1024.0;
  EXPECT_DOUBLE_EQ(mapMemoryBytes(s, RenderMode::Raster, seen), frame_seen);
  EXPECT_DOUBLE_EQ(mapMemoryBytes(s, RenderMode::Pvrr, seen), frame_seen + n2 * (16 + 16 + 4));
  EXPECT_DOUBLE_EQ(mapMemoryBytes(s, RenderMode::Pvrr, colour), frame_colour + n2 * (16 + 4));
  EXPECT_DOUBLE_EQ(mapMemoryBytes(s, RenderMode::Envmap, colour), frame_colour + 6 * n2 * 8 + 4 * n2);
  // Impostor cube maps hold each direction's distance even in a colour-only frame.
  EXPECT_DOUBLE_EQ(mapMemoryBytes(s, RenderMode::Impostor, colour), frame_colour + 6 * n2 * (8 + 16) + 4 * n2);
}

TEST(MapLimits, ShippedScenesFitTheReferenceLimits) {
  for (const char* name : {"plane-mirror", "car-mirror", "mirror-pair", "spectacle-lens", "progressive-lens"}) {
    const Scene s = test::shippedScene(name);
    for (RenderMode mode : {RenderMode::Pvrr, RenderMode::Raster, RenderMode::Envmap, RenderMode::Impostor})
      EXPECT_EQ(refusal(s, mode, {s.render.map_size, true, 512, 512}, roomyLimits()), "") << name;
  }
}

TEST(MapLimits, MapAboveTheTextureLimitIsRefusedNamingSceneAndSetting) {
  const Scene s = test::shippedScene("plane-mirror");
  GlLimits g = roomyLimits();
  g.max_texture_size = 2048;
  const std::string e = refusal(s, RenderMode::Pvrr, {4096, true, 512, 512}, g);
  EXPECT_NE(e.find("plane-mirror.json: render.map_size 4096: "), std::string::npos) << e;
  EXPECT_NE(e.find("GL_MAX_TEXTURE_SIZE 2048"), std::string::npos) << e;
  EXPECT_NE(e.find("the largest render.map_size that fits is 2048"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  EXPECT_EQ(refusal(s, RenderMode::Pvrr, {2048, true, 512, 512}, g), "");
}

TEST(MapLimits, CubeAboveTheCubeLimitIsRefusedInCubeModesOnly) {
  const Scene s = test::shippedScene("plane-mirror");
  GlLimits g = roomyLimits();
  g.max_cube_map_size = 1000;
  for (RenderMode mode : {RenderMode::Envmap, RenderMode::Impostor}) {
    const std::string e = refusal(s, mode, {1024, true, 512, 512}, g);
    EXPECT_NE(e.find("render.map_size 1024: a cube face of 1024 x 1024 texels exceeds this GL's "
                     "GL_MAX_CUBE_MAP_TEXTURE_SIZE 1000; the largest render.map_size that fits is 1000"),
              std::string::npos)
        << e;
  }
  EXPECT_EQ(refusal(s, RenderMode::Pvrr, {1024, true, 512, 512}, g), "");  // 2D maps: not bound by it
  g.max_renderbuffer_size = 512;  // the cube's depth buffer, the pvrr map's depth texture target
  const Scene small = test::shippedScene("plane-mirror", {"observer.image_size=[320, 240]"});
  EXPECT_NE(refusal(small, RenderMode::Envmap, {800, true, 512, 512}, g).find("GL_MAX_RENDERBUFFER_SIZE 512"),
            std::string::npos);
  EXPECT_NE(refusal(small, RenderMode::Pvrr, {1024, true, 512, 512}, g).find("GL_MAX_RENDERBUFFER_SIZE 512"),
            std::string::npos);
}

TEST(MapLimits, MemoryBeyondTheBudgetIsRefusedWithTheLargestSizeThatFits) {
  const Scene s = test::shippedScene("plane-mirror");
  GlLimits g = roomyLimits();
  const MapSizeSettings asked{4096, true, 512, 512};
  g.memory_bytes = 0.5 * mapMemoryBytes(s, RenderMode::Pvrr, asked);
  g.memory_source = "a test budget";
  const std::string e = refusal(s, RenderMode::Pvrr, asked, g);
  EXPECT_NE(e.find("render.map_size 4096: pvrr mode needs at least "), std::string::npos) << e;
  EXPECT_NE(e.find("(a test budget)"), std::string::npos) << e;
  const size_t at = e.find("fits is ");
  ASSERT_NE(at, std::string::npos) << e;
  const int best = std::stoi(e.substr(at + 8));
  // The advice is exact: that size fits the budget and the next does not.
  EXPECT_LE(mapMemoryBytes(s, RenderMode::Pvrr, {best, true, 512, 512}), g.memory_bytes);
  EXPECT_GT(mapMemoryBytes(s, RenderMode::Pvrr, {best + 1, true, 512, 512}), g.memory_bytes);
  EXPECT_EQ(refusal(s, RenderMode::Pvrr, {best, true, 512, 512}, g), "");
  // Raster mode has no maps: only its frame targets count.
  EXPECT_EQ(refusal(s, RenderMode::Raster, asked, g), "");
}

TEST(MapLimits, FrameTargetsAloneBeyondTheLimitsNameTheImageSize) {
  const Scene s = test::shippedScene("plane-mirror");
  GlLimits g = roomyLimits();
  g.max_renderbuffer_size = 700;  // the 800 x 600 image's depth target
  EXPECT_NE(refusal(s, RenderMode::Raster, {1024, true, 512, 512}, g)
                .find("plane-mirror.json: observer.image_size 800 x 600: "),
            std::string::npos);
  g = roomyLimits();
  g.memory_bytes = 1e6;  // less than the frame's own targets: no map size helps
  EXPECT_NE(refusal(s, RenderMode::Pvrr, {1024, true, 512, 512}, g)
                .find("no render.map_size fits (lower observer.image_size)"),
            std::string::npos);
  EXPECT_NE(refusal(s, RenderMode::Raster, {1024, true, 512, 512}, g)
                .find("observer.image_size 800 x 600: the frame's targets need"),
            std::string::npos);
}

TEST(MapLimits, ImpostorDataMapsAgainstTheTextureLimit) {
  GlLimits g = roomyLimits();
  g.max_texture_size = 1024;
  const Scene lens = test::shippedScene("spectacle-lens", {"observer.image_size=[320, 240]"});
  const std::string e = refusal(lens, RenderMode::Impostor, {256, true, 2048, 2048}, g);
  EXPECT_NE(e.find("impostor mode's lens height maps of 2048 texels exceed this GL's GL_MAX_TEXTURE_SIZE 1024"),
            std::string::npos)
      << e;
  EXPECT_EQ(refusal(lens, RenderMode::Pvrr, {256, true, 2048, 2048}, g), "");  // built in impostor mode only
  const Scene mirror = test::shippedScene("plane-mirror", {"observer.image_size=[320, 240]"});
  EXPECT_NE(refusal(mirror, RenderMode::Impostor, {256, true, 2048, 2048}, g).find("mirror surface maps of 2048"),
            std::string::npos);
  EXPECT_EQ(refusal(mirror, RenderMode::Impostor, {256, true, 2048, 1024}, g), "");  // no lens: no height maps
}

// The renderer checks once per change of what checkMapLimits reads (mapLimitsKey): every input of the check
// changes the key, and nothing else does.
TEST(MapLimits, TheKeyChangesWithEveryInputOfTheCheck) {
  const GlLimits g = roomyLimits();
  const MapSizeSettings base{1024, true, 512, 512};
  Scene s = test::shippedScene("plane-mirror");
  const std::vector<double> k = mapLimitsKey(s, RenderMode::Pvrr, base, g);
  EXPECT_EQ(mapLimitsKey(s, RenderMode::Pvrr, base, g), k);
  s.observer.eye += Vec3(0.1, 0, 0);  // the eye is no input
  EXPECT_EQ(mapLimitsKey(s, RenderMode::Pvrr, base, g), k);
  EXPECT_NE(mapLimitsKey(s, RenderMode::Impostor, base, g), k);
  for (MapSizeSettings m : {MapSizeSettings{2048, true, 512, 512}, MapSizeSettings{1024, false, 512, 512},
                            MapSizeSettings{1024, true, 1024, 512}, MapSizeSettings{1024, true, 512, 1024}})
    EXPECT_NE(mapLimitsKey(s, RenderMode::Pvrr, m, g), k);
  GlLimits smaller = g;
  smaller.memory_bytes /= 2;
  EXPECT_NE(mapLimitsKey(s, RenderMode::Pvrr, base, smaller), k);
  Scene wider = s;
  wider.observer.width = 1024;
  EXPECT_NE(mapLimitsKey(wider, RenderMode::Pvrr, base, g), k);
  Scene split = s;
  split.elements[0].patches_u = 2;
  EXPECT_NE(mapLimitsKey(split, RenderMode::Pvrr, base, g), k);
}

}  // namespace
}  // namespace pvrr
