// Keyframed motion (pvrr/scene/animation.h): interpolation against its closed forms, the rigid motion about
// the placed position, the scene format's "animation" and "dynamic" (one-line errors naming the JSON path), and
// the built scene posed at a time (applyAnimation), its bounds over a turn between keys, and the ray scene
// moved in place (RayScene::updateEnvironmentMeshes).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "pvrr/base/error.h"
#include "pvrr/scene/animation.h"
#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr {
namespace {

// The interpolation is a few double operations on values of order 1..10: exact to a few ulps.
constexpr double kTol = 1e-12;
// Mesh positions are floats relative to their anchor (metres of order 1): a rotation rounds them to float.
constexpr double kFloatTol_m = 1e-6;

AnimationDesc twoKeys(Interpolation i) {
  AnimationDesc a;
  a.interpolation = i;
  a.keys = {{1.0, Vec3(0, 0, 10), Vec3(0, 0, 0)}, {3.0, Vec3(0, 2, -10), Vec3(0, 90, 0)}};
  return a;
}

TEST(Animation, LinearIsTheStraightLineBetweenKeys) {
  const AnimationDesc a = twoKeys(Interpolation::Linear);
  for (const double t : {1.0, 1.5, 2.0, 2.75, 3.0}) {
    const double s = (t - 1.0) / 2.0;
    const Keyframe k = sampleAnimation(a, t);
    EXPECT_NEAR(k.offset_m.z, 10.0 - 20.0 * s, kTol) << t;
    EXPECT_NEAR(k.offset_m.y, 2.0 * s, kTol) << t;
    EXPECT_NEAR(k.rotation_deg.y, 90.0 * s, kTol) << t;
  }
}

TEST(Animation, SmoothIsSmoothstepWithZeroVelocityAtTheKeys) {
  const AnimationDesc a = twoKeys(Interpolation::Smooth);
  for (const double t : {1.25, 2.0, 2.5}) {
    const double s = (t - 1.0) / 2.0, w = 3 * s * s - 2 * s * s * s;
    EXPECT_NEAR(sampleAnimation(a, t).offset_m.z, 10.0 - 20.0 * w, kTol) << t;
  }
  // Half way it is where linear is; next to a key it has barely moved (derivative 0 there).
  EXPECT_NEAR(sampleAnimation(a, 2.0).offset_m.z, 0.0, kTol);
  const double h = 1e-4, moved = std::abs(sampleAnimation(a, 1.0 + h).offset_m.z - 10.0);
  EXPECT_LT(moved, 20.0 * 3 * (h / 2) * (h / 2) * 1.01);  // 3 s^2 of the way, s = h / 2
}

TEST(Animation, HoldsTheFirstKeyBeforeAndTheLastAfter) {
  const AnimationDesc a = twoKeys(Interpolation::Linear);
  EXPECT_EQ(sampleAnimation(a, -5.0).offset_m, Vec3(0, 0, 10));
  EXPECT_EQ(sampleAnimation(a, 100.0).offset_m, Vec3(0, 2, -10));
  AnimationDesc one;
  one.keys = {{0.0, Vec3(1, 2, 3), Vec3(0)}};
  EXPECT_EQ(sampleAnimation(one, 7.0).offset_m, Vec3(1, 2, 3));
}

TEST(Animation, ThreeKeysInterpolateWithinTheirOwnInterval) {
  AnimationDesc a;
  a.keys = {{0.0, Vec3(0), Vec3(0)}, {1.0, Vec3(1, 0, 0), Vec3(0)}, {3.0, Vec3(1, 4, 0), Vec3(0)}};
  EXPECT_NEAR(sampleAnimation(a, 0.5).offset_m.x, 0.5, kTol);
  EXPECT_NEAR(sampleAnimation(a, 2.0).offset_m.y, 2.0, kTol);
  EXPECT_NEAR(sampleAnimation(a, 2.0).offset_m.x, 1.0, kTol);
}

TEST(Animation, MotionRotatesAboutThePlacedPositionThenOffsets) {
  AnimationDesc a;
  a.keys = {{0.0, Vec3(0.5, 0, 0), Vec3(0, 90, 0)}};
  const Vec3 pivot(2, 1, -4);
  const Mat4 m = motionAt(a, pivot, 0.0);
  // The pivot only moves by the offset; a point 1 m along +x from it turns to -z (90 deg about +y).
  const Vec3 p = Vec3(m * Vec4(pivot, 1.0)), q = Vec3(m * Vec4(pivot + Vec3(1, 0, 0), 1.0));
  EXPECT_NEAR(glm::length(p - (pivot + Vec3(0.5, 0, 0))), 0.0, kTol);
  EXPECT_NEAR(glm::length(q - (pivot + Vec3(0.5, 0, -1))), 0.0, kTol);
  // The rotation is rotation_deg's R = Rz Ry Rx.
  const Mat3 r = rotationFromDeg(Vec3(0, 0, 90));
  EXPECT_NEAR(glm::length(r * Vec3(1, 0, 0) - Vec3(0, 1, 0)), 0.0, kTol);
}

const std::string kScene = R"({
  "version": 1,
  "observer": {"eye": [0, 1.2, 0], "target": [0, 1.2, -1]},
  "environment": [
    {"type": "box", "name": "car", "centre": [2, 0.7, 10], "size": [1.8, 1.4, 4.2],
     "animation": {"interpolation": "linear",
                   "keys": [{"time_s": 0, "offset": [0, 0, 0]}, {"time_s": 2, "offset": [0, 0, -20]}]}},
    {"type": "ground", "point": [0, 0, 0], "normal": [0, 1, 0], "size": [50, 50]}
  ],
  "elements": [
    {"name": "m", "type": "mirror", "pose": {"position": [0, 1.2, -1], "normal": [0, 0, 1]},
     "outline": {"shape": "circle", "diameter": 0.2}, "surface": {"type": "plane"},
     "animation": {"keys": [{"time_s": 0}, {"time_s": 1, "rotation_deg": [0, 10, 0]}]}}
  ]
})";

std::string errorOf(const std::string& text) {
  try {
    parseScene(text, "t.json", "");
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return "";
}
std::string edited(const std::string& from, const std::string& to) {
  std::string s = kScene;
  const size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

TEST(Animation, SceneFormatReadsKeysAndDynamic) {
  const SceneDesc d = parseScene(kScene, "t.json", "");
  ASSERT_TRUE(d.environment[0].animation);
  EXPECT_TRUE(d.environment[0].dynamic);
  EXPECT_FALSE(d.environment[1].dynamic);
  EXPECT_EQ(d.environment[0].animation->keys.size(), 2u);
  EXPECT_EQ(d.environment[0].animation->keys[1].offset_m, Vec3(0, 0, -20));
  EXPECT_TRUE(d.elements[0].dynamic);
  EXPECT_EQ(d.elements[0].animation->interpolation, Interpolation::Linear);
}

TEST(Animation, BadAnimationsGiveOneLineNamingThePath) {
  EXPECT_EQ(errorOf(edited("{\"time_s\": 2, ", "{\"time_s\": 0, ")),
            "t.json: environment[0].animation.keys[1].time_s: expected a time after the previous key's 0 s, got 0");
  EXPECT_EQ(errorOf(edited("\"interpolation\": \"linear\"", "\"interpolation\": \"smoth\"")),
            "t.json: environment[0].animation.interpolation: expected one of \"linear\" or \"smooth\", got \"smoth\"; "
            "did you mean \"smooth\"?");
  EXPECT_NE(
      errorOf(edited("\"keys\": [{\"time_s\": 0}, {\"time_s\": 1, \"rotation_deg\": [0, 10, 0]}]", "\"keys\": []"))
          .find("t.json: elements[0].animation.keys: expected a non-empty array of keys"),
      std::string::npos);
  EXPECT_NE(errorOf(edited("\"size\": [1.8, 1.4, 4.2],", "\"size\": [1.8, 1.4, 4.2], \"dynamic\": false,"))
                .find("t.json: environment[0].dynamic: expected true (an animated object is dynamic)"),
            std::string::npos);
  EXPECT_NE(errorOf(edited("{\"time_s\": 0, \"offset\"", "{\"time_s\": 0, \"ofset\"")).find("did you mean \"offset\"?"),
            std::string::npos);
}

TEST(Animation, TheBuiltSceneIsPosedAtTheTimeGiven) {
  const SceneDesc d = parseScene(kScene, "t.json", "");
  Scene s = buildScene(d);
  const auto centre = [&](double t) {
    applyAnimation(s, d, t);
    const EnvMesh& m = s.meshes[0];
    Vec3 sum(0);
    for (const glm::vec3& p : m.positions) sum += m.anchor + Vec3(p);
    return sum / double(m.positions.size());
  };
  const Vec3 bounds_min = s.bounds_min, bounds_max = s.bounds_max;
  EXPECT_NEAR(glm::length(centre(0.0) - Vec3(2, 0.7, 10)), 0.0, kFloatTol_m);
  EXPECT_NEAR(glm::length(centre(0.5) - Vec3(2, 0.7, 5)), 0.0, kFloatTol_m);
  EXPECT_NEAR(glm::length(centre(2.0) - Vec3(2, 0.7, -10)), 0.0, kFloatTol_m);
  // The bounds hold every key's pose and do not change with time.
  EXPECT_EQ(s.bounds_min, bounds_min);
  EXPECT_EQ(s.bounds_max, bounds_max);
  EXPECT_LE(bounds_min.z, -10 - 2.1 + kFloatTol_m);
  EXPECT_GE(bounds_max.z, 10 + 2.1 - kFloatTol_m);
  // The mirror turns 5 deg about its vertex at t = 0.5: its normal (local +z) turns with it; the ground stays.
  applyAnimation(s, d, 0.5);
  const Vec3 n = s.elements[0].toWorldDir(Vec3(0, 0, 1));
  EXPECT_NEAR(std::atan2(n.x, n.z), radians(5.0), kTol);
  EXPECT_NEAR(glm::length(s.elements[0].toWorldPoint(Vec3(0)) - Vec3(0, 1.2, -1)), 0.0, kTol);
  EXPECT_FALSE(applyAnimation(s, d, 0.5)) << "nothing moves from where it is";
  EXPECT_TRUE(applyAnimation(s, d, 0.6));
  EXPECT_EQ(s.time_s, 0.6);
}

// A long bar turning from -45 to +45 degrees about its centre between two keys: at 0 degrees (mid-way) its
// ends reach 4 m from the centre along x, beyond both key poses' boxes (4 cos 45 = 2.83 m, plus the bar's
// half width). The bounds hold every instant's pose (checked finely here), not only the keys'.
TEST(Animation, BoundsHoldARotationBetweenKeys) {
  const std::string scene = R"({
    "version": 1,
    "observer": {"eye": [0, 1.2, 0], "target": [0, 1.2, -1]},
    "environment": [
      {"type": "box", "name": "bar", "centre": [0, 0.5, -10], "size": [8, 0.2, 0.2],
       "animation": {"keys": [{"time_s": 0, "rotation_deg": [0, -45, 0]}, {"time_s": 1, "rotation_deg": [0, 45, 0]}]}}
    ]
  })";
  const SceneDesc d = parseScene(scene, "t.json", "");
  Scene s = buildScene(d);
  const Vec3 lo = s.bounds_min, hi = s.bounds_max;
  EXPECT_GE(hi.x, 4.0) << "the mid-way pose is outside the keys' boxes";
  for (int i = 0; i <= 200; ++i) {
    applyAnimation(s, d, i / 200.0);
    const EnvMesh& m = s.meshes[0];
    for (const glm::vec3& p : m.positions) {
      const Vec3 w = m.anchor + Vec3(p);
      EXPECT_TRUE(glm::all(glm::greaterThanEqual(w, lo - kFloatTol_m)) &&
                  glm::all(glm::lessThanEqual(w, hi + kFloatTol_m)))
          << "t = " << i / 200.0;
    }
  }
  // Sampling: 90 deg of turn in 1 deg steps would be 90, capped at kMaxSweepSteps (64): 90 / 64 deg each,
  // padded by the bar's half diagonal times that.
  const SweepSamples sw = sweepSamples(*d.environment[0].animation);
  EXPECT_EQ(sw.times_s.size(), size_t(kMaxSweepSteps) + 1);
  EXPECT_NEAR(sw.max_step_rad, radians(90.0 / kMaxSweepSteps), kTol);
}

// The animated car moves in the ray scene in place: a ray at where it is now hits it, where it was misses
// it, as in a ray scene built anew at that instant; the static ground is hit all along.
TEST(Animation, TheRaySceneMovesAnimatedMeshesInPlace) {
  const SceneDesc d = parseScene(kScene, "t.json", "");
  Scene s = buildScene(d);
  RayScene rays(s);
  EXPECT_TRUE(rays.hasDynamicMeshes());
  const Vec3 down(0, -1, 0);
  const auto meshHit = [&](const RayScene& r, double z) { return r.intersect(Vec3(2, 5, z), down).mesh; };
  EXPECT_EQ(meshHit(rays, 10), 0);  // the car at t = 0
  applyAnimation(s, d, 1.0);        // 10 m on
  EXPECT_EQ(rays.updateEnvironmentMeshes(), 1);
  EXPECT_EQ(rays.updateEnvironmentMeshes(), 0) << "nothing moved since";
  RayScene fresh(s);
  for (const double z : {10.0, 0.0, -10.0, 5.0}) {
    const RayHit a = rays.intersect(Vec3(2, 5, z), down), b = fresh.intersect(Vec3(2, 5, z), down);
    EXPECT_EQ(a.mesh, b.mesh) << z;
    EXPECT_EQ(a.t, b.t) << z;
    EXPECT_EQ(a.point, b.point) << z;
  }
  EXPECT_EQ(meshHit(rays, 10), 1) << "the car left: the ground";
  EXPECT_EQ(meshHit(rays, 0), 0) << "the car is here now";
  // A packet query goes through the same scene.
  Vec3 o[2] = {Vec3(2, 5, 0), Vec3(2, 5, 10)}, dirs[2] = {down, down};
  RayHit out[2];
  rays.intersectPacket(o, dirs, 2, out);
  EXPECT_EQ(out[0].mesh, 0);
  EXPECT_EQ(out[1].mesh, 1);
}

}  // namespace
}  // namespace pvrr
