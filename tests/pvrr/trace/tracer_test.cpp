// The reference tracer against closed forms: it is the ground truth of every accuracy figure.
#include <gtest/gtest.h>

#include <array>
#include <filesystem>

#include <glm/gtc/matrix_transform.hpp>

#include "cad/lens.h"
#include "pvrr/optics/optics.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/trace/tracer.h"
#include "support/test_scenes.h"

namespace pvrr {
namespace {

// Exact-surface hits are Newton-refined in double: a few ulps of the coordinates (metres, |x| ~ 1).
constexpr double kExactHitTol = 1e-12;
// The bound for the laws of reflection and refraction along traced paths.
constexpr double kLawTol = 1e-9;

TEST(Tracer, PlaneMirrorMapsAPointToItsMirrorImage) {
  Scene s = test::roomScene(Vec3(0.3, 0.2, 2.0), Vec3(0, 0, 0));
  test::addMirror(s, cad::makePlane(cad::Outline::circle(2.0)), cad::Outline::circle(2.0), test::pose(Vec3(0), Vec3(0, 0, 1)));
  s.updateBounds();
  RayScene rays(s);
  Tracer tracer(rays, TraceOptions{});
  // Aim at the mirror image of a wall point seen in the z = 0 mirror: the path must end exactly on it.
  const Vec3 wall_point(1.2, -0.7, 3.0);  // on the z = +3 wall (behind the observer)
  const Vec3 image(wall_point.x, wall_point.y, -wall_point.z);
  const Vec3 eye = s.observer.eye;
  std::vector<PathSegment> path;
  TraceResult r = tracer.trace(eye, glm::normalize(image - eye), 0, &path);
  ASSERT_EQ(path.size(), 2u);
  EXPECT_EQ(path[0].event, "reflect");
  EXPECT_EQ(path[1].event, "diffuse");
  EXPECT_LT(glm::length(r.seen - wall_point), kExactHitTol * 10);
  EXPECT_EQ(r.first_element, 0);
  EXPECT_EQ(r.bounces, 1);
}

// A ray that is not finite (degenerate geometry upstream) meets nothing instead of reaching Embree, which
// asserts on it (an element posed with its up along its normal had NaN vertices and aborted the renderer).
TEST(Tracer, NonFiniteRaysMeetNothing) {
  Scene s = test::roomScene(Vec3(0.3, 0.2, 2.0), Vec3(0, 0, 0));
  const cad::Outline outline = cad::Outline::rectangle(0.6, 0.4);
  test::addMirror(s, cad::makePlane(outline), outline, test::pose(Vec3(0), Vec3(0, 0, 1)));
  s.updateBounds();
  RayScene rays(s);
  const double nan = std::nan("");
  EXPECT_TRUE(rays.intersect(Vec3(0, 0, 1), Vec3(0, 0, -1), 0).hit());  // the mirror, for contrast
  EXPECT_FALSE(rays.intersect(Vec3(nan, 0, 1), Vec3(0, 0, -1), 0).hit());
  EXPECT_FALSE(rays.intersect(Vec3(0, 0, 1), Vec3(0, nan, -1), 0).hit());
  EXPECT_FALSE(rays.intersectElementSurface(0, 0, Vec3(0, 0, 1), Vec3(nan, 0, -1), 0).hit());
}

TEST(Tracer, SphericalMirrorMatchesAnalyticReflection) {
  const double R = 1.2;  // convex, centre behind the mirror at z = -R
  Scene s = test::roomScene(Vec3(0.1, 0.05, 1.5), Vec3(0, 0, 0));
  const cad::Outline outline = cad::Outline::rectangle(0.4, 0.3, 0.05);
  test::addMirror(s, cad::makeSphere(R, outline), outline, test::pose(Vec3(0), Vec3(0, 0, 1)));
  s.updateBounds();
  RayScene rays(s);
  Tracer tracer(rays, TraceOptions{});
  const Vec3 centre(0, 0, -R);
  for (double x : {-0.15, 0.0, 0.12}) {
    for (double y : {-0.1, 0.03, 0.11}) {
      const Vec3 o = s.observer.eye;
      const Vec3 d = glm::normalize(Vec3(x, y, 0.0) - o);
      // Independent solution: nearest root of |o + t d - c|^2 = R^2; normal radial; mirror formula.
      const Vec3 oc = o - centre;
      const double b = glm::dot(oc, d), c = glm::dot(oc, oc) - R * R;
      const double t = -b - std::sqrt(b * b - c);
      const Vec3 p = o + t * d;
      const Vec3 n = (p - centre) / R;
      const Vec3 refl = d - 2.0 * glm::dot(d, n) * n;
      std::vector<PathSegment> path;
      tracer.trace(o, d, 0, &path);
      ASSERT_GE(path.size(), 2u);
      ASSERT_EQ(path[0].event, "reflect");
      EXPECT_LT(glm::length(path[0].point - p), kExactHitTol) << x << "," << y;
      EXPECT_LT(glm::length(path[0].normal - n), 1e-12);
      EXPECT_LT(glm::length(path[1].direction - refl), 1e-12);
    }
  }
}

TEST(Tracer, ExactHitIsIndependentOfTheCandidateTessellation) {
  const double R = -0.6;  // concave
  Scene s = test::roomScene(Vec3(0.0, 0.0, 0.45), Vec3(0, 0, 0));
  const cad::Outline outline = cad::Outline::circle(0.2);
  test::addMirror(s, cad::makeSphere(R, outline), outline, test::pose(Vec3(0), Vec3(0, 0, 1)));
  s.updateBounds();
  RayScene coarse(s, RaySceneOptions{6}), fine(s, RaySceneOptions{128});
  const double scene_size = 2 * s.boundsRadius();
  for (int i = 0; i < 25; ++i) {
    const Vec3 aim(0.08 * std::cos(i * 0.7) * (i % 5) / 4.0, 0.08 * std::sin(i * 0.7) * (i % 5) / 4.0, 0);
    const Vec3 o = s.observer.eye, d = glm::normalize(aim - o);
    RayHit a = coarse.intersect(o, d), b = fine.intersect(o, d);
    ASSERT_EQ(a.kind, HitKind::Element);
    ASSERT_EQ(b.kind, HitKind::Element);
    EXPECT_LT(glm::length(a.point - b.point), 1e-9 * scene_size);
    // And against the analytic sphere: |p - c| = |R|.
    EXPECT_NEAR(glm::length(a.point - Vec3(0, 0, -R)), std::abs(R), kExactHitTol);
  }
}

// A lens built in code: front (eye side) and back sag surfaces, index n without dispersion.
void addLens(Scene& s, cad::SagSurfacePtr front, cad::SagSurfacePtr back, const cad::Outline& outline, double t,
             double n, const Mat4& pose, const Dispersion* dispersion = nullptr) {
  Element e;
  e.name = "lens";
  e.type = ElementType::Lens;
  e.lens = cad::makeLens(front, back, outline, t, 0, "test lens");
  e.outline = outline;
  e.local_to_world = pose;
  e.world_to_local = glm::inverse(pose);
  e.dispersion = dispersion ? *dispersion : Dispersion::constant(n);
  e.dispersion_on = dispersion != nullptr;
  s.elements.push_back(e);
  s.updateBounds();
}

TEST(Tracer, SlabShiftsARayByTheTextbookAmount) {
  const double t = 0.01, n = 1.5;
  Scene s = test::roomScene(Vec3(0, 0, 1), Vec3(0, 0, 0));
  const cad::Outline outline = cad::Outline::circle(0.3);
  addLens(s, cad::makePlane(outline), cad::makePlane(outline), outline, t, n, test::pose(Vec3(0), Vec3(0, 0, 1)));
  RayScene rays(s);
  Tracer tracer(rays, TraceOptions{});
  for (double theta_deg : {10.0, 30.0, 55.0}) {
    const double th = radians(theta_deg);
    const Vec3 d(std::sin(th), 0, -std::cos(th));
    const Vec3 o = Vec3(0, 0, 0) - 0.5 * d;  // through the front vertex
    std::vector<PathSegment> path;
    tracer.trace(o, d, 0, &path);
    ASSERT_GE(path.size(), 3u);
    EXPECT_EQ(path[0].event, "refract");
    EXPECT_EQ(path[1].event, "refract");
    const Vec3 out_o = path[2].origin, out_d = path[2].direction;
    EXPECT_LT(glm::length(out_d - d), 1e-12);  // parallel to the incident ray
    // Lateral shift: distance between the incident line and the emerging line.
    const double shift = glm::length(glm::cross(out_o - o, d));
    const double expected = t * std::sin(th) * (1 - std::cos(th) / std::sqrt(n * n - std::sin(th) * std::sin(th)));
    EXPECT_NEAR(shift, expected, 1e-12) << theta_deg;
  }
}

TEST(Tracer, GlassBallFocusesNearTheParaxialFocus) {
  // A ball lens of radius a from two hemispheres (front R = a, back R = -a, thickness 2a).
  const double a = 0.01, n = 1.5;
  Scene s = test::roomScene(Vec3(0, 0, 1), Vec3(0, 0, 0));
  const cad::Outline outline = cad::Outline::circle(2 * a * 0.999);
  addLens(s, cad::makeSphere(a, outline), cad::makeSphere(-a, outline), outline, 2 * a, n,
          test::pose(Vec3(0), Vec3(0, 0, 1)));
  RayScene rays(s);
  Tracer tracer(rays, TraceOptions{});
  // Rays travel along +z from the far side (z < -2a) towards the eye side. Ball centre at z = -a.
  // Paraxial focus from the centre: f = n a / (2 (n - 1)). Third-order longitudinal spherical
  // aberration grows as h^2: the crossing lies before f by less than C h^2 / a with C < 1 here.
  const double f = n * a / (2 * (n - 1));
  double prev_gap = 0;
  for (double h_rel : {0.05, 0.1, 0.2}) {
    const double h = h_rel * a;
    std::vector<PathSegment> path;
    tracer.trace(Vec3(h, 0, -1.0), Vec3(0, 0, 1), 0, &path);
    ASSERT_GE(path.size(), 3u);
    const Vec3 o = path[2].origin, d = path[2].direction;
    ASSERT_LT(d.x, 0);
    const double z_cross = o.z + (-o.x / d.x) * d.z;  // where x = 0
    const double gap = (-a + f) - z_cross;            // paraxial focus minus crossing
    EXPECT_GT(gap, 0) << h_rel;
    EXPECT_LT(gap, h * h / a) << h_rel;
    EXPECT_GT(gap, prev_gap);  // aberration grows with height
    prev_gap = gap;
  }
}

TEST(Tracer, TotalInternalReflectionBeyondTheCriticalAngle) {
  const double n = 1.5;
  Scene s = test::roomScene(Vec3(0, 0, 1), Vec3(0, 0, 0));
  // Back surface concave towards the glass (R = -0.1 m, centre at z = 0): normal-incidence rays entering the
  // flat front meet it at sin(i) = x / 0.1, beyond the critical angle for x > 0.1 / n.
  const cad::Outline outline = cad::Outline::circle(0.18);
  addLens(s, cad::makePlane(outline), cad::makeSphere(-0.1, outline), outline, 0.1, n, test::pose(Vec3(0), Vec3(0, 0, 1)));
  RayScene rays(s);
  Tracer tracer(rays, TraceOptions{});
  int tir = 0;
  for (double x = 0.05; x < 0.089; x += 0.005) {
    std::vector<PathSegment> path;
    tracer.trace(Vec3(x, 0, 1.0), Vec3(0, 0, -1), 0, &path);
    for (const PathSegment& p : path)
      if (p.event == "tir") {
        ++tir;
        const double cos_i = std::abs(glm::dot(p.direction, p.normal));
        EXPECT_LT(cos_i, std::cos(criticalAngle(n, 1.0)) + 1e-12);
      }
  }
  EXPECT_GT(tir, 0);
}

// Checks one traced path segment by segment.
void checkLaws(const std::vector<PathSegment>& path, const std::string& where) {
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    const PathSegment& s = path[i];
    const Vec3 d = s.direction, dn = path[i + 1].direction, n = s.normal;
    if (s.event == "reflect" || s.event == "tir") {
      EXPECT_LT(glm::length(dn - (d - 2 * glm::dot(d, n) * n)), kLawTol) << where;
    } else if (s.event == "refract") {
      const double sin_i = glm::length(glm::cross(d, n)), sin_t = glm::length(glm::cross(dn, n));
      EXPECT_NEAR(s.n1 * sin_i, s.n2 * sin_t, kLawTol) << where;
      EXPECT_NEAR(glm::dot(glm::cross(d, n), dn), 0.0, kLawTol) << where;  // coplanar
    }
    EXPECT_LT(glm::length(path[i + 1].origin - s.point), kLawTol) << where;
  }
}

// Light totally reflected inside a lens crosses it and meets the back surface again: a plano-convex lens
// (flat front to the light, back R = 20 mm, 36 mm across, 12 mm thick) reflects a ray entering parallel to
// the axis 13.5 to 15.5 mm off it (sin i = h / R, beyond 1 / 1.5) across the lens to the far side of the
// back, where the chord meets it at the same angle: reflected again, it leaves through the front back
// towards the light (a retro-reflection, as in a Porro prism). The lens's own surface search must step past
// the ray's start on the back surface: it once found only that and reported the ray leaving through the edge.
TEST(Tracer, TotallyReflectedLightCrossesTheLensAndLeavesThroughTheFront) {
  Scene s = test::roomScene(Vec3(0, 0, 1), Vec3(0, 0, 0));
  const cad::Outline disc = cad::Outline::circle(0.036);
  addLens(s, cad::makePlane(disc), cad::makeSphere(-0.02, disc), disc, 0.012, 1.5, test::pose(Vec3(0), Vec3(0, 0, 1)));
  RayScene rays(s);
  Tracer tracer(rays, TraceOptions{});
  for (double h = 0.0135; h <= 0.01551; h += 0.0005) {
    std::vector<PathSegment> path;
    const TraceResult r = tracer.trace(Vec3(h, 0.001, 0.5), Vec3(0, 0, -1), 0, &path);
    std::string events;
    for (const PathSegment& p : path) events += p.event + " ";
    ASSERT_EQ(events, "refract tir tir refract diffuse ") << "h = " << h;
    EXPECT_LT(path[2].point.x, 0.0) << "the second reflection is on the far side";
    EXPECT_GT(path[3].direction.z, 0.0) << "back towards the light";
    EXPECT_GT(glm::length(r.color), 0.0);
    checkLaws(path, "h = " + std::to_string(h));
  }
}

TEST(Tracer, PathsInEveryDefaultSceneObeyTheLaws) {
  const std::filesystem::path models = std::filesystem::path(PVRR_SOURCE_DIR) / "models";
  int scenes = 0, specular = 0;
  for (const auto& entry : std::filesystem::directory_iterator(models)) {
    if (entry.path().extension() != ".json") continue;
    SceneDesc desc = loadScene(entry.path().string(), {"observer.image_size=[40,30]"});
    Scene scene = buildScene(desc);
    RayScene rays(scene);
    Tracer tracer(rays, TraceOptions{});
    ++scenes;
    for (int y = 0; y < 30; y += 3)
      for (int x = 0; x < 40; x += 3) {
        std::vector<PathSegment> path;
        tracer.trace(scene.observer.eye, scene.observer.pixelDirection(x + 0.5, y + 0.5), 0, &path);
        for (const PathSegment& p : path) specular += p.event == "reflect" || p.event == "refract";
        checkLaws(path, entry.path().filename().string());
      }
  }
  EXPECT_GE(scenes, 5);
  EXPECT_GT(specular, 0);
}

// A room with a convex mirror on the left and a dispersive biconvex polycarbonate lens on the right of the
// view: every kind of primary hit (environment, mirror, lens, mirror rim, lens rim) in one small image.
Scene mirrorAndLensScene(int width, int height) {
  Scene s = test::roomScene(Vec3(0.0, 0.05, 1.0), Vec3(0, 0, 0), width, height);
  const cad::Outline mo = cad::Outline::rectangle(0.3, 0.22, 0.04);
  test::addMirror(s, cad::makeSphere(0.8, mo), mo, test::pose(Vec3(-0.22, 0, 0), Vec3(0.35, 0.1, 1)));
  const cad::Outline lo = cad::Outline::circle(0.26);
  const Dispersion pc = lookupLensMaterial("polycarbonate").dispersion;
  addLens(s, cad::makeSphere(0.5, lo), cad::makeSphere(-0.5, lo), lo, 0.05, pc.n_d(),
          test::pose(Vec3(0.2, 0, 0), Vec3(-0.2, 0, 1)), &pc);
  s.updateBounds();
  return s;
}

// Packets exist for speed only: their hits must be the single-ray hits. Both resolve Embree's candidate
// with the same double-precision code, so they agree to the last bit unless Embree's packet and single
// kernels pick different triangles at a shared edge; then both are exact hits on the same surface.
constexpr double kPacketTol = 1e-12;  // m, the bound the issue states for packet vs single

TEST(RayScenePackets, PrimaryHitsMatchSingleRays) {
  Scene s = mirrorAndLensScene(64, 48);
  RayScene rays(s);
  const Observer& ob = s.observer;
  int kinds[3] = {0, 0, 0}, identical = 0, total = 0;
  // 4 x 4 tiles of pixels, and a ragged final packet of 7 lanes.
  for (int ty = 0; ty < ob.height; ty += 4)
    for (int tx = 0; tx < ob.width; tx += 4) {
      std::array<Vec3, RayScene::kPacketSize> o, d;
      std::array<RayHit, RayScene::kPacketSize> hits;
      const bool ragged = tx == 0 && ty == 0;
      const int count = ragged ? 7 : 16;
      for (int k = 0; k < count; ++k) {
        o[size_t(k)] = ob.eye;
        d[size_t(k)] = ob.pixelDirection(tx + k % 4 + 0.5, ty + k / 4 + 0.5);
      }
      rays.intersectPacket(o.data(), d.data(), count, hits.data());
      for (int k = 0; k < count; ++k) {
        const RayHit single = rays.intersect(o[size_t(k)], d[size_t(k)]);
        const RayHit& p = hits[size_t(k)];
        ++total;
        ++kinds[int(single.kind)];
        ASSERT_EQ(p.kind, single.kind) << tx << "," << ty << " lane " << k;
        EXPECT_EQ(p.element, single.element);
        EXPECT_EQ(p.surface, single.surface);
        EXPECT_EQ(p.mesh, single.mesh);
        if (!single.hit()) continue;
        EXPECT_LT(glm::length(p.point - single.point), kPacketTol);
        EXPECT_LT(glm::length(p.normal - single.normal), kPacketTol);
        identical += p.point == single.point && p.t == single.t;
      }
    }
  // The grid covers environment, element and (none) misses are impossible inside the room.
  EXPECT_GT(kinds[int(HitKind::Environment)], 100);
  EXPECT_GT(kinds[int(HitKind::Element)], 100);
  // Bit-identical except at the odd shared edge.
  EXPECT_GE(identical, total * 99 / 100);
}

TEST(RayScenePackets, PacketAndSingleRayFramesAgree) {
  Scene s = mirrorAndLensScene(48, 36);
  RayScene rays(s);
  for (DispersionMode mode : {DispersionMode::Off, DispersionMode::Rgb}) {
    TraceOptions po, so;
    po.dispersion = so.dispersion = mode;
    so.primary_packets = false;
    const Frame a = Tracer(rays, po).render(), b = Tracer(rays, so).render();
    ASSERT_EQ(a.color.size(), b.color.size());
    for (size_t i = 0; i < a.color.size(); ++i) {
      EXPECT_EQ(a.element[i], b.element[i]) << i;
      EXPECT_EQ(a.bounces[i], b.bounces[i]) << i;
      EXPECT_LT(glm::length(a.seen[i] - b.seen[i]), kPacketTol * 1e3) << i;  // 1e-9 m after several bounces
      EXPECT_LT(glm::length(a.color[i] - b.color[i]), 1e-9) << i;
    }
  }
}

// Spectacles turning with the head (RaySceneOptions::moving_elements: the lens's candidate BVHs are refitted,
// the top level rebuilt): after updateElementPoses, every frame traced through the refitted scene matches
// one traced through a scene built afresh at the new pose. Exact element hits come from Newton on the
// exact surface either way; only the candidate search differs, so the seen points agree to 1e-9 m.
TEST(RayScene, MovingElementsAfterAPoseUpdateMatchAFreshScene) {
  Scene s = buildScene(loadScene(std::string(PVRR_SOURCE_DIR) + "/models/spectacle-lens.json", {"observer.image_size=[64,48]"}));
  RaySceneOptions moving;
  moving.moving_elements = true;
  RayScene refitted(s, moving);
  const SceneDesc desc = loadScene(std::string(PVRR_SOURCE_DIR) + "/models/spectacle-lens.json", {"observer.image_size=[64,48]"});
  const Vec3 eye = s.observer.eye, target = s.observer.target;
  size_t lens_pixels = 0;
  for (double deg : {3.0, 10.0}) {
    const Mat4 rot = glm::rotate(Mat4(1.0), radians(deg), s.observer.up);
    s.observer.target = eye + Vec3(rot * Vec4(target - eye, 0.0));
    updateAttachedElements(s, desc);
    refitted.updateElementPoses();
    RayScene fresh(s);
    const Frame a = Tracer(refitted, TraceOptions{}).render(), b = Tracer(fresh, TraceOptions{}).render();
    for (size_t i = 0; i < a.seen.size(); ++i) {
      ASSERT_EQ(a.element[i], b.element[i]) << deg << " deg, pixel " << i;
      EXPECT_LT(glm::length(a.seen[i] - b.seen[i]), 1e-9) << deg << " deg, pixel " << i;
      lens_pixels += a.element[i] >= 0;
    }
  }
  EXPECT_GT(lens_pixels, 1000u);  // the lens fills most of the view
}

TEST(Tracer, RgbModeRecordsEachChannelsSeenPoint) {
  Scene s = mirrorAndLensScene(32, 24);
  RayScene rays(s);
  TraceOptions rgb;
  rgb.dispersion = DispersionMode::Rgb;
  Tracer tracer(rays, rgb);
  const Frame f = tracer.render();
  const size_t n = size_t(f.width) * size_t(f.height);
  for (const auto& c : f.channel_seen) ASSERT_EQ(c.size(), n);
  const Tracer mono(rays, TraceOptions{});
  int lens_pixels = 0, fringes = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const size_t i = size_t(y) * size_t(f.width) + size_t(x);
      const Vec3 d = s.observer.pixelDirection(x + 0.5, y + 0.5);
      // Each channel's seen point is that of its own wavelength's ray; green is the frame's seen point.
      for (int c = 0; c < 3; ++c) {
        const TraceResult r = mono.trace(s.observer.eye, d, kRgbWavelengths_nm[c]);
        EXPECT_LT(glm::length(f.channel_seen[size_t(c)][i] - r.seen), 1e-9) << x << "," << y << " c" << c;
      }
      EXPECT_EQ(f.channel_seen[1][i], f.seen[i]);
      if (f.element[i] == 1) {
        ++lens_pixels;
        fringes += glm::length(f.channel_seen[0][i] - f.channel_seen[2][i]) > 1e-6;
      } else if (f.element[i] < 0) {
        EXPECT_EQ(f.channel_seen[0][i], f.seen[i]);
        EXPECT_EQ(f.channel_seen[2][i], f.seen[i]);
      }
    }
  EXPECT_GT(lens_pixels, 20);
  EXPECT_GT(fringes, lens_pixels / 2);  // polycarbonate (V_d = 30) separates C and F
  // Other modes leave the channels empty.
  const Frame off = mono.render();
  for (const auto& c : off.channel_seen) EXPECT_TRUE(c.empty());
}

}  // namespace
}  // namespace pvrr
