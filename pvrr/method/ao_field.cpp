#include "pvrr/method/ao_field.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "pvrr/trace/ambient_occlusion.h"
#include "pvrr/trace/ray_scene.h"

namespace pvrr {

Vec2 octEncode(const Vec3& u) {
  const double l1 = std::abs(u.x) + std::abs(u.y) + std::abs(u.z);
  Vec2 p(u.x / l1, u.y / l1);
  if (u.z < 0) {
    const Vec2 sign(p.x >= 0 ? 1.0 : -1.0, p.y >= 0 ? 1.0 : -1.0);
    p = (Vec2(1.0) - Vec2(std::abs(p.y), std::abs(p.x))) * sign;
  }
  return p * 0.5 + Vec2(0.5);
}

Vec3 octDecode(Vec2 uv) {
  const Vec2 p = uv * 2.0 - Vec2(1.0);
  Vec3 v(p.x, p.y, 1.0 - std::abs(p.x) - std::abs(p.y));
  if (v.z < 0) {
    const Vec2 sign(v.x >= 0 ? 1.0 : -1.0, v.y >= 0 ? 1.0 : -1.0);
    const Vec2 q = (Vec2(1.0) - Vec2(std::abs(v.y), std::abs(v.x))) * sign;
    v.x = q.x;
    v.y = q.y;
  }
  return glm::normalize(v);
}

namespace {

// The placed copies of occluder `occluder`'s meshes as a scene of their own (no elements, one material).
Scene occluderScene(const Scene& scene, int occluder) {
  Scene s;
  s.materials.push_back(DiffuseMaterial{});
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (scene.meshes[m].occluder != occluder) continue;
    const bool animated = m < scene.placed_meshes.size() && !scene.placed_meshes[m].positions.empty();
    EnvMesh mesh = animated ? scene.placed_meshes[m] : scene.meshes[m];
    mesh.material = 0;
    s.meshes.push_back(std::move(mesh));
    s.mesh_object.push_back(0);
  }
  s.updateBounds();
  return s;
}

// The positional sample of texel (i, j) and its inward frame (t, b, inward).
struct Sample {
  Vec3 s, t, b, inward;
};
Sample positionalSample(int i, int j, int positions) {
  Sample p;
  p.s = octDecode(Vec2((i + 0.5) / positions, (j + 0.5) / positions));
  p.inward = -p.s;
  basisAround(p.inward, p.t, p.b);
  return p;
}

// The direction of texel (i, j) of a concentric map of `directions` per side, in the frame (t, b, inward).
Vec3 directionOf(const Sample& p, int i, int j, int directions) {
  const Vec3 l = malleyLift(concentricDisk(Vec2((i + 0.5) / directions * 2 - 1, (j + 0.5) / directions * 2 - 1)));
  return glm::normalize(l.x * p.t + l.y * p.b + l.z * p.inward);
}

int texelOf(double u, int n) { return std::clamp(int(std::floor(u * n)), 0, n - 1); }

// The occlusion volume of a field whose maps are built (below).
void buildVolume(AoField& f);

}  // namespace

AoField buildAoField(const Scene& scene, int occluder, int positions, int directions) {
  const auto start = std::chrono::steady_clock::now();
  AoField f;
  f.occluder = occluder;
  f.positions = positions;
  f.directions = directions;
  const Scene own = occluderScene(scene, occluder);
  Vec3 lo(kInf), hi(-kInf);
  for (const EnvMesh& m : own.meshes)
    for (const glm::vec3& p : m.positions) {
      lo = glm::min(lo, m.anchor + Vec3(p));
      hi = glm::max(hi, m.anchor + Vec3(p));
    }
  if (own.meshes.empty() || lo.x > hi.x) return f;
  f.centre = 0.5 * (lo + hi);
  for (const EnvMesh& m : own.meshes)
    for (const glm::vec3& p : m.positions) f.radius = std::max(f.radius, glm::length(m.anchor + Vec3(p) - f.centre));
  f.radius = std::max(f.radius, 1e-6) * (1 + kAoRadiusMargin);
  const int w = f.width();
  f.data.assign(size_t(w) * size_t(w), kAoMiss);
  const RayScene rays(own);
  const double diameter = 2 * f.radius;
  tbb::parallel_for(0, positions * positions, [&](int k) {
    const int i = k % positions, j = k / positions;
    const Sample p = positionalSample(i, j, positions);
    const Vec3 origin = f.centre + f.radius * p.s;
    for (int dj = 0; dj < directions; ++dj) {
      Vec3 o[RayScene::kPacketSize], d[RayScene::kPacketSize];
      RayHit hits[RayScene::kPacketSize];
      for (int di0 = 0; di0 < directions; di0 += RayScene::kPacketSize) {
        const int count = std::min(RayScene::kPacketSize, directions - di0);
        for (int q = 0; q < count; ++q) {
          o[q] = origin;
          d[q] = directionOf(p, di0 + q, dj, directions);
        }
        rays.intersectPacket(o, d, count, hits, 0, diameter, false);
        for (int q = 0; q < count; ++q) {
          if (!hits[q].hit()) continue;
          const size_t texel = size_t(j * directions + dj) * size_t(w) + size_t(i * directions + di0 + q);
          f.data[texel] = uint8_t(std::min(254.0, std::round(hits[q].t / diameter * 254)));
        }
      }
    }
  });
  buildVolume(f);
  f.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return f;
}

namespace {

// The occlusion of the field at local offset p (from the centre) for the six axis normals.
std::array<double, 6> axisOcclusion(const AoField& f, const Vec3& p) {
  std::array<double, 6> o{};
  const double dist = glm::length(p), radius = f.radius, c = dist * dist - radius * radius;
  const int side = int(std::sqrt(double(kAoVolumeRays)));
  auto add = [&](const Vec3& w, double weight) {
    for (int a = 0; a < 3; ++a) o[size_t(2 * a + (w[a] < 0))] += weight * std::abs(w[a]);
  };
  if (dist > radius) {
    const Vec3 axis = -p / dist;
    const double sin_a = radius / dist, cos_a = std::sqrt(std::max(0.0, 1 - sin_a * sin_a));
    Vec3 ta, tb;
    basisAround(axis, ta, tb);
    const double weight = 2 * (1 - cos_a) / (side * side);
    for (int i = 0; i < side; ++i)
      for (int j = 0; j < side; ++j) {
        const Vec2 d = concentricDisk(Vec2((i + 0.5) / side * 2 - 1, (j + 0.5) / side * 2 - 1));
        const double r2 = glm::dot(d, d), cos_t = 1 - r2 * (1 - cos_a), rd = std::sqrt(r2);
        const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t));
        const Vec2 around = rd > 0 ? d / rd : Vec2(0);
        const Vec3 w = cos_t * axis + sin_t * (around.x * ta + around.y * tb);
        const double b = glm::dot(p, w), disc = b * b - c;
        if (disc < 0) continue;
        const Vec3 e = p + (-b - std::sqrt(disc)) * w;
        if (fieldDistance(f, e / glm::length(e), w) < kInf) add(w, weight);
      }
  } else {
    // The whole sphere of directions, each cell of the octahedral map one (equal-area to a factor of about 2:
    // weighted by its solid angle, the Jacobian of octDecode, here by the normalisation's 1 / |v|^3).
    double total = 0;
    std::vector<std::pair<Vec3, double>> dirs;
    const int inside = kAoVolumeInsideSide;
    for (int i = 0; i < inside; ++i)
      for (int j = 0; j < inside; ++j) {
        const Vec2 uv((i + 0.5) / inside, (j + 0.5) / inside);
        const Vec2 q = uv * 2.0 - Vec2(1.0);
        const double zl = 1 - std::abs(q.x) - std::abs(q.y);
        const Vec3 v(zl >= 0 ? q.x : (1 - std::abs(q.y)) * (q.x >= 0 ? 1 : -1),
                     zl >= 0 ? q.y : (1 - std::abs(q.x)) * (q.y >= 0 ? 1 : -1), zl);
        const double l = glm::length(v);
        dirs.push_back({v / l, 1 / (l * l * l)});
        total += 1 / (l * l * l);
      }
    for (const auto& [w, jac] : dirs) {
      const double b = glm::dot(p, w);
      const double t_exit = -b + std::sqrt(std::max(0.0, b * b - c));
      const Vec3 e = p + t_exit * w;
      if (fieldDistance(f, e / glm::length(e), -w) < t_exit) add(w, 4 * jac / total);  // 4 pi / pi
    }
  }
  for (double& v : o) v = std::min(1.0, v);
  return o;
}

void buildVolume(AoField& f) {
  const int n = kAoVolumeSize;
  f.volume.assign(size_t(n) * size_t(n) * size_t(n) * 8, 0);
  tbb::parallel_for(0, n * n, [&](int jk) {
    const int j = jk % n, k = jk / n;
    for (int i = 0; i < n; ++i) {
      const Vec3 t(2 * (i + 0.5) / n - 1, 2 * (j + 0.5) / n - 1, 2 * (k + 0.5) / n - 1);
      const Vec3 p(aoUnwarp(t.x, f.radius), aoUnwarp(t.y, f.radius), aoUnwarp(t.z, f.radius));
      const std::array<double, 6> o = axisOcclusion(f, p);
      uint8_t* texel = &f.volume[(size_t(k) * size_t(n) * size_t(n) + size_t(j) * size_t(n) + size_t(i)) * 8];
      for (int a = 0; a < 6; ++a) texel[a] = uint8_t(std::lround(o[size_t(a)] * 255));
    }
  });
  // The reach: past every grid point whose occlusion (fade included) is not negligible, by one cell outward on
  // each axis (trilinear reads mix it into the cells around it).
  f.reach = 0;
  auto outward = [&](int i) {  // the offset of grid index i moved one cell away from the centre
    const int o = std::clamp(2 * i + 1 < n ? i - 1 : i + 1, 0, n - 1);
    return std::max(std::abs(aoUnwarp(2 * (i + 0.5) / n - 1, f.radius)), std::abs(aoUnwarp(2 * (o + 0.5) / n - 1, f.radius)));
  };
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const uint8_t* texel = &f.volume[(size_t(k) * size_t(n) * size_t(n) + size_t(j) * size_t(n) + size_t(i)) * 8];
        const Vec3 p(aoUnwarp(2 * (i + 0.5) / n - 1, f.radius), aoUnwarp(2 * (j + 0.5) / n - 1, f.radius),
                     aoUnwarp(2 * (k + 0.5) / n - 1, f.radius));
        const double fade = aoFade(f.radius * f.radius / std::max(glm::dot(p, p), 1e-300));
        const uint8_t most = *std::max_element(texel, texel + 6);
        if (fade * most / 255.0 < kAoNegligible) continue;
        f.reach = std::max(f.reach, glm::length(Vec3(outward(i), outward(j), outward(k))));
      }
}

}  // namespace

std::vector<uint8_t> groundMap(const AoField& f, double height) {
  const int n = kAoGroundSize;
  std::vector<uint8_t> map(size_t(n) * size_t(n), 0);
  if (f.volume.empty()) return map;
  const double y = height - f.centre.y;
  tbb::parallel_for(0, n, [&](int k) {
    for (int i = 0; i < n; ++i) {
      const Vec3 p(aoUnwarp(2 * (i + 0.5) / n - 1, f.radius), y, aoUnwarp(2 * (k + 0.5) / n - 1, f.radius));
      const double fade = aoFade(f.radius * f.radius / std::max(glm::dot(p, p), 1e-300));
      if (fade <= 0) continue;
      map[size_t(k) * size_t(n) + size_t(i)] = uint8_t(std::lround(fade * axisOcclusion(f, p)[2] * 255));
    }
  });
  return map;
}

double groundMapOcclusion(const AoField& f, const std::vector<uint8_t>& map, const Mat4& motion, const Vec3& x) {
  if (map.empty()) return 0;
  const Vec3 p = glm::transpose(Mat3(motion)) * (x - Vec3(motion[3])) - f.centre;
  const int n = kAoGroundSize;
  double g[2], fr[2];
  int i0[2];
  const double offsets[2] = {p.x, p.z};
  for (int a = 0; a < 2; ++a) {
    g[a] = std::clamp((aoWarp(offsets[a], f.radius) + 1) / 2 * n - 0.5, 0.0, double(n - 1));
    i0[a] = std::min(int(std::floor(g[a])), n - 2);
    fr[a] = g[a] - i0[a];
  }
  double o = 0;
  for (int c = 0; c < 4; ++c) {
    const int dx = c & 1, dz = c >> 1;
    o += (dx ? fr[0] : 1 - fr[0]) * (dz ? fr[1] : 1 - fr[1]) *
         map[size_t(i0[1] + dz) * size_t(n) + size_t(i0[0] + dx)] / 255.0;
  }
  return o;
}

std::array<double, 6> volumeCube(const AoField& f, const Mat4& motion, const Vec3& x_world) {
  std::array<double, 6> o{};
  if (f.volume.empty()) return o;
  const Vec3 p = glm::transpose(Mat3(motion)) * (x_world - Vec3(motion[3])) - f.centre;
  const double fade = aoFade(f.radius * f.radius / std::max(glm::dot(p, p), 1e-300));
  if (fade <= 0) return o;
  const int sz = kAoVolumeSize;
  // Trilinear between grid points at texture coordinates (i + 0.5) / n, clamped at the outermost (GL's
  // GL_LINEAR with GL_CLAMP_TO_EDGE).
  double g[3];
  int i0[3];
  double fr[3];
  for (int a = 0; a < 3; ++a) {
    g[a] = std::clamp((aoWarp(p[a], f.radius) + 1) / 2 * sz - 0.5, 0.0, double(sz - 1));
    i0[a] = std::min(int(std::floor(g[a])), sz - 2);
    fr[a] = g[a] - i0[a];
  }
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
    const double w = (dx ? fr[0] : 1 - fr[0]) * (dy ? fr[1] : 1 - fr[1]) * (dz ? fr[2] : 1 - fr[2]);
    const uint8_t* texel =
        &f.volume[(size_t(i0[2] + dz) * size_t(sz) * size_t(sz) + size_t(i0[1] + dy) * size_t(sz) + size_t(i0[0] + dx)) * 8];
    for (size_t a = 0; a < 6; ++a) o[a] += w * texel[a] / 255.0;
  }
  for (double& v : o) v *= fade;
  return o;
}

double cubeOcclusion(const std::array<double, 6>& o, const Vec3& n) {
  double sum = 0;
  for (int a = 0; a < 3; ++a) sum += n[a] * n[a] * o[size_t(2 * a + (n[a] < 0))];
  return sum;
}

double volumeOcclusion(const AoField& f, const Mat4& motion, const Vec3& x_world, const Vec3& n_world) {
  if (f.volume.empty()) return 0;
  return cubeOcclusion(volumeCube(f, motion, x_world), glm::transpose(Mat3(motion)) * n_world);
}

double volumeVisibility(const std::vector<AoField>& fields, const Scene& scene, const Vec3& x, const Vec3& n,
                        int receiver) {
  double occluded = 0;
  for (const AoField& f : fields)
    if (f.occluder != receiver) occluded += volumeOcclusion(f, occluderMotion(scene, f.occluder), x, n);
  return std::max(0.0, 1 - std::min(1.0, occluded));
}

std::vector<AoField> buildAoFields(const Scene& scene) {
  std::vector<AoField> fields;
  const AmbientOcclusionDesc& a = scene.render.ambient_occlusion;
  for (int o = 0; o < occluderCount(scene); ++o) fields.push_back(buildAoField(scene, o, a.positions, a.directions));
  return fields;
}

double fieldDistance(const AoField& f, const Vec3& s, const Vec3& w) {
  const Vec2 uv = octEncode(s);
  const int i = texelOf(uv.x, f.positions), j = texelOf(uv.y, f.positions);
  const Sample p = positionalSample(i, j, f.positions);
  Vec2 disk(glm::dot(w, p.t), glm::dot(w, p.b));
  const double r = glm::length(disk);
  if (r > 1) disk /= r;  // a ray that grazes the sphere at a neighbouring sample: the map's rim
  const Vec2 sq = concentricSquare(disk);
  const int di = texelOf((sq.x + 1) / 2, f.directions), dj = texelOf((sq.y + 1) / 2, f.directions);
  const uint8_t v = f.data[size_t(j * f.directions + dj) * size_t(f.width()) + size_t(i * f.directions + di)];
  return v == kAoMiss ? kInf : v / 254.0 * 2 * f.radius;
}

double fieldOcclusion(const AoField& f, const Mat4& motion, const Vec3& x_world, const Vec3& n_world, int samples) {
  const Mat3 r(motion);
  const Vec3 t(motion[3]);
  const Vec3 x = glm::transpose(r) * (x_world - t), n = glm::transpose(r) * n_world;
  const Vec3 p = x - f.centre;
  const double dist = glm::length(p), radius = f.radius;
  const int side = std::max(1, int(std::ceil(std::sqrt(double(samples)))));
  const double c = dist * dist - radius * radius;
  double occluded = 0;
  if (dist > radius) {
    const Vec3 axis = -p / dist;
    const double sin_a = radius / dist, cos_a = std::sqrt(std::max(0.0, 1 - sin_a * sin_a));
    if (sin_a * sin_a < kAoMinCone || glm::dot(n, axis) < -sin_a) return 0;  // too small, or below the horizon
    Vec3 ta, tb;
    basisAround(axis, ta, tb);
    const double weight = 2 * (1 - cos_a) / (side * side);  // solid angle / pi per sample
    for (int i = 0; i < side; ++i)
      for (int j = 0; j < side; ++j) {
        const Vec2 d = concentricDisk(Vec2((i + 0.5) / side * 2 - 1, (j + 0.5) / side * 2 - 1));
        const double r2 = glm::dot(d, d), cos_t = 1 - r2 * (1 - cos_a);
        const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t)), rd = std::sqrt(r2);
        const Vec2 around = rd > 0 ? d / rd : Vec2(0);
        const Vec3 w = cos_t * axis + sin_t * (around.x * ta + around.y * tb);
        const double cos_n = glm::dot(w, n);
        if (cos_n <= 0) continue;
        const double b = glm::dot(p, w), disc = b * b - c;
        if (disc < 0) continue;
        const Vec3 e = p + (-b - std::sqrt(disc)) * w;
        if (fieldDistance(f, e / glm::length(e), w) < kInf) occluded += weight * cos_n;
      }
    return std::min(1.0, occluded);
  }
  Vec3 tn, bn;
  basisAround(n, tn, bn);
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) {
      const Vec3 l = malleyLift(concentricDisk(Vec2((i + 0.5) / side * 2 - 1, (j + 0.5) / side * 2 - 1)));
      const Vec3 w = glm::normalize(l.x * tn + l.y * bn + l.z * n);
      const double b = glm::dot(p, w);
      const double t_exit = -b + std::sqrt(std::max(0.0, b * b - c));
      const Vec3 e = p + t_exit * w;
      if (fieldDistance(f, e / glm::length(e), -w) < t_exit) occluded += 1;
    }
  return occluded / (side * side);
}

Mat4 occluderMotion(const Scene& scene, int occluder) {
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    if (scene.meshes[m].occluder == occluder) return scene.meshMotion(m);
  return Mat4(1.0);
}

double fieldVisibility(const std::vector<AoField>& fields, const Scene& scene, const Vec3& x, const Vec3& n,
                       int receiver, int samples) {
  double occluded = 0;
  for (const AoField& f : fields)
    if (f.occluder != receiver && !f.data.empty())
      occluded += fieldOcclusion(f, occluderMotion(scene, f.occluder), x, n, samples);
  return std::max(0.0, 1 - occluded);
}

}  // namespace pvrr
