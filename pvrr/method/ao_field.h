// Presampled visibility around rigid objects, for ambient occlusion (pvrr/trace/ambient_occlusion.h defines
// it): [Gaitatzes et al.]'s displacement fields. Per occluding object, at load time, with Embree:
// - positional samples: `positions`^2 points on the object's bounding sphere (centre: its bounding box's
//   centre in the placed pose; radius: the farthest vertex, widened by kAoRadiusMargin), one per texel of an
//   octahedral map of the sphere (uniform enough, with a constant-time inverse);
// - from each, `directions`^2 rays over the inward hemisphere, one per texel of a concentric map lifted by
//   Malley's method (the paper's best sampling), in the frame basisAround(-s);
// - per ray one byte: the distance to the object's first hit, in 254ths of the sphere's diameter, 255 when
//   the ray misses (the paper's 8-bit maps). A field is (positions * directions)^2 bytes, one square atlas.
// The field lives in the object's placed frame; the object's rigid motion (EnvMesh::motion) carries it.
//
// At run time (fieldVisibility here; shaders/ambient_occlusion.glsl the same in GLSL), per receiver point x
// with normal n and per field:
// - x outside the sphere: `samples` rays uniform over the cone of directions that meet the sphere, weighted by
//   their solid angle and cosine; a ray that enters the sphere at e is occluded when the field's ray from the
//   sample nearest e, in the same direction, hits (the paper's Algorithm 2, sampling only rays that meet the
//   bounding sphere);
// - x inside it (the ground under a car): `samples` cosine-distributed rays about n; the field's ray from
//   the sample nearest the exit point e, back along the ray, hits at distance d; the object lies between x
//   and e when d < |e - x|.
// Occlusions of several fields add (a direction two of them hide is counted twice: an approximation); the
// visibility is 1 minus their sum, at least 0.
//
// What a frame reads (the occlusion volume): casting the fragment's rays through the field costs llvmpipe
// seconds a 1280 x 720 frame, so the field's occlusion is evaluated once, at load time, on a grid around the
// occluder in its own frame (rigid: it moves with it), kAoVolumeSize^3 points at warped coordinates
// t = x / (|x| + r) per axis (x from the sphere's centre: fine near the object, the whole space within
// (-1, 1)), each holding the occlusion for the six axis normals +-x, +-y, +-z (an "ambient cube": a normal n
// reads sum n_i^2 O(sign(n_i) axis_i), exact for axis normals, such as a ground under a car that turns about
// the vertical). A fragment reads it trilinearly: one texture lookup per occluder (the GPU copy holds, per
// octant of normals, the three axis occlusions of its signs: pvrr/gl/ao_fields.cpp).
//
// The ground maps (what most fragments read): on a horizontal plane y = h (a ground, a pavement) facing up,
// with the occluder turning about the vertical only, the occlusion depends on the two horizontal offsets from
// the centre alone. Per occluder and per such height a kAoGroundSize^2 map of O(+y) at the warped coordinates
// (x, z) of the volume, the fade (aoFade) included: one bilinear lookup of one channel per occluder, not two
// trilinear ones of four.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "pvrr/scene/scene.h"

namespace pvrr {

inline constexpr double kAoRadiusMargin = 1e-3;  // relative widening of the bounding sphere
inline constexpr uint8_t kAoMiss = 255;          // a field ray that meets nothing
// A sphere seen within a cone narrower than this (sin^2 of its half angle: farther than 10 radii) is left out:
// it hides at most this cosine-weighted fraction (less by how much of the sphere the occluder fills); a
// volume's occlusion fades out linearly from twice this (7 radii) so that no edge shows
// (shaders/ambient_occlusion.glsl's AO_MIN_CONE).
inline constexpr double kAoMinCone = 0.01;
// The fade: 1 at sin^2 >= 2 kAoMinCone, 0 at kAoMinCone.
inline double aoFade(double sin2) { return std::clamp(sin2 / kAoMinCone - 1, 0.0, 1.0); }
// Occlusion below this is left out where a whole mesh lies beyond it (AoField::reach): it darkens a pixel by
// at most albedo * ambient * 2/255, under one 8-bit step of the picture for albedo * ambient <= 0.5.
inline constexpr double kAoNegligible = 2.0 / 255;

struct AoField {
  int occluder = -1;        // EnvMesh::occluder
  Vec3 centre{0};           // bounding sphere in the placed pose (world)
  double radius = 0;
  int positions = 0;        // positional samples per side of the octahedral map
  int directions = 0;       // direction samples per side of each concentric map
  std::vector<uint8_t> data;  // width()^2 bytes, row v at v * width(): texel (p.x * directions + d.x,
                              // p.y * directions + d.y) for positional texel p and direction texel d
  // The occlusion volume: kAoVolumeSize^3 grid points (x fastest), per point 8 bytes: O for +x, -x, +y, -y,
  // +z, -z in 255ths, then two zeros.
  std::vector<uint8_t> volume;
  // Beyond this distance from the centre (m, the field's frame) the volume's occlusion, fade included, is below
  // kAoNegligible for every normal: the raster modes draw a mesh wholly beyond it without this field.
  double reach = 0;
  double build_ms = 0;      // its precomputation (wall clock): field and volume
  int width() const { return positions * directions; }
  size_t bytes() const { return data.size(); }
};

inline constexpr int kAoVolumeSize = 40;       // grid points per axis
inline constexpr int kAoVolumeRays = 64;        // rays per grid point outside the sphere (its cone)
inline constexpr int kAoVolumeInsideSide = 12;  // inside: the whole sphere, kAoVolumeInsideSide^2 rays
inline constexpr int kAoGroundSize = 64;        // ground map texels per side (finer than the volume's 40)

// The warped coordinate t in (-1, 1) of offset x from the centre (radius r), and back.
inline double aoWarp(double x, double r) { return x / (std::abs(x) + r); }
inline double aoUnwarp(double t, double r) { return r * t / (1 - std::abs(t)); }

// Octahedral map of the unit sphere onto [0, 1]^2, and back.
Vec2 octEncode(const Vec3& unit);
Vec3 octDecode(Vec2 uv);

// The field of occluder `occluder` (its meshes, in their placed pose; Scene::placed_meshes for an animated
// one), with `positions`^2 positional and `directions`^2 directional samples.
AoField buildAoField(const Scene& scene, int occluder, int positions, int directions);
// A field per occluder (index = EnvMesh::occluder), with the scene's render.ambient_occlusion sampling.
std::vector<AoField> buildAoFields(const Scene& scene);

// The field's distance (metres) along the ray that enters the sphere at unit direction s from its centre in
// direction w (both in the field's frame), or kInf when it misses.
double fieldDistance(const AoField& f, const Vec3& s, const Vec3& w);
// The cosine-weighted occlusion (0..1) one field casts at world point x with unit normal n, its object moved
// by `motion` (rigid), with `samples` rays.
double fieldOcclusion(const AoField& f, const Mat4& motion, const Vec3& x, const Vec3& n, int samples);
// The visibility A(x, n) of the fields of every occluder but `receiver` (-1: none), each moved by its
// meshes' current EnvMesh::motion.
double fieldVisibility(const std::vector<AoField>& fields, const Scene& scene, const Vec3& x, const Vec3& n,
                       int receiver, int samples);
// The occlusion of the field's volume (trilinear, ambient cube) at world x with unit normal n: what a frame
// shades (shaders/ambient_occlusion.glsl).
double volumeOcclusion(const AoField& f, const Mat4& motion, const Vec3& x, const Vec3& n);
// The volume's ambient cube at world x (trilinear, the fade included): the occlusion for the six axis normals
// +x, -x, +y, -y, +z, -z of the field's frame; and what it gives normal n (the field's frame): sum n_i^2 O_i.
std::array<double, 6> volumeCube(const AoField& f, const Mat4& motion, const Vec3& x);
double cubeOcclusion(const std::array<double, 6>& cube, const Vec3& n);
// The visibility from the volumes of every occluder but `receiver`.
double volumeVisibility(const std::vector<AoField>& fields, const Scene& scene, const Vec3& x, const Vec3& n,
                        int receiver);
// The ground map of field f on the plane y = height (the field's frame, world metres): kAoGroundSize^2 bytes
// (x fastest), O(+y) in 255ths with the fade, texel (i, k) at the warped offsets (2 (i + 0.5) / n - 1,
// 2 (k + 0.5) / n - 1) in x and z from the centre.
std::vector<uint8_t> groundMap(const AoField& f, double height);
// The occlusion the ground map casts at world x on a horizontal plane facing up (what the shader's ground
// variant shades): bilinear, clamped at the outermost texels; the occluder's motion turns about the vertical.
double groundMapOcclusion(const AoField& f, const std::vector<uint8_t>& map, const Mat4& motion, const Vec3& x);
// The current motion of occluder `occluder` (its first mesh's; a group's objects move together).
Mat4 occluderMotion(const Scene& scene, int occluder);

}  // namespace pvrr
