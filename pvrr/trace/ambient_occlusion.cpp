#include "pvrr/trace/ambient_occlusion.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace pvrr {

Vec2 concentricDisk(Vec2 s) {
  if (s.x == 0 && s.y == 0) return Vec2(0);
  double r, phi;
  if (std::abs(s.x) > std::abs(s.y)) {
    r = s.x;
    phi = kPi / 4 * (s.y / s.x);
  } else {
    r = s.y;
    phi = kPi / 2 - kPi / 4 * (s.x / s.y);
  }
  return r * Vec2(std::cos(phi), std::sin(phi));
}

Vec2 concentricSquare(Vec2 d) {
  const double r = std::sqrt(d.x * d.x + d.y * d.y);
  if (r == 0) return Vec2(0);
  double psi = std::atan2(d.y, d.x);         // (-pi, pi]
  if (psi < -kPi / 4) psi += 2 * kPi;         // [-pi/4, 7 pi/4)
  const double k = 4 / kPi;
  if (psi < kPi / 4) return Vec2(r, k * psi * r);
  if (psi < 3 * kPi / 4) return Vec2(k * (kPi / 2 - psi) * r, r);
  if (psi < 5 * kPi / 4) return Vec2(-r, -k * (psi - kPi) * r);
  return Vec2(-k * (3 * kPi / 2 - psi) * r, -r);
}

void basisAround(const Vec3& n, Vec3& t, Vec3& b) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double c = n.x * n.y * a;
  t = Vec3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = Vec3(c, sign + n.y * n.y * a, -n.y);
}

int occluderOfMesh(const Scene& scene, int mesh) {
  if (mesh < 0 || size_t(mesh) >= scene.meshes.size()) return -1;
  return scene.meshes[size_t(mesh)].occluder;
}

int occluderCount(const Scene& scene) {
  int n = 0;
  for (const EnvMesh& m : scene.meshes) n = std::max(n, m.occluder + 1);
  return n;
}

bool ambientRayOccluded(const RayScene& rays, const Vec3& x, const Vec3& w, int receiver, double t_min) {
  const Scene& scene = rays.scene();
  // Past what lets the ray through (a mesh that does not occlude, the receiver's own object, an element),
  // a bounded number of times: a ray that passes more is counted unoccluded.
  constexpr int kMaxPassThrough = 64;
  for (int i = 0; i < kMaxPassThrough; ++i) {
    const RayHit hit = rays.intersect(x, w, t_min);
    if (!hit.hit()) return false;
    if (hit.kind == HitKind::Environment) {
      const int occluder = occluderOfMesh(scene, hit.mesh);
      if (occluder >= 0 && occluder != receiver) return true;
    }
    t_min = hit.t + rays.epsilon();
  }
  return false;
}

namespace {

// A hash of the point's bits and a counter to [0, 1): the sample pattern's jitter, fixed per point.
double pointHash(const Vec3& x, uint64_t k) {
  uint64_t h = 1469598103934665603ull ^ (k * 0x9e3779b97f4a7c15ull);
  for (int c = 0; c < 3; ++c) {
    uint64_t bits;
    const double v = x[c];
    std::memcpy(&bits, &v, sizeof bits);
    h = (h ^ bits) * 1099511628211ull;
    h ^= h >> 29;
  }
  h *= 0xbf58476d1ce4e5b9ull;
  h ^= h >> 31;
  return double(h >> 11) * (1.0 / 9007199254740992.0);
}

}  // namespace

double referenceAmbientVisibility(const RayScene& rays, const Vec3& x, const Vec3& n, int receiver, int samples) {
  if (occluderCount(rays.scene()) == 0) return 1.0;
  const int side = std::max(1, int(std::ceil(std::sqrt(double(samples)))));
  Vec3 t, b;
  basisAround(n, t, b);
  const double t_min = rays.epsilon();
  int open = 0;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) {
      const uint64_t k = uint64_t(i * side + j);
      const Vec2 sq((i + pointHash(x, 2 * k)) / side * 2 - 1, (j + pointHash(x, 2 * k + 1)) / side * 2 - 1);
      const Vec3 l = malleyLift(concentricDisk(sq));
      const Vec3 w = glm::normalize(l.x * t + l.y * b + l.z * n);
      open += !ambientRayOccluded(rays, x, w, receiver, t_min);
    }
  return double(open) / double(side * side);
}

}  // namespace pvrr
