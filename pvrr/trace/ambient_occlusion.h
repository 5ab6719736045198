// Ambient occlusion (render.ambient_occlusion, docs/scene-format.md): what it means, and the reference's
// hemisphere-sampled estimate of it.
//
// Definition, shared by the reference (here) and the raster path's displacement fields
// (pvrr/method/ao_field.h, shaders/ambient_occlusion.glsl):
//   visibility A(x, n) = 1/pi * integral over the hemisphere about n of V(x, w) (w . n) dw,
//   V = 0 where the ray x + t w (t > 0, any distance) meets an occluding environment object other than the
//   one x lies on, else 1.
// Occluders are the objects marked "ambient_occlusion" (EnvMesh::occluder; objects of one named group form
// one occluder); other meshes and the optical elements let the ray through. An occluder does not occlude
// itself. The ambient lights' term of the
// environment shading (pvrr/trace/shading.h) is multiplied by A; directional and point lights are not.
//
// The sampling maps shared by both (cosine-weighted directions from a square, [Gaitatzes et al.]'s concentric
// map sampling): Shirley and Chiu's concentric map of [-1, 1]^2 onto the unit disk, lifted to the hemisphere by
// Malley's method, and its inverse.
#pragma once
#include "pvrr/trace/ray_scene.h"

namespace pvrr {

// Shirley-Chiu concentric map: the square [-1, 1]^2 onto the unit disk, area-preserving up to a constant.
Vec2 concentricDisk(Vec2 square);
// Its inverse: a point of the unit disk back to the square.
Vec2 concentricSquare(Vec2 disk);
// Malley: a point of the unit disk lifted to the unit hemisphere about +z (cosine-distributed when the disk
// points are uniform).
inline Vec3 malleyLift(Vec2 d) { return Vec3(d, std::sqrt(std::max(0.0, 1.0 - d.x * d.x - d.y * d.y))); }
// An orthonormal basis (t, b) perpendicular to unit n, continuous except where n.z changes sign
// (Duff et al. 2017, "Building an orthonormal basis, revisited"); the shader has the same formula.
void basisAround(const Vec3& n, Vec3& t, Vec3& b);

// The occluder of environment mesh `mesh` (EnvMesh::occluder), or -1.
int occluderOfMesh(const Scene& scene, int mesh);
// How many occluders the scene has (one more than the largest EnvMesh::occluder).
int occluderCount(const Scene& scene);

// The reference: A(x, n) estimated with `samples` cosine-distributed rays (a jittered concentric-map grid of
// ceil(sqrt(samples))^2 cells, each jittered by a hash of x: unbiased, and the same for the same point). `receiver`: the occluder x lies on (it does not occlude), or -1. 1 when nothing occludes.
double referenceAmbientVisibility(const RayScene& rays, const Vec3& x, const Vec3& n, int receiver, int samples);

// Whether the ray x + t w (t > t_min) meets an occluder other than `receiver`.
bool ambientRayOccluded(const RayScene& rays, const Vec3& x, const Vec3& w, int receiver, double t_min);

}  // namespace pvrr
