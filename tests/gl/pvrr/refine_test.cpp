// Per-fragment refinement of pvrr mode (render.refine; shaders/pvrr_refine.glsl): each mirror fragment's exact
// reflected ray, and each lens fragment's exact exit rays, searched in its map. Against the reference tracer: a
// convex mirror and a saddle (whose interpolated coordinates err most between vertices), one patch and 2 x 2
// patches, the shipped mirrors and lenses; off and skipped elements draw exactly the unrefined pixels; every
// refined element's fragment is counted once, refined or fallen back, in its own frame's note. OSMesa and EGL.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <iostream>
#include <regex>
#include <string>
#include <vector>

#include "pvrr/analysis/accuracy.h"
#include "pvrr/base/error.h"
#include "pvrr/gl/renderer.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/trace/tracer.h"
#include "support/gl_backends.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// The refined median must be at most this: the impostor mode, which reflects each fragment's exact ray too,
// measures 0.0005' to 0.003' on such mirrors (grazing_test.cpp); refined: 0.008' to 0.03', unrefined 3' to 7'. A search
// that converged onto the wrong surface, or a normal from the wrong parameters, is arcminutes off.
constexpr double kRefinedMedianArcmin = 0.05;
// And its p95 at most this (the depth edges of the room's box are where the interpolation fails; the
// refined search lands on one side of them or falls back; measured 0.02' to 0.06'); unrefined: 13' to 30'.
constexpr double kRefinedP95Arcmin = 1.0;

// Lenses (ShippedLensesMatchTheReference, 160 x 120): the refined median at most this fraction of the unrefined
// one (measured 0.0003 to 0.013: 0.00022' against 0.67' on the spectacle lens, 0.00032' against 0.026' on the
// reading lens), and at most kLensMedianArcmin: the impostor mode, whose exit rays come from the same height
// maps, measures 0.0003' to 0.003' on these lenses; refined 0.0002' to 0.0006'. An exit ray from the wrong
// index or a search on the wrong surface is arcminutes off.
constexpr double kLensMedianRatio = 0.1;
constexpr double kLensMedianArcmin = 0.01;

// The shipped car mirror at 160 x 120 (its map scaled to the image: map_texels_per_pixel), refined median at
// most this; unrefined 0.77'.
constexpr double kSmallMapMedianArcmin = 0.15;

ErrorStats errorStats(const Frame& ref, const Frame& f) {
  const std::vector<double> e = angularErrors(ref, ref.seen, f.seen);
  return summarizeErrors(e);
}

// The second pass's refinement note ("refine (N steps): D fragments drawn, F kept ..., M kept it ...").
std::string refineNote(const Frame& f) {
  for (const StageTiming& s : f.stages.stages)
    if (s.note.find("refine (") != std::string::npos) return s.note.substr(s.note.find("refine ("));
  return "";
}

// The counts of the note: drawn, failed (search off the map's surface), missed (view ray off the surface).
std::array<long, 3> refineCounts(const std::string& note) {
  std::smatch m;
  const std::regex re(R"((\d+) fragments drawn, (\d+) kept the interpolated coordinate.*?, (\d+) kept it)");
  if (!std::regex_search(note, m, re)) return {-1, -1, -1};
  return {std::stol(m[1]), std::stol(m[2]), std::stol(m[3])};
}

// The quadratic split's note: of T mirror triangles, W searched whole and S split (their parts drawn by the
// quadratic program or searched), the area searched in the split ones (in triangles); the others drawn whole by
// the quadratic program.
struct SplitCounts {
  long triangles = -1, searched_whole = -1, split = -1;
  double searched_area = -1;  // of the split triangles' parts
};
SplitCounts splitCounts(const std::string& note) {
  std::smatch m;
  const std::regex re(R"(of (\d+) mirror triangles (\d+) searched whole and (\d+) split in four \(parts searched: ([0-9.]+))");
  if (!std::regex_search(note, m, re)) return {};
  return {std::stol(m[1]), std::stol(m[2]), std::stol(m[3]), std::stod(m[4])};
}

// One scene rendered unrefined, refined with `steps` and unrefined again, with the first two against the reference
// tracer (their figures printed under `name`).
struct RefineRun {
  gl::RasterFrame plain, refined, off_again;
  ErrorStats unrefined_error, refined_error;
  std::string note;  // the refined frame's (refineNote)
};
RefineRun runRefined(Scene& s, int steps, const std::string& name) {
  RayScene rays(s);
  const Frame ref = Tracer(rays, TraceOptions{}).render();
  gl::Renderer r(s, rays, gl::RendererOptions{});
  RefineRun run;
  s.render.refine = 0;
  run.plain = r.render(RenderMode::Pvrr);
  s.render.refine = steps;
  run.refined = r.render(RenderMode::Pvrr);
  s.render.refine = 0;
  run.off_again = r.render(RenderMode::Pvrr);
  run.unrefined_error = errorStats(ref, run.plain);
  run.refined_error = errorStats(ref, run.refined);
  run.note = refineNote(run.refined);
  const ErrorStats &a = run.unrefined_error, &b = run.refined_error;
  std::cout << "[ measured ] " << name << ": unrefined median " << a.median_arcmin << "' p95 " << a.p95_arcmin
            << "', refined median " << b.median_arcmin << "' p95 " << b.p95_arcmin << "' (" << b.pixels << " px); "
            << run.note << "\n";
  return run;
}

// Every fragment of the refined element (index 0, drawn once) counted in the note, and fewer than a tenth kept
// the interpolated coordinate; returns the note's counts (refineCounts).
std::array<long, 3> expectFragmentsCounted(const gl::RasterFrame& refined, const std::string& note) {
  const std::array<long, 3> n = refineCounts(note);
  EXPECT_GE(n[0], 0) << note;
  const size_t element_px = size_t(std::count(refined.element.begin(), refined.element.end(), 0));
  EXPECT_EQ(size_t(n[0]), element_px) << note;
  EXPECT_LT(n[1] + n[2], n[0] / 10) << note;
  return n;
}

Scene mirrorScene(cad::SagSurfacePtr surface, int patches, int tess = 9) {
  const Vec3 eye(0.0, 0.3, 2.0), centre(0.0, 0.0, 0.0);
  Scene s = test::roomScene(eye, centre, 200, 150);
  s.observer.fov_y_rad = radians(25);
  const cad::Outline outline = cad::Outline::rectangle(0.5, 0.4, 0.04);
  // Turned 25 deg about the vertical axis: the reflection shows the room's box and its depth edges.
  const Vec3 normal = glm::normalize(Vec3(std::sin(radians(25.0)), 0.1, std::cos(radians(25.0))));
  test::addMirror(s, surface, outline, test::pose(centre, normal), tess, 0.9);
  // A box on the mirror's central reflected ray, 2 m away, against the wall 1.5 m behind it: depth edges in
  // the reflection, where searches must fall back.
  EnvMesh box = makeBoxMesh(Vec3(1.5, 0.05, 1.3), Vec3(0.3, 0.3, 0.3), Mat3(1.0));
  box.material = 2;
  s.meshes.push_back(box);
  s.elements[0].patches_u = s.elements[0].patches_v = patches;
  s.updateBounds();
  return s;
}

class RefineTest : public ::testing::TestWithParam<gl::GlBackend> {};

// Refined against the reference: a convex mirror and a saddle, one patch and 2 x 2, each far closer than the
// unrefined frame, and each refined fragment counted.
TEST_P(RefineTest, MirrorsAndPatchesMatchTheReference) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const cad::Outline outline = cad::Outline::rectangle(0.5, 0.4, 0.04);
  struct Case {
    const char* name;
    cad::SagSurfacePtr surface;
    int patches;
    int tess = 9;
  };
  // 9 x 9: nearly every triangle's quadratic interpolant misses the exact ray by more than the split's tolerance
  // (measured 121 to 125 of 128), so nearly all are split in four, and a part of those searches (measured 10 to
  // 25 triangles' area of 128); 17 x 17: most are drawn whole by the quadratic program (measured 67 of 512
  // split, their parts searched 22.75 triangles' area; pvrr_refine.cpp).
  const Case cases[] = {{"convex", cad::makeSphere(1.2, outline), 1},
                        {"convex 2x2 patches", cad::makeSphere(1.2, outline), 2},
                        {"saddle 2x2 patches", cad::makeToric(1.5, -1.5, 0.0, outline), 2},
                        {"convex 17x17", cad::makeSphere(1.2, outline), 1, 17}};
  for (const Case& c : cases) {
    Scene s = mirrorScene(c.surface, c.patches, c.tess);
    const RefineRun run = runRefined(s, 4, c.name);
    const ErrorStats &a = run.unrefined_error, &b = run.refined_error;
    const std::string& note = run.note;
    const gl::RasterFrame& refined = run.refined;
    ASSERT_GT(b.pixels, 2000u) << c.name;
    EXPECT_LE(b.median_arcmin, kRefinedMedianArcmin) << c.name;
    EXPECT_LE(b.p95_arcmin, kRefinedP95Arcmin) << c.name;
    EXPECT_LT(b.median_arcmin, a.median_arcmin / 10) << c.name;
    // The fragments drawn are the mirror's pixels (one mirror, no overdraw); few fall back, and the box's depth
    // edges make some.
    const std::array<long, 3> n = expectFragmentsCounted(refined, note);
    EXPECT_GT(n[1], 0) << note;
    // The quadratic split: the triangles across the box's depth edges searched, on the finer grid the smooth
    // rest drawn by the quadratic program; off again draws the unrefined pixels.
    const SplitCounts split = splitCounts(note);
    ASSERT_GT(split.triangles, 0) << note;
    EXPECT_GT(split.searched_area, 0.0) << note;
    EXPECT_LT(split.searched_area, double(split.split)) << note;  // splitting leaves parts to the quadratic program
    if (c.tess > 9)
      EXPECT_LT(split.split + split.searched_whole, split.triangles / 2) << note;
    else
      EXPECT_GE(split.split + split.searched_whole, split.triangles * 9 / 10) << note;
    EXPECT_EQ(run.off_again.color, run.plain.color) << c.name;
  }
}

// The counts are read once the frame has finished (not while its draws wait), yet each frame's note holds that
// frame's own counts: zeroed before its draws, neither accumulated over frames nor a frame late. Three frames,
// the second with a narrower field of view (the mirror covers more pixels), each note against its own frame.
TEST_P(RefineTest, CountsAreEachFramesOwn) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const cad::Outline outline = cad::Outline::rectangle(0.5, 0.4, 0.04);
  Scene s = mirrorScene(cad::makeSphere(1.2, outline), 1);
  s.render.refine = 2;
  RayScene rays(s);
  gl::Renderer r(s, rays, gl::RendererOptions{});
  std::vector<std::string> notes;
  std::vector<size_t> pixels;
  for (const double fov_deg : {25.0, 20.0, 25.0}) {
    s.observer.fov_y_rad = radians(fov_deg);
    const gl::RasterFrame f = r.render(RenderMode::Pvrr);
    notes.push_back(refineNote(f));
    pixels.push_back(size_t(std::count(f.element.begin(), f.element.end(), 0)));
    const std::array<long, 3> n = refineCounts(notes.back());
    ASSERT_GE(n[0], 0) << notes.back();
    EXPECT_EQ(size_t(n[0]), pixels.back()) << fov_deg << " deg: " << notes.back();
  }
  EXPECT_GT(pixels[1], pixels[0] + 1000);
  EXPECT_EQ(notes[2], notes[0]);
}

// A frame that draws what the last counted frame drew (nothing moved, the same maps and camera) is drawn without
// the counters (their shader variant is slower on llvmpipe) and repeats that frame's counts: the same picture
// and the same note as a frame that counts, until something moves.
TEST_P(RefineTest, SteadyFramesRepeatTheCountedFramesCounts) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const cad::Outline outline = cad::Outline::rectangle(0.5, 0.4, 0.04);
  Scene s = mirrorScene(cad::makeSphere(1.2, outline), 1);
  s.render.refine = 2;
  RayScene rays(s);
  gl::Renderer r(s, rays, gl::RendererOptions{});
  gl::FrameCache cache;
  const Vec3 eye0 = s.observer.eye;
  std::vector<gl::RasterFrame> frames;
  std::vector<std::string> notes;
  // Stands alone, settles (the nodes now cached: counted again), steady twice, moved 1 cm (counted).
  for (const double dx : {0.0, 0.0, 0.0, 0.0, 0.01}) {
    s.observer.eye = eye0 + Vec3(dx, 0.0, 0.0);
    cache.environment_changed = false;
    frames.push_back(r.render(RenderMode::Pvrr, &cache));
    notes.push_back(refineNote(frames.back()));
    const std::array<long, 3> n = refineCounts(notes.back());
    ASSERT_GE(n[0], 0) << notes.back();
    EXPECT_EQ(size_t(n[0]), size_t(std::count(frames.back().element.begin(), frames.back().element.end(), 0)))
        << notes.back();
  }
  for (size_t i = 2; i < 4; ++i) {
    EXPECT_EQ(notes[i], notes[1]);
    EXPECT_TRUE(frames[i].color == frames[1].color) << "frame " << i << " differs from the counted frame";
  }
  EXPECT_NE(notes[4], notes[1]);
}

// The quadratic split's parts wait for the view to settle: a frame that stands alone (the first of its cache)
// splits its failing triangles, a frame that moved since the cached one searches them whole (their parts'
// nodes are not computed while the view moves), and the next frame in which nothing moved splits them again.
TEST_P(RefineTest, SplitsOnceTheViewSettles) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const cad::Outline outline = cad::Outline::rectangle(0.5, 0.4, 0.04);
  Scene s = mirrorScene(cad::makeSphere(1.2, outline), 1);
  s.render.refine = 2;
  RayScene rays(s);
  gl::Renderer r(s, rays, gl::RendererOptions{});
  gl::FrameCache cache;
  const Vec3 eye0 = s.observer.eye;
  std::vector<SplitCounts> counts;
  std::vector<std::string> notes;
  for (const double dx : {0.0, 0.01, 0.01}) {  // the first pose, moved 1 cm, the same again
    s.observer.eye = eye0 + Vec3(dx, 0.0, 0.0);
    cache.environment_changed = false;
    notes.push_back(refineNote(r.render(RenderMode::Pvrr, &cache)));
    counts.push_back(splitCounts(notes.back()));
    ASSERT_GT(counts.back().triangles, 0) << notes.back();
  }
  EXPECT_GT(counts[0].split, 0) << notes[0];
  EXPECT_EQ(counts[1].split, 0) << notes[1];
  EXPECT_GT(counts[1].searched_whole, 0) << notes[1];
  EXPECT_GT(counts[2].split, 0) << notes[2];
  EXPECT_EQ(counts[2].searched_whole, 0) << notes[2];
  EXPECT_LT(counts[2].searched_area, double(counts[2].split)) << notes[2];
  // The same pose drawn split (the failing parts' triangles whole, behind the quadratic parts) and whole: the
  // mirror's fragments counted alike, so the triangles drawn behind add none over the quadratic parts (they
  // would add about the split triangles' area less the searched area) and hide none of their own. kDrawnTol:
  // pixels on the parts' edges, whose midpoint corners are rounded to float.
  constexpr double kDrawnTol = 0.002;
  auto drawn = [](const std::string& note) {
    std::smatch m;
    return std::regex_search(note, m, std::regex(R"((\d+) fragments drawn)")) ? std::stod(m[1]) : -1.0;
  };
  ASSERT_GT(drawn(notes[1]), 0) << notes[1];
  EXPECT_NEAR(drawn(notes[2]), drawn(notes[1]), kDrawnTol * drawn(notes[1])) << notes[1] << "\n" << notes[2];
}

// Off draws the unrefined pixels (the default, the paper's method), and so does refinement of an element it
// skips: a plane mirror, whose interpolation is exact already, named with the reason in the note.
TEST_P(RefineTest, OffAndSkippedElementsDrawTheUnrefinedPixels) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  const cad::Outline outline = cad::Outline::rectangle(0.5, 0.4, 0.04);
  Scene s = mirrorScene(cad::makeSphere(1.2, outline), 1);
  EXPECT_EQ(s.render.refine, 0);  // the format's default
  RayScene rays(s);
  gl::Renderer r(s, rays, gl::RendererOptions{});
  const gl::RasterFrame off = r.render(RenderMode::Pvrr);
  EXPECT_EQ(refineNote(off), "");
  s.render.refine = 4;
  EXPECT_NE(r.render(RenderMode::Pvrr).color, off.color);  // the knob reaches the renderer
  s.render.refine = 0;
  EXPECT_EQ(r.render(RenderMode::Pvrr).color, off.color);

  Scene p = mirrorScene(cad::makePlane(outline), 1);
  RayScene prays(p);
  gl::Renderer pr(p, prays, gl::RendererOptions{});
  const gl::RasterFrame plane_off = pr.render(RenderMode::Pvrr);
  p.render.refine = 4;
  const gl::RasterFrame plane_on = pr.render(RenderMode::Pvrr);
  EXPECT_EQ(plane_on.color, plane_off.color);
  EXPECT_EQ(plane_on.seen, plane_off.seen);
  const std::string note = refineNote(plane_on);
  EXPECT_NE(note.find("not refined: mirror0 (the vertex fit is exact"), std::string::npos) << note;
}

// The knob from a scene file (render.refine, through --set as `pvrr render` takes it), on the shipped car
// mirror (a NURBS from STEP), the mirror pair (the convex mirror seen in a plane one: nested maps; the plane
// mirror skipped) and the concave shaving mirror (zooming-region maps, reversed depth): refined against the
// reference, far below the unrefined frame.
TEST_P(RefineTest, ShippedMirrorsFromTheirFiles) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  for (const std::string name : {"car-mirror", "mirror-pair", "concave-mirror"}) {
    const std::string path = std::string(PVRR_SOURCE_DIR) + "/models/" + name + ".json";
    const SceneDesc desc = loadScene(path, {"observer.image_size=[160,120]", "render.refine=2"});
    ASSERT_EQ(desc.render.refine, 2);
    Scene s = buildScene(desc);
    const RefineRun run = runRefined(s, desc.render.refine, name + " 160x120");
    const ErrorStats &a = run.unrefined_error, &b = run.refined_error;
    const std::string& note = run.note;
    EXPECT_LE(b.median_arcmin, a.median_arcmin / 5) << name;
    EXPECT_LE(b.p95_arcmin, a.p95_arcmin) << name;
    if (name == "concave-mirror") {
      // The shaving mirror seen from inside its focal length: all of it is the zooming region, whose reversed
      // maps are searched backward along their axis (640 x 480: 0.134' / 0.53' unrefined, 0.0004' / 0.0012'
      // refined). Every fragment refined: none left for another reason.
      EXPECT_EQ(note.find("not refined"), std::string::npos) << note;
      EXPECT_LE(b.median_arcmin, kRefinedMedianArcmin);
    } else if (name == "car-mirror") {
      // At 160 x 120 the map has ~6 times fewer texels across than at 640 x 480 (0.0107' there): measured
      // 0.077' / 0.72' (the failing triangles searched whole: 0.078' / 0.98'; all triangles searched: 0.073' /
      // 0.61'; the quadratic split's tolerance, pvrr_refine.cpp).
      EXPECT_LE(b.median_arcmin, kSmallMapMedianArcmin);
      EXPECT_LE(b.p95_arcmin, kRefinedP95Arcmin);
    } else {
      EXPECT_NE(note.find("not refined: back-wall-mirror (the vertex fit is exact"), std::string::npos) << note;
    }
  }
}

// Lenses refine each channel's exact exit ray (front and back refraction in the lens's refractor height maps),
// searched in the lens's map: the spectacle lens (one channel, the whole picture), the reading lens (RGB
// dispersion: three exit rays a fragment, the seen point the d line's), the progressive lens (a NURBS back
// surface), the burning lens (RGB, 5 x 5 patches with 130-150 deg maps, some drawn traced) and the spectacle
// lens with an aspheric front and a rectangular outline (the entry found in the height map, the outline in
// its mask, rather than in closed form) at 160 x 120,
// against the reference: at least as close as unrefined in median and p95 and far closer in median; each lens
// fragment counted once, refined or fallen back; off draws the unrefined pixels.
TEST_P(RefineTest, ShippedLensesMatchTheReference) {
  const auto ctx = test::glContextOrFail(GetParam());
  if (!ctx) return;
  struct Case {
    const char* name;
    const char* file;
    std::vector<std::string> set;
  };
  // The shipped lenses' fronts are spheres (met in closed form) and their outlines ellipses or circles (tested in
  // closed form); the variant's aspheric front is met in its height map (as the progressive lens's NURBS back)
  // and its rounded rectangle tested in the outline mask.
  const Case cases[] = {{"spectacle-lens", "spectacle-lens", {}},
                        {"reading-lens", "reading-lens", {}},
                        {"progressive-lens", "progressive-lens", {}},
                        {"burning-lens", "burning-lens", {}},
                        {"spectacle-lens, aspheric front, rectangle", "spectacle-lens",
                         {"elements[0].front.type=\"asphere\"", "elements[0].front.conic=-0.5",
                          "elements[0].outline={\"shape\": \"rectangle\", \"width\": 0.05, \"height\": 0.04, "
                          "\"corner_radius\": 0.008}"}}};
  for (const Case& c : cases) {
    const std::string name = c.name;
    const std::string path = std::string(PVRR_SOURCE_DIR) + "/models/" + c.file + ".json";
    std::vector<std::string> set = c.set;
    set.push_back("observer.image_size=[160,120]");
    Scene s = buildScene(loadScene(path, set));
    const RefineRun run = runRefined(s, 2, name + " 160x120");
    EXPECT_EQ(run.off_again.color, run.plain.color) << name;
    EXPECT_EQ(run.off_again.seen, run.plain.seen) << name;
    const ErrorStats &a = run.unrefined_error, &b = run.refined_error;
    const std::string& note = run.note;
    const gl::RasterFrame& refined = run.refined;
    ASSERT_GT(b.pixels, 500u) << name;
    EXPECT_LE(b.median_arcmin, a.median_arcmin * kLensMedianRatio) << name;
    EXPECT_LE(b.median_arcmin, kLensMedianArcmin) << name;
    EXPECT_LE(b.p95_arcmin, a.p95_arcmin) << name;
    EXPECT_EQ(note.find("not refined"), std::string::npos) << note;
    EXPECT_NE(note.find("totally reflected inside"), std::string::npos) << note;
    expectFragmentsCounted(refined, note);
  }
}

// render.refine: "off" or a step count in [1, kMaxRefineSteps]; anything else is refused naming the path.
TEST(RefineKnob, ParsesOffOrAStepCount) {
  const std::string path = std::string(PVRR_SOURCE_DIR) + "/models/car-mirror.json";
  EXPECT_EQ(loadScene(path).render.refine, 0);  // the shipped scene leaves the default: off
  EXPECT_EQ(loadScene(path, {"render.refine=off"}).render.refine, 0);
  EXPECT_EQ(loadScene(path, {"render.refine=16"}).render.refine, 16);
  for (const std::string bad : {"render.refine=0", "render.refine=17", "render.refine=on", "render.refine=2.5"}) {
    try {
      loadScene(path, {bad});
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("render.refine: expected \"off\" or an integer in [1, 16]"), std::string::npos) << m;
    }
  }
}

PVRR_GL_BACKENDS(RefineTest);

}  // namespace
}  // namespace pvrr
