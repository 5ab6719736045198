// Keyframed rigid motion of environment objects and elements (the scene format's "animation" block,
// docs/scene-format.md): per key a time in seconds, an offset from the pose the object is placed at and a
// rotation about that placed position; between keys linear or smooth (ease-in/ease-out) interpolation,
// before the first key the first, after the last the last. Evaluated in doubles.
#pragma once
#include <vector>

#include "pvrr/base/math.h"
#include "pvrr/base/names.h"

namespace pvrr {

struct Keyframe {
  double time_s = 0;
  Vec3 offset_m{0};      // displacement of the object from its placed pose (metres, world or observer frame)
  Vec3 rotation_deg{0};  // R = Rz * Ry * Rx about the object's placed position, as the scene's rotation_deg
};

// Between two keys at fraction s in [0, 1] of their interval: linear s; smooth 3 s^2 - 2 s^3 (smoothstep:
// zero velocity at every key, so a motion that stops at a key stops without a jolt).
enum class Interpolation { Linear, Smooth };
inline constexpr NameTable<Interpolation, 2> kInterpolationNames = {
    {{Interpolation::Linear, "linear"}, {Interpolation::Smooth, "smooth"}}};
constexpr const NameTable<Interpolation, 2>& nameTable(Interpolation) { return kInterpolationNames; }
static_assert(namesAreUnique(kInterpolationNames));

struct AnimationDesc {
  Interpolation interpolation = Interpolation::Linear;
  std::vector<Keyframe> keys;  // at least one, times strictly increasing (the parser checks)
};

// The offset and the rotation angles at time t (componentwise interpolation of the angles: exact for a
// rotation about one axis, the turn of a car).
Keyframe sampleAnimation(const AnimationDesc& a, double t_s);

// The interpolation weight of fraction s in [0, 1].
double interpolationWeight(Interpolation i, double s);

// R = Rz * Ry * Rx of angles in degrees.
Mat3 rotationFromDeg(const Vec3& deg);

// The rigid motion at time t of an object placed at `pivot`: x -> pivot + offset + R (x - pivot).
Mat4 motionAt(const AnimationDesc& a, const Vec3& pivot, double t_s);

// Instants that bound an animation's whole motion: every key, and between two keys enough instants that the
// rotation angles change by at most kSweepStepDeg summed over the three axes from one to the next (at most
// kMaxSweepSteps per interval, each step then larger). Between two neighbouring instants a point at distance
// r from the pivot stays within r max_step_rad of the segment joining its two sampled positions: the
// translation is linear in the interpolation weight, as the segment is, so only the turn strays from it; R =
// Rz Ry Rx turns by at most the sum of its angles' changes, so the turning point moves at most r max_step_rad
// and the segment's point at most as far, both starting and ending together. Padding the box of the
// sampled poses by r max_step_rad therefore bounds the sweep.
struct SweepSamples {
  std::vector<double> times_s;
  double max_step_rad = 0;  // the largest sum of the three angles' changes between neighbouring instants
};
inline constexpr double kSweepStepDeg = 1.0;
inline constexpr int kMaxSweepSteps = 64;
SweepSamples sweepSamples(const AnimationDesc& a);

}  // namespace pvrr
