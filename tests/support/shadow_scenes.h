// Scenes with closed-form shadows, shared by the reference's shadow-ray tests (tests/pvrr/trace) and the
// raster shadow-map tests (tests/gl/shadow): an occluder over a ground plane y = 0 under one light, and the
// outline of its shadow on the ground in closed form.
#pragma once
#include <cmath>
#include <string>

#include "pvrr/scene/scene_build.h"
#include "pvrr/scene/scene_json.h"

namespace pvrr::test {

// Sphere of radius kSphereRadius at kSphereCentre; horizontal square quad of side kQuadSide at height
// kQuadHeight centred on the y axis.
inline const Vec3 kSphereCentre(0.1, 0.5, -0.1);
constexpr double kSphereRadius = 0.2;
constexpr double kQuadSide = 0.4, kQuadHeight = 1.0;

// occluder: "sphere" or "quad"; light: one light's JSON object; elements: the "elements" array's contents.
inline Scene shadowScene(const std::string& occluder, const std::string& light, const std::string& elements = "",
                         int width = 160, int height = 120) {
  const std::string sphere = R"({"type": "sphere", "name": "ball", "centre": [0.1, 0.5, -0.1], "radius": 0.2,
                                 "material": {"color": [0.8, 0.3, 0.2]}})";
  const std::string quad = R"({"type": "quad", "name": "slab", "centre": [0, 1.0, 0], "normal": [0, 1, 0],
                               "up": [0, 0, -1], "size": [0.4, 0.4], "material": {"color": [0.3, 0.8, 0.2]}})";
  const std::string text = R"({"version": 1, "units": "m",
    "observer": {"eye": [0, 3.2, 1.6], "target": [0, 0, 0], "fov_y_deg": 50, "image_size": [)" +
                           std::to_string(width) + ", " + std::to_string(height) + R"(]},
    "environment": [
      {"type": "ground", "name": "floor", "point": [0, 0, 0], "normal": [0, 1, 0], "size": [6, 6],
       "material": {"color": [0.7, 0.7, 0.7]}},
      )" + (occluder == "sphere" ? sphere : quad) +
                           R"(],
    "lights": [)" + light + R"(, {"type": "ambient", "color": [0.2, 0.2, 0.2]}],
    "elements": [)" + elements +
                           R"(],
    "render": {"background": [0, 0, 0]}})";
  Scene s = buildScene(parseScene(text, "shadow-scene", ""));
  s.updateBounds();
  return s;
}

// Whether ground point g (y = 0) lies in the sphere's shadow under a directional light travelling along d
// (unit): the shadow is an ellipse centred where the line through the sphere's centre along d meets the
// ground, with semi-axis r across the light's horizontal direction and r / |d.y| along it. Returns the
// ellipse's normalised radius (< 1 inside), so that callers can leave out a band around the outline.
inline double sphereShadowRadius(const Vec3& d, const Vec3& g) {
  const Vec3 c = kSphereCentre + (-kSphereCentre.y / d.y) * d;
  const Vec3 h = glm::length(Vec3(d.x, 0, d.z)) > 0 ? glm::normalize(Vec3(d.x, 0, d.z)) : Vec3(1, 0, 0);
  const Vec3 across(-h.z, 0, h.x);
  const Vec3 q = g - c;
  const double a = kSphereRadius / std::abs(d.y), b = kSphereRadius;
  return std::sqrt((glm::dot(q, h) / a) * (glm::dot(q, h) / a) + (glm::dot(q, across) / b) * (glm::dot(q, across) / b));
}

// The quad's shadow under a point light at `light` (above the quad): the square scaled about the light by
// similar triangles, s = H / (H - h), H the light's height and h the quad's. Returns the Chebyshev distance
// of ground point g from the shadow's centre over its half side (< 1 inside).
inline double quadShadowRadius(const Vec3& light, const Vec3& g) {
  const double s = light.y / (light.y - kQuadHeight);
  const Vec3 centre = light + s * (Vec3(0, kQuadHeight, 0) - light);
  const double half = 0.5 * kQuadSide * s;
  return std::max(std::abs(g.x - centre.x), std::abs(g.z - centre.z)) / half;
}

}  // namespace pvrr::test
