// Vector types shared by every layer. CPU-side geometry is double precision throughout; floats appear
// only where data is handed to the GPU.
#pragma once
#include <glm/glm.hpp>
#include <cmath>
#include <limits>

namespace pvrr {
using Vec2 = glm::dvec2;
using Vec3 = glm::dvec3;
using Vec4 = glm::dvec4;
using Mat3 = glm::dmat3;
using Mat4 = glm::dmat4;

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

inline double radians(double deg) { return deg * (kPi / 180.0); }
inline double degrees(double rad) { return rad * (180.0 / kPi); }
inline double arcminutes(double rad) { return rad * (180.0 * 60.0 / kPi); }
inline bool isFinite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Angle between two vectors, accurate for tiny angles (atan2 of |a×b| and a·b, not acos).
inline double angleBetween(const Vec3& a, const Vec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}
}  // namespace pvrr
