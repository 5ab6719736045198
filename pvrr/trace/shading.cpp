#include "pvrr/trace/shading.h"

#include "pvrr/base/image.h"

#include <cmath>

namespace pvrr {
namespace {

int wrap(int i, int n) {
  int r = i % n;
  return r < 0 ? r + n : r;
}

}  // namespace

Vec3 sampleTexture(const Texture& t, Vec2 uv) {
  if (t.width <= 0 || t.height <= 0) return Vec3(1.0);
  // GL texel centres are at (i + 0.5) / size; v = 0 is the bottom row (the last row in memory).
  double x = uv.x * t.width - 0.5;
  double y = uv.y * t.height - 0.5;
  double fx = std::floor(x), fy = std::floor(y);
  double ax = x - fx, ay = y - fy;
  int x0 = wrap(int(fx), t.width), x1 = wrap(int(fx) + 1, t.width);
  int y0 = wrap(int(fy), t.height), y1 = wrap(int(fy) + 1, t.height);
  auto texel = [&](int xi, int yi) {
    const uint8_t* p = &t.rgb[(size_t(t.height - 1 - yi) * t.width + xi) * 3];
    return Vec3(srgb8ToLinear(p[0]), srgb8ToLinear(p[1]), srgb8ToLinear(p[2]));
  };
  Vec3 c0 = glm::mix(texel(x0, y0), texel(x1, y0), ax);
  Vec3 c1 = glm::mix(texel(x0, y1), texel(x1, y1), ax);
  return glm::mix(c0, c1, ay);
}

Vec3 shadeDiffuse(const Scene& scene, const DiffuseMaterial& m, const Vec3& p, const Vec3& n, Vec2 uv,
                  const ShadowRays* shadows, double ambient_visibility, const Vec3& caustic) {
  Vec3 albedo = m.color;
  if (m.texture >= 0) albedo *= sampleTexture(scene.textures[size_t(m.texture)], uv);
  Vec3 light(0.0);
  for (const Light& l : scene.lights) {
    switch (l.type) {
      case Light::Type::Ambient:
        light += ambient_visibility * l.radiance;
        break;
      case Light::Type::Directional: {
        const double cos_l = -glm::dot(n, l.direction);
        if (cos_l > 0) light += cos_l * l.radiance * (shadows ? shadows->transmittance(l, p) : Vec3(1.0));
        break;
      }
      case Light::Type::Point: {
        Vec3 to = l.position - p;
        double d2 = glm::dot(to, to);
        const double cos_l = d2 > 0 ? glm::dot(n, to) / std::sqrt(d2) : 0.0;
        if (cos_l > 0) light += cos_l / d2 * l.radiance * (shadows ? shadows->transmittance(l, p) : Vec3(1.0));
        break;
      }
    }
  }
  return albedo * (light + caustic);
}

}  // namespace pvrr
