// Ambient occlusion in the raster modes (pvrr/gl/ao_fields.h, shaders/ambient_occlusion.glsl) against the
// reference's hemisphere sampling (pvrr/trace/ambient_occlusion.h), issue 24: on the ground around a box car
// lit by an ambient light only, the visibility each picture shows (colour / (albedo * ambient)) agrees
// within 0.05 mean absolute difference, directly (raster mode), seen in a plane mirror (pvrr mode, whose
// first pass shades the ground with the fields too), and with the car moved and turned by its animation.
// With render.ambient_occlusion off, the picture is the one without any occluder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "pvrr/gl/ao_fields.h"
#include "pvrr/gl/ao_vertex_receivers.h"
#include "pvrr/gl/context.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/trace/tracer.h"
#include "support/gl_backends.h"

namespace pvrr {
namespace {

class AmbientOcclusionTest : public ::testing::TestWithParam<gl::GlBackend> {};

// Issue 24's bound on the ground around a car: mean |A_raster - A_reference|.
constexpr double kGroundMad = 0.05;
constexpr double kGroundAlbedo = 0.7, kAmbient = 0.5, kMirrorReflectance = 0.9;
// The mean occlusion of the ground in the mirror against the reference's, relative: envmap and impostor cubes
// see the ground from the mirror's centre, not from each mirror point, so what a pixel shows moves (envmap
// measured 0.140 against 0.106, pvrr and impostor within 0.003).
constexpr double kModeOcclusionRel = 0.5;

// A car of six boxes (one occluder, "car") on a 30 m ground, an ambient light only. `animation`: the car's
// parts' "animation" member (or empty); `mirror`: an element array's contents; `ao`: render.ambient_occlusion;
// `extra`: more environment objects (each with a leading comma); `eye`: the observer's eye.
SceneDesc carDesc(const std::string& animation, const std::string& mirror, const std::string& ao,
                  const std::string& extra = "", const std::string& eye = "[4.5, 5.5, 6.5]") {
  std::string parts;
  const char* boxes[] = {R"("centre": [0, 0.75, 0], "size": [1.8, 0.8, 4.4])",
                         R"("centre": [0, 1.45, 0.3], "size": [1.6, 0.6, 2.4])",
                         R"("centre": [-0.8, 0.32, -1.4], "size": [0.22, 0.64, 0.64])",
                         R"("centre": [0.8, 0.32, -1.4], "size": [0.22, 0.64, 0.64])",
                         R"("centre": [-0.8, 0.32, 1.4], "size": [0.22, 0.64, 0.64])",
                         R"("centre": [0.8, 0.32, 1.4], "size": [0.22, 0.64, 0.64])"};
  for (const char* b : boxes)
    parts += std::string(R"(, {"type": "box", "ambient_occlusion": "car", "material": {"color": [0.6, 0.1, 0.1]}, )") + b +
             (animation.empty() ? "" : ", \"animation\": " + animation) + "}";
  const std::string text = R"({"version": 1, "units": "m",
    "observer": {"eye": )" + eye + R"(, "target": [0, 0.3, 0], "fov_y_deg": 55, "image_size": [200, 150]},
    "environment": [{"type": "ground", "name": "road", "point": [0, 0, 0], "normal": [0, 1, 0], "size": [30, 30],
                     "material": {"color": [0.7, 0.7, 0.7]}})" + parts + extra + R"(],
    "lights": [{"type": "ambient", "color": [0.5, 0.5, 0.5]}],
    "elements": [)" + mirror + R"(],
    "render": {"background": [0, 0, 0], "ambient_occlusion": )" + ao + "}}";
  return parseScene(text, "ao-scene", "");
}

struct Difference {
  int pixels = 0;
  double mad = 0, darkest = 1;
};

// Over the pixels whose reference path ends on the ground after `bounces` reflections within 6 m of `car`.
Difference groundDifference(const Frame& ref, const gl::RasterFrame& raster, int bounces, double reflectance,
                            const Vec3& car) {
  Difference d;
  double sum = 0;
  const double unoccluded = reflectance * kGroundAlbedo * kAmbient;
  for (size_t i = 0; i < ref.seen.size(); ++i) {
    const Vec3 p = ref.seen[i];
    if (std::abs(p.y) > 1e-9 || ref.bounces[i] != bounces || glm::length(p - car) > 6) continue;
    if (bounces == 0 && ref.element[i] >= 0) continue;
    const double a_ref = ref.color[i].x / unoccluded, a_raster = raster.color[i].x / unoccluded;
    sum += std::abs(a_raster - a_ref);
    d.darkest = std::min(d.darkest, a_ref);
    ++d.pixels;
  }
  d.mad = d.pixels ? sum / d.pixels : 1;
  return d;
}

// Prints the comparison (`what`) and checks issue 24's bound on it: enough pixels, the occlusion in the picture
// (the reference's darkest visibility below `max_darkest`), the mean difference below kGroundMad.
void expectAgrees(const Difference& d, const char* what, int min_pixels, double max_darkest) {
  std::printf("[ ambient occlusion ] %s: %d pixels, mean |A - A_ref| %.4f, darkest %.3f\n", what, d.pixels, d.mad,
              d.darkest);
  EXPECT_GT(d.pixels, min_pixels) << what;
  EXPECT_LT(d.darkest, max_darkest) << what;
  EXPECT_LT(d.mad, kGroundMad) << what;
}

TEST_P(AmbientOcclusionTest, GroundAroundACarAgreesWithTheReference) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const Scene s = buildScene(carDesc("", "", "true"));
  RayScene rays(s);
  const Frame ref = Tracer(rays, TraceOptions{}).render();
  gl::Renderer renderer(s, rays, gl::RendererOptions{});
  const gl::RasterFrame raster = renderer.render(RenderMode::Raster);
  expectAgrees(groundDifference(ref, raster, 0, 1.0, Vec3(0)), "ground around a car", 5000, 0.4);
  const StageTiming* stage = raster.stages.find(gl::kAmbientOcclusionStage);
  ASSERT_TRUE(stage);
  EXPECT_TRUE(stage->ran) << stage->reason;
  EXPECT_EQ(stage->count, 1);
}

// The car moved by `animation` (its parts' "animation" member), at t = 1 s, rendered in raster mode: the ground
// within 6 m of `car` against the reference.
Difference movedCarDifference(const std::string& animation, const Vec3& car) {
  const SceneDesc desc = carDesc(animation, "", "true");
  Scene s = buildScene(desc);
  applyAnimation(s, desc, 1.0);
  RayScene rays(s);
  const Frame ref = Tracer(rays, TraceOptions{}).render();
  gl::Renderer renderer(s, rays, gl::RendererOptions{});
  return groundDifference(ref, renderer.render(RenderMode::Raster), 0, 1.0, car);
}

TEST_P(AmbientOcclusionTest, TheFieldMovesWithTheCar) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  expectAgrees(movedCarDifference(R"({"keys": [{"time_s": 0}, {"time_s": 1, "offset": [1.5, 0, -1], "rotation_deg": [0, 40, 0]}]})",
                                  Vec3(1.5, 0, -1)),
               "moved car", 5000, 0.4);
}

// The static faces are drawn with vertex values (pvrr/gl/ao_vertex_receivers.h), kept from frame to frame: with
// the car moved between two frames of one renderer, the second frame's ground follows it (its grids made again)
// and agrees with the reference there.
TEST_P(AmbientOcclusionTest, TheVertexValuesFollowTheCarFromFrameToFrame) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const SceneDesc desc =
      carDesc(R"({"keys": [{"time_s": 0}, {"time_s": 1, "offset": [1.5, 0, -1], "rotation_deg": [0, 40, 0]}]})", "", "true");
  Scene s = buildScene(desc);
  applyAnimation(s, desc, 0.0);
  RayScene rays(s);
  gl::Renderer renderer(s, rays, gl::RendererOptions{});
  const Frame before_ref = Tracer(rays, TraceOptions{}).render();
  expectAgrees(groundDifference(before_ref, renderer.render(RenderMode::Raster), 0, 1.0, Vec3(0)),
               "vertex values, first frame", 5000, 0.4);
  renderer.render(RenderMode::Raster);  // the grids kept: nothing moved
  applyAnimation(s, desc, 1.0);
  RayScene moved_rays(s);
  const Frame after_ref = Tracer(moved_rays, TraceOptions{}).render();
  const gl::RasterFrame after = renderer.render(RenderMode::Raster);
  expectAgrees(groundDifference(after_ref, after, 0, 1.0, Vec3(1.5, 0, -1)), "vertex values, the car moved", 5000, 0.4);
  const StageTiming* stage = after.stages.find(gl::kAmbientOcclusionStage);
  ASSERT_TRUE(stage);
  EXPECT_NE(stage->note.find("vertex values (faces drawn so far) on"), std::string::npos) << stage->note;
}

// A car lifted off the ground (a jump): its ground maps no longer lie on the road's plane, so the road reads the
// occlusion volumes instead (pvrr/gl/ao_fields.h), and agrees all the same.
TEST_P(AmbientOcclusionTest, ALiftedCarsGroundReadsTheVolumes) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  expectAgrees(movedCarDifference(R"({"keys": [{"time_s": 0}, {"time_s": 1, "offset": [0.5, 0.4, 0], "rotation_deg": [0, 20, 0]}]})",
                                  Vec3(0.5, 0, 0)),
               "lifted car", 5000, 0.6);
}

// A plane mirror behind the car, turned so that the eye sees in it the ground behind the car; `ao`:
// render.ambient_occlusion.
SceneDesc mirrorDesc(const std::string& ao) {
  const Vec3 eye(4.5, 5.5, 6.5), m(-3, 1.5, -5), g(0, 0, -3);
  const Vec3 n = glm::normalize(glm::normalize(eye - m) + glm::normalize(g - m));
  char mirror[600];
  std::snprintf(mirror, sizeof mirror,
                R"({"name": "m", "type": "mirror", "pose": {"position": [%.6f, %.6f, %.6f], "normal": [%.6f, %.6f, %.6f],
                    "up": [0, 1, 0]}, "outline": {"shape": "rectangle", "width": 3.0, "height": 2.0},
                    "surface": {"type": "plane"}, "tessellation": 7, "material": {"reflectance": 0.9}})",
                m.x, m.y, m.z, n.x, n.y, n.z);
  return carDesc("", mirror, ao);
}

// The mean visibility the picture shows over the pixels whose reference path ends on the ground after one
// reflection within 6 m of the car.
double meanInMirror(const Frame& ref, const gl::RasterFrame& raster) {
  double sum = 0;
  int count = 0;
  for (size_t i = 0; i < ref.seen.size(); ++i) {
    const Vec3 p = ref.seen[i];
    if (std::abs(p.y) > 1e-9 || ref.bounces[i] != 1 || glm::length(p) > 6) continue;
    sum += raster.color[i].x / (kMirrorReflectance * kGroundAlbedo * kAmbient);
    ++count;
  }
  return count ? sum / count : 1;
}

// The first passes of every map-based mode (pvrr maps, envmap and impostor cubes) shade the ground with the
// fields: the ground seen in the mirror is darker with ambient occlusion on, by about what the reference shows.
TEST_P(AmbientOcclusionTest, EveryModesFirstPassesShadeIt) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const Scene on = buildScene(mirrorDesc("true")), off = buildScene(mirrorDesc("false"));
  RayScene rays_on(on), rays_off(off);
  const Frame ref = Tracer(rays_on, TraceOptions{}).render();
  double ref_sum = 0;
  int ref_count = 0;
  for (size_t i = 0; i < ref.seen.size(); ++i)
    if (std::abs(ref.seen[i].y) <= 1e-9 && ref.bounces[i] == 1 && glm::length(ref.seen[i]) <= 6) {
      ref_sum += ref.color[i].x / (kMirrorReflectance * kGroundAlbedo * kAmbient);
      ++ref_count;
    }
  ASSERT_GT(ref_count, 300);
  const double ref_occlusion = 1 - ref_sum / ref_count;
  gl::Renderer r_on(on, rays_on, gl::RendererOptions{}), r_off(off, rays_off, gl::RendererOptions{});
  for (const RenderMode mode : {RenderMode::Pvrr, RenderMode::Envmap, RenderMode::Impostor}) {
    const double occlusion = meanInMirror(ref, r_off.render(mode)) - meanInMirror(ref, r_on.render(mode));
    std::printf("[ ambient occlusion ] %s, in the mirror: mean occlusion %.4f, the reference's %.4f\n",
                nameOf(mode), occlusion, ref_occlusion);
    EXPECT_NEAR(occlusion, ref_occlusion, kModeOcclusionRel * ref_occlusion) << nameOf(mode);
  }
}

TEST_P(AmbientOcclusionTest, TheGroundInAMirrorAgreesInPvrrMode) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const Scene s = buildScene(mirrorDesc("true"));
  RayScene rays(s);
  const Frame ref = Tracer(rays, TraceOptions{}).render();
  gl::Renderer renderer(s, rays, gl::RendererOptions{});
  expectAgrees(groundDifference(ref, renderer.render(RenderMode::Pvrr), 1, kMirrorReflectance, Vec3(0)),
               "in the mirror (pvrr)", 300, 0.6);
}

// A wall beside the car, seen from either side: the face toward the car is darkened by it; the face turned away
// from it, whose hemisphere the car is not in, is drawn without ambient occlusion (AoFields::volumeBound): there
// the very pixels of the picture without.
TEST_P(AmbientOcclusionTest, AFaceTurnedAwayFromTheCarIsDrawnWithout) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const std::string wall =
      R"(, {"type": "box", "name": "wall", "centre": [3, 1, 0], "size": [0.2, 2, 6], "material": {"color": [0.7, 0.7, 0.7]}})";
  for (const double side : {-1.0, 1.0}) {  // the face at x = 3 + 0.1 side; -1: the one toward the car
    const std::string eye = side < 0 ? "[-3, 2, 8]" : "[9, 2, 8]";
    const Scene on = buildScene(carDesc("", "", "true", wall, eye)), off = buildScene(carDesc("", "", "false", wall, eye));
    RayScene rays_on(on), rays_off(off);
    gl::Renderer r_on(on, rays_on, gl::RendererOptions{}), r_off(off, rays_off, gl::RendererOptions{});
    const gl::RasterFrame a = r_on.render(RenderMode::Raster), b = r_off.render(RenderMode::Raster);
    int pixels = 0, equal = 0;
    double darkening = 0;
    for (size_t i = 0; i < b.seen.size(); ++i) {
      const Vec3 p = b.seen[i];
      if (std::abs(p.x - (3 + 0.1 * side)) > 1e-3 || std::abs(p.z) > 2.9 || p.y < 0.1 || p.y > 1.9) continue;
      ++pixels;
      equal += a.color[i] == b.color[i];
      darkening += (b.color[i].x - a.color[i].x) / (kGroundAlbedo * kAmbient);
    }
    std::printf("[ ambient occlusion ] wall face %s the car: %d pixels, mean occlusion %.4f, %d unchanged\n",
                side < 0 ? "toward" : "turned from", pixels, pixels ? darkening / pixels : 0.0, equal);
    ASSERT_GT(pixels, 1000);
    if (side < 0) {
      EXPECT_GT(darkening / pixels, 0.02);
    } else {
      EXPECT_EQ(equal, pixels);
    }
  }
}

// Issue 24's cost: a face of a culled box with the camera behind its plane gets no grid (it keeps its two
// triangles, culled whole), and the picture of the faces in view is the same as with every face drawn. The wall
// stands 2.9 m beside the car; from the car's side its far face (x = 3.1), seen from behind, is turned to the car
// by the two-sided shading and would have a grid.
TEST_P(AmbientOcclusionTest, AHiddenFaceOfACulledBoxGetsNoGrid) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const std::string wall =
      R"(, {"type": "box", "name": "wall", "centre": [3, 1, 0], "size": [0.2, 2, 6], "material": {"color": [0.7, 0.7, 0.7]}})";
  const Scene scene = buildScene(carDesc("", "", "true", wall, "[-3, 2.5, 8]"));
  RayScene rays(scene);
  gl::RendererOptions culling, every_face;
  every_face.cull_back_faces = false;
  gl::Renderer r_cull(scene, rays, culling), r_all(scene, rays, every_face);
  r_cull.render(RenderMode::Raster);  // the grids are made while the first frame draws: noted from the second
  r_all.render(RenderMode::Raster);
  const gl::RasterFrame a = r_cull.render(RenderMode::Raster), b = r_all.render(RenderMode::Raster);
  auto faces = [](const gl::RasterFrame& f) {
    const StageTiming* stage = f.stages.find(gl::kAmbientOcclusionStage);
    const size_t at = stage ? stage->note.find("vertex values (faces drawn so far) on ") : std::string::npos;
    return at == std::string::npos ? -1 : std::atoi(stage->note.c_str() + at + 38);
  };
  int pixels = 0, equal = 0;
  double darkening = 0;
  for (size_t i = 0; i < b.seen.size(); ++i) {
    const Vec3 p = b.seen[i];
    if (std::abs(p.x - 2.9) > 1e-3 || std::abs(p.z) > 2.9 || p.y < 0.1 || p.y > 1.9) continue;  // the face in view
    ++pixels;
    equal += a.color[i] == b.color[i];
    darkening += 1 - a.color[i].x / (kGroundAlbedo * kAmbient);
  }
  std::printf("[ ambient occlusion ] hidden faces: %d faces with grids culling (%d drawing every face); the face in "
              "view %d pixels, %d unchanged, mean occlusion %.4f\n", faces(a), faces(b), pixels, equal,
              pixels ? darkening / pixels : 0.0);
  ASSERT_GT(pixels, 1000);
  EXPECT_GT(darkening / pixels, 0.02);  // the face in view is occluded (it has a grid)
  EXPECT_EQ(equal, pixels);
  ASSERT_GT(faces(a), 0);
  EXPECT_LT(faces(a), faces(b));
}

// The mesh drawn in one draw (AoVertexReceivers::merged, issue 24's cost): its buffer holds each face's grid
// exactly as the face's own grid (the same vertices and occlusions, the indices offset), the faces drawn without
// occlusion with their own vertices and zeros on both sides, and it is made again with the grids when the car
// moves.
TEST_P(AmbientOcclusionTest, AMeshsMergedBufferHoldsItsFacesGridsAndZeros) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const std::string wall =
      R"(, {"type": "box", "name": "wall", "centre": [3, 1, 0], "size": [0.2, 2, 6], "material": {"color": [0.7, 0.7, 0.7]}})";
  const SceneDesc desc =
      carDesc(R"({"keys": [{"time_s": 0}, {"time_s": 1, "offset": [1.2, 0, -1], "rotation_deg": [0, 30, 0]}]})", "", "true", wall);
  Scene s = buildScene(desc);
  applyAnimation(s, desc, 0.0);
  const std::vector<AoField> fields = buildAoFields(s);
  ASSERT_FALSE(fields.empty());
  gl::AoVertexReceivers receivers(s, fields);
  size_t m = 0;
  while (m < s.meshes.size() && s.meshes[m].name != "wall") ++m;
  ASSERT_LT(m, s.meshes.size());
  const EnvMesh& mesh = s.meshes[m];
  // The box's faces: its triangles grouped by normal; the face toward the car and the top as grids.
  std::vector<std::vector<uint32_t>> triangles;
  std::vector<Vec3> normals;
  for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3 n(mesh.normals[mesh.triangles[t].x]);
    size_t g = 0;
    while (g < normals.size() && normals[g] != n) ++g;
    if (g == normals.size()) normals.push_back(n), triangles.emplace_back();
    triangles[g].push_back(t);
  }
  ASSERT_EQ(normals.size(), 6u);
  std::vector<gl::AoVertexReceivers::Face> faces;
  for (size_t g = 0; g < normals.size(); ++g) faces.push_back({&triangles[g], normals[g], normals[g].x < -0.5 || normals[g].y > 0.5});
  constexpr int kStride = gl::AoVertexReceivers::kAoStride;
  for (const double t : {0.0, 1.0}) {
    applyAnimation(s, desc, t);
    const gl::AoVertexReceivers::Merged* merged = receivers.merged(m, faces);
    ASSERT_TRUE(merged);
    EXPECT_EQ(merged->grids, 2);
    ASSERT_EQ(merged->face.size() * 3, merged->indices.size());
    EXPECT_EQ(merged->buffers.count, int(merged->indices.size()));
    // Each triangle is its face's own (grid or mesh triangle `source`), read through offset indices; the ones
    // without occlusion first.
    ASSERT_EQ(merged->source.size(), merged->face.size());
    std::vector<std::vector<int>> seen(faces.size());
    size_t grid_vertices = 0;
    for (size_t g = 0; g < faces.size(); ++g)
      if (faces[g].grid) grid_vertices += receivers.gridData(m, g)->size() / kStride;
    double toward_max = 0;
    int plain_most = 0;
    for (size_t t = 0; t < merged->face.size(); ++t) {
      const size_t g = size_t(merged->face[t]);
      const int src = merged->source[t];
      seen[g].push_back(src);
      float most = 0;
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = merged->indices[3 * t + size_t(k)];
        const float* d = &merged->data[size_t(v) * kStride];
        most = std::max({most, d[8], d[9]});
        if (!faces[g].grid) {
          EXPECT_EQ(v, mesh.triangles[triangles[g][size_t(src)]][k]);
          EXPECT_EQ(Vec3(d[0], d[1], d[2]), Vec3(mesh.positions[v]));
          EXPECT_EQ(d[8], 0.0f);  // drawn without occlusion, on both sides
          EXPECT_EQ(d[9], 0.0f);
          continue;
        }
        const std::vector<float>& data = *receivers.gridData(m, g);
        const uint32_t i = (*receivers.gridIndices(m, g))[3 * size_t(src) + size_t(k)];
        for (int c = 0; c < kStride; ++c) ASSERT_EQ(d[c], data[size_t(i) * kStride + size_t(c)]);
        if (normals[g].x < -0.5) toward_max = std::max(toward_max, double(d[8]));
      }
      // The plain triangles, drawn without the values, hold less than kAoValueNegligible; the others more.
      if (3 * t < size_t(merged->plain)) {
        EXPECT_LT(most, gl::kAoValueNegligible);
        ++plain_most;
      } else {
        EXPECT_GE(most, gl::kAoValueNegligible);
      }
    }
    for (size_t g = 0; g < faces.size(); ++g) {  // every triangle once
      std::sort(seen[g].begin(), seen[g].end());
      const size_t n = faces[g].grid ? receivers.gridIndices(m, g)->size() / 3 : triangles[g].size();
      ASSERT_EQ(seen[g].size(), n);
      for (size_t k = 0; k < n; ++k) EXPECT_EQ(seen[g][k], int(k));
    }
    EXPECT_GE(plain_most, 6);  // at least the three faces drawn without grids
    EXPECT_EQ(merged->data.size() / kStride, mesh.positions.size() + grid_vertices);
    std::printf("[ ambient occlusion ] merged wall at t = %.0f: %zu triangles (%d without the values), the face toward the car up to %.3f\n", t,
                merged->face.size(), plain_most, toward_max);
    EXPECT_GT(toward_max, 0.02);
  }
  // Made again for the car where it is now: its face toward the car is not the one of t = 0.
  applyAnimation(s, desc, 0.0);
  const std::vector<float> before = receivers.merged(m, faces)->data;
  applyAnimation(s, desc, 1.0);
  EXPECT_NE(receivers.merged(m, faces)->data, before);
}

TEST_P(AmbientOcclusionTest, OffChangesNoPixel) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const Scene off = buildScene(carDesc("", "", "false"));
  SceneDesc plain = carDesc("", "", "false");
  for (EnvObjectDesc& o : plain.environment) o.occluder.clear();
  const Scene none = buildScene(plain);
  RayScene rays_off(off), rays_none(none);
  gl::Renderer r_off(off, rays_off, gl::RendererOptions{}), r_none(none, rays_none, gl::RendererOptions{});
  const gl::RasterFrame a = r_off.render(RenderMode::Raster), b = r_none.render(RenderMode::Raster);
  EXPECT_EQ(a.color, b.color);
  const StageTiming* stage = a.stages.find(gl::kAmbientOcclusionStage);
  ASSERT_TRUE(stage);
  EXPECT_FALSE(stage->ran);
  EXPECT_NE(stage->reason.find("off"), std::string::npos);
}

PVRR_GL_BACKENDS(AmbientOcclusionTest);

}  // namespace
}  // namespace pvrr
