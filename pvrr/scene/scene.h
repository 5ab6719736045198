// The runtime scene shared by the reference tracer and the raster paths: environment triangle meshes with
// diffuse materials, lights, the observer, and the optical elements with their exact surfaces.
//
// Frames and units: world space, metres, double precision. Meshes keep their vertices relative to a per-mesh
// anchor (`EnvMesh::anchor`) so that huge world coordinates stay precise when converted to float for Embree
// and the GPU (camera-relative rendering subtracts the camera position from the anchor in double).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "cad/lens.h"
#include "pvrr/base/math.h"
#include "cad/tessellate.h"
#include "pvrr/optics/material.h"
#include "pvrr/scene/render_desc.h"
#include "pvrr/scene/scene_desc.h"

namespace pvrr {

// An sRGB-encoded RGB8 texture; sampled bilinearly with repeat wrapping after decoding to linear, on the CPU
// (shading.h) exactly as the GPU samples an GL_SRGB8 texture with GL_LINEAR filtering.
struct Texture {
  std::string name;
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // rows top-down as in the PNG; uv (0,0) is the bottom-left corner of the image
};

struct DiffuseMaterial {
  Vec3 color{0.8};   // linear RGB albedo (multiplies the texture)
  int texture = -1;  // index into Scene::textures, or -1
};

struct EnvMesh {
  std::string name;
  Vec3 anchor{0};                   // world position the local vertices are relative to
  std::vector<glm::vec3> positions; // relative to anchor (float: converted once, precisely, from doubles)
  std::vector<glm::vec3> normals;   // unit, world orientation
  std::vector<glm::vec2> uvs;
  std::vector<glm::u32vec3> triangles;
  int material = 0;
  // The triangles bound a convex solid and wind counter-clockwise seen from outside (makeBoxMesh,
  // makeSphereMesh): where near clipping cannot cut the solid open, its back faces are hidden by its front
  // faces, and the renderer culls them (RendererOptions::cull_back_faces).
  bool closed_convex = false;
  // The ambient occluder it belongs to (EnvObjectDesc::occluder, numbered from 0 in the order of their first
  // mesh; pvrr/trace/ambient_occlusion.h), or -1.
  int occluder = -1;
};

struct Light {
  enum class Type { Directional, Point, Ambient } type = Type::Directional;
  Vec3 direction{0, -1, 0};  // directional: the direction light travels (unit)
  Vec3 position{0};          // point
  Vec3 radiance{1};          // linear RGB, intensity folded in; point lights fall off as 1/d^2 (d in m)
  // Directional, point: occluders between a surface and the light shadow it (LightDesc::shadows). Off unless
  // set, so that a scene built in code keeps its unshadowed picture.
  bool shadows = false;
  // Directional, point: the raster modes draw its caustics (LightDesc::caustics; pvrr/gl/caustic_pass.h).
  bool caustics = false;
};

struct Observer {
  Vec3 eye{0}, target{0, 0, -1}, up{0, 1, 0};
  double fov_y_rad = radians(45);
  int width = 640, height = 480;
  Mat4 view() const;                                   // world -> camera (OpenGL conventions)
  Mat4 projection(double near_m, double far_m) const;  // OpenGL clip, symmetric
  // The projection the renderer and the reports use to decide what the observer sees (near 1 mm, far
  // 1000 km): visibilityProjection() * view() is the observer's world -> clip for visibility tests.
  Mat4 visibilityProjection() const { return projection(1e-3, 1e6); }
  // The world-space ray through pixel (x, y) with pixel centres at +0.5 and the origin at the top-left.
  Vec3 pixelDirection(double px, double py) const;
};

enum class ElementType { Mirror, Lens };

// How a mirror reflects: a constant reflectance or a conductor with complex index per RGB channel.
struct MirrorMaterial {
  bool metal = false;
  Vec3 reflectance{0.9};     // used when !metal
  Vec3 n{1.0}, k{0.0};       // conductor index per channel (R, G, B) when metal
  // A named metal's measured table (null for a plain reflectance or an explicit per-channel conductor):
  // the tracer's spectral mode reflects with metal_table->index(lambda) at each sample wavelength.
  std::shared_ptr<const Metal> metal_table;
};

struct Element {
  std::string name;
  ElementType type = ElementType::Mirror;
  Mat4 local_to_world{1.0};  // rigid pose: local +z is the element's front (towards the observer/eye)
  Mat4 world_to_local{1.0};
  bool attached_to_observer = false;
  double eye_rotation_centre_m = 0.0255;  // lens: the wearer's eye's centre of rotation behind the eye-side vertex

  // Mirror: `surface`. Lens: `lens.front` (eye side) and `lens.back`. All in local coordinates.
  cad::SurfacePtr surface;
  cad::LensSolid lens;
  cad::Outline outline;             // in the parameter plane of `surface` (or the lens's local xy)
  bool has_outline = true;

  int tess_u = 7, tess_v = 7;       // per-vertex grid of the PVRR path
  int patches_u = 1, patches_v = 1;
  // > 0: split patches until each view volume's FOV is below this. The default (kDefaultMaxPatchFovDeg,
  // chosen by measurement: docs/method.md) splits no shipped scene and the stiff ones that need it.
  double max_patch_fov_rad = kDefaultMaxPatchFovDeg * kPi / 180.0;

  MirrorMaterial mirror;
  Dispersion dispersion;            // lens material
  bool dispersion_on = false;
  // Lens: the glass's absorption coefficient per channel (R, G, B), 1/m (pvrr/optics/material.h); 0: clear.
  Vec3 absorption_per_m{0.0};
  bool absorbing() const { return absorption_per_m != Vec3(0.0); }
  // Tinted lens: its mean thickness over the outline (m), charged by the shadow rule where a line has no
  // chord through the glass (pvrr/trace/shadow_rays.h: it grazes the surface); 0 for a clear lens.
  double shadow_path_m = 0;
  // What a path of length_m inside the lens's glass keeps per channel: exp(-absorption_per_m length_m).
  Vec3 internalTransmittance(double length_m) const { return pvrr::internalTransmittance(absorption_per_m, length_m); }

  const cad::Surface& frontSurface() const { return type == ElementType::Lens ? *lens.front : *surface; }
  Vec3 toWorldPoint(const Vec3& p) const { return Vec3(local_to_world * Vec4(p, 1.0)); }
  Vec3 toWorldDir(const Vec3& d) const { return Vec3(local_to_world * Vec4(d, 0.0)); }
  Vec3 toLocalPoint(const Vec3& p) const { return Vec3(world_to_local * Vec4(p, 1.0)); }
  Vec3 toLocalDir(const Vec3& d) const { return Vec3(world_to_local * Vec4(d, 0.0)); }
};

// The scene file's render settings (their defaults are RenderDesc's) and what the build derives from the scene.
struct RenderSettings : RenderDesc {
  double far_distance_m = 1e4;  // where escaping rays get their far point
};

struct Scene {
  std::string name;            // file stem, e.g. "car-mirror"
  std::string source_path;
  Observer observer;
  std::vector<Texture> textures;
  std::vector<DiffuseMaterial> materials;
  std::vector<EnvMesh> meshes;
  std::vector<Light> lights;
  std::vector<Element> elements;
  RenderSettings render;
  // Animation (pvrr/scene/animation.h, applyAnimation in scene_build.h): the instant the animated objects and
  // elements are posed at; and per environment mesh (parallel to `meshes`; an object whose file has its own
  // materials became several meshes) the index of the scene file's environment object it was built from, and
  // its placed copy (before any motion) if that object is animated, else an empty mesh.
  // mesh_motion: per environment mesh, the rigid motion (world) that took its placed copy to where it is now
  // (identity for a mesh that is not animated): the renderer and the ray scene compare it with the motion
  // they last drew or built with, to update only what moved (issue 24's static/dynamic split).
  double time_s = 0;
  std::vector<size_t> mesh_object;
  std::vector<EnvMesh> placed_meshes;
  std::vector<Mat4> mesh_motion;
  bool meshAnimated(size_t m) const { return m < placed_meshes.size() && !placed_meshes[m].positions.empty(); }
  Mat4 meshMotion(size_t m) const { return m < mesh_motion.size() ? mesh_motion[m] : Mat4(1.0); }
  // Axis-aligned bounds of the environment (world), for far planes and escape distances. With animation:
  // of every pose the animated meshes take, at their keys and between them (animatedBounds in scene_build.cpp:
  // a rotation sweeps outside its key poses), so that they do not change with time.
  Vec3 bounds_min{0}, bounds_max{0};
  void updateBounds();
  double boundsRadius() const { return 0.5 * glm::length(bounds_max - bounds_min); }
};

// Mesh builders for the environment primitives (world-space input, doubles). UVs: per face in [0,1]
// unless `uv_scale_m` > 0, in which case u,v = distance / uv_scale_m (textures repeat).
EnvMesh makeQuadMesh(const Vec3& centre, const Vec3& normal, const Vec3& up, double width, double height,
                     double uv_scale_m = 0);
EnvMesh makeBoxMesh(const Vec3& centre, const Vec3& size, const Mat3& rotation, double uv_scale_m = 0);
EnvMesh makeSphereMesh(const Vec3& centre, double radius, int slices = 48, int stacks = 24);

}  // namespace pvrr
