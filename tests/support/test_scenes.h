// Small scenes built in code for tests whose expectations are analytic. Header-only.
#pragma once
#include "cad/lens.h"
#include "cad/sag.h"
#include "pvrr/scene/scene.h"

namespace pvrr::test {

// Local frame -> world for an element whose local +z is `normal` and local +y follows `up`.
inline Mat4 pose(const Vec3& position, const Vec3& normal, const Vec3& up = Vec3(0, 1, 0)) {
  const Vec3 z = glm::normalize(normal);
  const Vec3 y = glm::normalize(up - glm::dot(up, z) * z);
  const Vec3 x = glm::cross(y, z);
  Mat4 m(1.0);
  m[0] = Vec4(x, 0);
  m[1] = Vec4(y, 0);
  m[2] = Vec4(z, 0);
  m[3] = Vec4(position, 1);
  return m;
}

inline void addMirror(Scene& s, cad::SagSurfacePtr surface, const cad::Outline& outline, const Mat4& local_to_world,
                      int tess = 7, double reflectance = 1.0) {
  Element e;
  e.name = "mirror" + std::to_string(s.elements.size());
  e.type = ElementType::Mirror;
  e.surface = surface;
  e.outline = outline;
  e.local_to_world = local_to_world;
  e.world_to_local = glm::inverse(local_to_world);
  e.tess_u = e.tess_v = tess;
  e.mirror.reflectance = Vec3(reflectance);
  s.elements.push_back(e);
}

// A room-like box of quads around the origin (inward-facing walls, a checker-free flat colour per wall),
// ambient + one directional light, observer at `eye` looking at `target`.
inline Scene roomScene(const Vec3& eye, const Vec3& target, int width = 96, int height = 72) {
  Scene s;
  s.name = "test-room";
  s.observer.eye = eye;
  s.observer.target = target;
  s.observer.up = Vec3(0, 1, 0);
  s.observer.fov_y_rad = radians(40);
  s.observer.width = width;
  s.observer.height = height;
  const double half = 3.0;
  const Vec3 colours[6] = {{0.8, 0.2, 0.2}, {0.2, 0.8, 0.2}, {0.2, 0.2, 0.8}, {0.8, 0.8, 0.2}, {0.2, 0.8, 0.8}, {0.8, 0.2, 0.8}};
  const Vec3 normals[6] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  for (int i = 0; i < 6; ++i) {
    const Vec3 n = normals[i];
    const Vec3 up = std::abs(n.y) > 0.5 ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
    EnvMesh m = makeQuadMesh(-half * n, n, up, 2 * half, 2 * half);
    m.material = i;
    s.meshes.push_back(m);
    s.materials.push_back(DiffuseMaterial{colours[i], -1});
  }
  // A small box inside the room, for depth edges.
  EnvMesh box = makeBoxMesh(Vec3(0.8, -0.5, -1.5), Vec3(0.6, 0.8, 0.5), Mat3(1.0));
  box.material = 0;
  s.meshes.push_back(box);
  Light amb;
  amb.type = Light::Type::Ambient;
  amb.radiance = Vec3(0.3);
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = glm::normalize(Vec3(-0.3, -1, -0.5));
  sun.radiance = Vec3(0.7);
  s.lights = {amb, sun};
  s.updateBounds();
  s.render.far_distance_m = 1e4;
  return s;
}

// The room seen through a lens with outline `disc` (n = 1.5, no dispersion, 24 x 24 vertices) at z = 2 m facing
// +z, from `eye` towards `target` with an 8 deg field: by default 0.5 m in front of the lens, looking through
// it at the far wall 5 m away.
inline Scene roomLensScene(const char* name, cad::SagSurfacePtr front, cad::SagSurfacePtr back, double thickness,
                           const cad::Outline& disc, const Vec3& eye = Vec3(0, 0, 2.5),
                           const Vec3& target = Vec3(0, 0, -3)) {
  Scene s = roomScene(eye, target, 160, 120);
  s.observer.fov_y_rad = radians(8);
  Element e;
  e.name = name;
  e.type = ElementType::Lens;
  e.lens = cad::makeLens(front, back, disc, thickness, 0.0, name);
  e.outline = disc;
  e.local_to_world = pose(Vec3(0, 0, 2.0), Vec3(0, 0, 1));
  e.world_to_local = glm::inverse(e.local_to_world);
  e.dispersion = Dispersion::constant(1.5);
  e.tess_u = e.tess_v = 24;
  s.elements.push_back(e);
  s.updateBounds();
  return s;
}

}  // namespace pvrr::test
