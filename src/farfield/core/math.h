// Math aliases on glm. Units: metres and radians inside Farfield; degrees and pixels only at the user-facing edge.
#pragma once

#define GLM_FORCE_CXX17
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <cmath>
#include <cstdint>
#include <numbers>

namespace farfield {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Vec4 = glm::vec4;
using DVec2 = glm::dvec2;
using DVec3 = glm::dvec3;
using IVec2 = glm::ivec2;
using Mat3 = glm::mat3;
using Mat4 = glm::mat4;
using DMat4 = glm::dmat4;

inline constexpr double kPi = std::numbers::pi;

constexpr double degToRad(double deg) { return deg * (kPi / 180.0); }
constexpr double radToDeg(double rad) { return rad * (180.0 / kPi); }

inline bool isFinite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline bool isFinite(const Vec2& v) { return std::isfinite(v.x) && std::isfinite(v.y); }

// 2D cross product (z of the 3D cross product).
inline double cross2(const DVec2& a, const DVec2& b) { return a.x * b.y - a.y * b.x; }
inline float cross2(const Vec2& a, const Vec2& b) { return a.x * b.y - a.y * b.x; }

}  // namespace farfield
