#include "pvrr/scene/scene.h"

#include <glm/gtc/matrix_transform.hpp>

namespace pvrr {

Mat4 Observer::view() const { return glm::lookAt(eye, target, up); }

Mat4 Observer::projection(double near_m, double far_m) const {
  return glm::perspective(fov_y_rad, double(width) / double(height), near_m, far_m);
}

Vec3 Observer::pixelDirection(double px, double py) const {
  Vec3 f = glm::normalize(target - eye);
  Vec3 r = glm::normalize(glm::cross(f, up));
  Vec3 u = glm::cross(r, f);
  double th = std::tan(0.5 * fov_y_rad);
  double aspect = double(width) / double(height);
  double x = (2.0 * px / width - 1.0) * th * aspect;
  double y = (1.0 - 2.0 * py / height) * th;
  return glm::normalize(f + x * r + y * u);
}

void Scene::updateBounds() {
  bounds_min = Vec3(kInf);
  bounds_max = Vec3(-kInf);
  auto add = [&](const Vec3& p) {
    bounds_min = glm::min(bounds_min, p);
    bounds_max = glm::max(bounds_max, p);
  };
  for (const EnvMesh& m : meshes)
    for (const glm::vec3& p : m.positions) add(m.anchor + Vec3(p));
  for (const Element& e : elements) add(Vec3(e.local_to_world[3]));
  add(observer.eye);
}

namespace {

// Appends a quad (4 vertices, 2 triangles, CCW seen from `normal`) to a mesh whose anchor is set.
void appendQuad(EnvMesh& m, const Vec3& centre, const Vec3& normal, const Vec3& up, double w, double h,
                double uv_scale_m) {
  Vec3 n = glm::normalize(normal);
  Vec3 v = glm::normalize(up - glm::dot(up, n) * n);
  Vec3 u = glm::cross(v, n);
  uint32_t base = uint32_t(m.positions.size());
  const double su = uv_scale_m > 0 ? w / uv_scale_m : 1.0;
  const double sv = uv_scale_m > 0 ? h / uv_scale_m : 1.0;
  const double corners[4][2] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
  for (const auto& c : corners) {
    Vec3 p = centre + c[0] * w * u + c[1] * h * v;
    m.positions.push_back(glm::vec3(p - m.anchor));
    m.normals.push_back(glm::vec3(n));
    m.uvs.push_back(glm::vec2(float((c[0] + 0.5) * su), float((c[1] + 0.5) * sv)));
  }
  m.triangles.push_back({base, base + 1, base + 2});
  m.triangles.push_back({base, base + 2, base + 3});
}

}  // namespace

EnvMesh makeQuadMesh(const Vec3& centre, const Vec3& normal, const Vec3& up, double width, double height,
                     double uv_scale_m) {
  EnvMesh m;
  m.anchor = centre;
  appendQuad(m, centre, normal, up, width, height, uv_scale_m);
  return m;
}

EnvMesh makeBoxMesh(const Vec3& centre, const Vec3& size, const Mat3& rotation, double uv_scale_m) {
  EnvMesh m;
  m.anchor = centre;
  const Vec3 ax[3] = {rotation[0], rotation[1], rotation[2]};
  const Vec3 half = 0.5 * size;
  // Faces +x, -x, +y, -y, +z, -z; `up` is a face-local vertical (world +y where possible).
  for (int a = 0; a < 3; ++a) {
    for (int s = -1; s <= 1; s += 2) {
      Vec3 n = double(s) * ax[a];
      Vec3 up = a == 1 ? ax[2] : ax[1];
      double w = a == 0 ? size.z : size.x;
      double h = a == 1 ? size.z : size.y;
      appendQuad(m, centre + half[a] * n, n, up, w, h, uv_scale_m);
    }
  }
  // A closed solid only with a positive size (a negative one faces its quads inward) and orthonormal axes
  // (each face builds its own frame from its normal, so a reflection still winds outward).
  bool orthonormal = true;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) orthonormal = orthonormal && std::abs(glm::dot(ax[a], ax[b]) - (a == b)) < 1e-9;
  m.closed_convex = size.x > 0 && size.y > 0 && size.z > 0 && orthonormal;
  return m;
}

EnvMesh makeSphereMesh(const Vec3& centre, double radius, int slices, int stacks) {
  EnvMesh m;
  m.anchor = centre;
  for (int i = 0; i <= stacks; ++i) {
    double th = kPi * i / stacks;
    for (int j = 0; j <= slices; ++j) {
      double ph = 2 * kPi * j / slices;
      Vec3 n(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph));
      m.positions.push_back(glm::vec3(radius * n));
      m.normals.push_back(glm::vec3(n));
      m.uvs.push_back(glm::vec2(float(double(j) / slices), float(1.0 - double(i) / stacks)));
    }
  }
  const uint32_t row = uint32_t(slices + 1);
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      uint32_t a = uint32_t(i) * row + uint32_t(j), b = a + row;
      if (i > 0) m.triangles.push_back({a, b, a + 1});
      if (i < stacks - 1) m.triangles.push_back({a + 1, b, b + 1});
    }
  }
  m.closed_convex = radius > 0 && slices >= 3 && stacks >= 2;
  return m;
}

}  // namespace pvrr
