// Curved receivers for the caustic tests (docs/caustics.md "Curved receivers"): meshes that are height fields
// over a plane, built in code with their exact surface beside them. Header-only.
#pragma once
#include <cmath>
#include <functional>

#include "pvrr/scene/scene.h"
#include "support/test_scenes.h"

namespace pvrr::test {

// A height field over a plane: the point base + x u + y v + height(x, y) n for |x| <= half_x, |y| <= half_y, on
// a grid of cells_x x cells_y quads (two triangles each), vertex normals from the height's exact gradient
// (gradient(x, y) = (dh/dx, dh/dy)). n, u unit and orthogonal; v = n x u.
struct HeightField {
  Vec3 base{0}, n{0, 0, 1}, u{1, 0, 0};
  double half_x = 0.05, half_y = 0.05;
  std::function<double(double, double)> height;
  std::function<Vec2(double, double)> gradient;
  Vec3 v() const { return glm::cross(n, u); }
  Vec3 point(double x, double y) const { return base + x * u + y * v() + height(x, y) * n; }
  Vec3 normal(double x, double y) const {
    const Vec2 g = gradient(x, y);
    return glm::normalize(n - g.x * u - g.y * v());
  }
};

inline EnvMesh heightFieldMesh(const HeightField& f, int cells_x, int cells_y, const std::string& name) {
  EnvMesh m;
  m.name = name;
  m.anchor = f.base;
  for (int j = 0; j <= cells_y; ++j)
    for (int i = 0; i <= cells_x; ++i) {
      const double x = -f.half_x + 2 * f.half_x * i / cells_x, y = -f.half_y + 2 * f.half_y * j / cells_y;
      m.positions.push_back(glm::vec3(f.point(x, y) - f.base));
      m.normals.push_back(glm::vec3(f.normal(x, y)));
      m.uvs.push_back(glm::vec2(float(i) / cells_x, float(j) / cells_y));
    }
  for (int j = 0; j < cells_y; ++j)
    for (int i = 0; i < cells_x; ++i) {
      const uint32_t a = uint32_t(j * (cells_x + 1) + i), b = a + 1, c = a + uint32_t(cells_x) + 2,
                     d = a + uint32_t(cells_x) + 1;
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({a, c, d});
    }
  return m;
}

// A spherical bowl: the sphere of radius r whose lowest point is `base`, concave towards +n:
// height = r - sqrt(r^2 - x^2 - y^2).
inline HeightField sphericalBowl(const Vec3& base, const Vec3& n, const Vec3& u, double r, double half) {
  HeightField f;
  f.base = base, f.n = n, f.u = u, f.half_x = f.half_y = half;
  f.height = [r](double x, double y) { return r - std::sqrt(r * r - x * x - y * y); };
  f.gradient = [r](double x, double y) {
    const double s = std::sqrt(r * r - x * x - y * y);
    return Vec2(x / s, y / s);
  };
  return f;
}

// A cylinder segment of radius r whose axis runs along v, its lowest line through `base`, concave towards +n
// (convex: r < 0 bulges towards +n): height = sign(r) (|r| - sqrt(r^2 - x^2)).
inline HeightField cylinderSegment(const Vec3& base, const Vec3& n, const Vec3& u, double r, double half_x,
                                   double half_y) {
  HeightField f;
  f.base = base, f.n = n, f.u = u, f.half_x = half_x, f.half_y = half_y;
  const double a = std::abs(r), sign = r < 0 ? -1.0 : 1.0;
  f.height = [a, sign](double x, double) { return sign * (a - std::sqrt(a * a - x * x)); };
  f.gradient = [a, sign](double x, double) { return Vec2(sign * x / std::sqrt(a * a - x * x), 0.0); };
  return f;
}

// Waves of amplitude `a` (metres) and wavelength 20 mm along the plane's u, over 240 x 120 mm of a plane at
// x = 0.4 tilted 20 deg from facing the beam along +x: the grazing receiver of the caustic tests (a = 0: the same
// plane flat).
inline HeightField grazingWaves(double a) {
  const Vec3 n = glm::normalize(Vec3(-0.342, 0, 0.940));
  const Vec3 beam(1, 0, 0);
  HeightField f;
  f.base = Vec3(0.4, 0, 0), f.n = n, f.u = glm::normalize(beam - glm::dot(beam, n) * n);
  f.half_x = 0.12, f.half_y = 0.06;
  const double k = 2 * kPi / 0.02;
  f.height = [=](double x, double) { return a * std::sin(k * x); };
  f.gradient = [=](double x, double) { return Vec2(a * k * std::cos(k * x), 0.0); };
  return f;
}

// The beam scenes of the curved-receiver tests: the height field's mesh (diffuse) as receiver, the sun straight
// down (-z, radiance 1) with caustics on, and a plane mirror of radius `mirror_radius` at the origin facing
// (1, 0, 1), which turns the sun's light along +x onto the receiver.
inline void addBeamOnReceiver(Scene& s, const HeightField& f, int cells_x, int cells_y, const std::string& name,
                              double mirror_radius = 0.1, double reflectance = 0.9) {
  s.meshes.push_back(heightFieldMesh(f, cells_x, cells_y, name));
  s.materials.push_back(DiffuseMaterial{});
  Light sun;
  sun.direction = Vec3(0, 0, -1);
  sun.caustics = true;
  s.lights = {sun};
  const cad::Outline disc = cad::Outline::circle(mirror_radius);
  addMirror(s, cad::makePlane(disc), disc, pose(Vec3(0), glm::normalize(Vec3(1, 0, 1))), 7, reflectance);
}

}  // namespace pvrr::test
