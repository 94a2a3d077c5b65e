// Mesh: bounds, smooth normals, appending with a transform, validation of user-supplied geometry.
#include "farfield/scene/mesh.h"

#include <cmath>
#include <string>

#include "farfield/core/error.h"

namespace farfield::scene {

void Mesh::computeBounds() {
  bounds = Box3{};
  for (const Vec3& p : positions) bounds.expand(p);
}

void Mesh::computeNormals() {
  // The unnormalised cross product of two edges has length 2 * area, so summing it over the triangles around a
  // vertex weights each face by its area without computing the area separately.
  normals.assign(positions.size(), Vec3(0.0f));
  const size_t tri_count = triangleCount();
  for (size_t t = 0; t < tri_count; ++t) {
    const uint32_t i0 = indices[3 * t], i1 = indices[3 * t + 1], i2 = indices[3 * t + 2];
    if (i0 >= positions.size() || i1 >= positions.size() || i2 >= positions.size()) continue;
    const Vec3 n = glm::cross(positions[i1] - positions[i0], positions[i2] - positions[i0]);
    normals[i0] += n;
    normals[i1] += n;
    normals[i2] += n;
  }
  for (Vec3& n : normals) {
    const float len = glm::length(n);
    // A vertex used by no triangle (or only by degenerate ones) still needs a finite unit normal.
    n = (len > 0.0f && std::isfinite(len)) ? n / len : Vec3(0.0f, 0.0f, 1.0f);
  }
}

void Mesh::append(const Mesh& other, const Mat4& m) {
  // Attribute arrays stay consistent: when only one side has normals, the other side's are computed; when only
  // one side has uvs, the other side gets (0, 0).
  const bool this_empty = positions.empty();
  const bool want_normals = this_empty ? !other.normals.empty() : (!normals.empty() || !other.normals.empty());
  const bool want_uvs = this_empty ? !other.uvs.empty() : (!uvs.empty() || !other.uvs.empty());
  if (want_normals && normals.size() != positions.size()) computeNormals();
  if (want_uvs && uvs.size() != positions.size()) uvs.resize(positions.size(), Vec2(0.0f));

  const Mesh* src = &other;
  Mesh with_normals;
  if (want_normals && other.normals.size() != other.positions.size()) {
    with_normals = other;
    with_normals.computeNormals();
    src = &with_normals;
  }

  const uint32_t base = uint32_t(positions.size());
  const Mat3 normal_matrix = glm::transpose(glm::inverse(Mat3(m)));
  // A mirroring transform turns counter-clockwise triangles clockwise; swapping two indices keeps front faces
  // facing outward.
  const bool mirror = glm::determinant(Mat3(m)) < 0.0f;

  positions.reserve(positions.size() + src->positions.size());
  for (const Vec3& p : src->positions) positions.push_back(Vec3(m * Vec4(p, 1.0f)));
  if (want_normals) {
    for (const Vec3& n : src->normals) {
      const Vec3 t = normal_matrix * n;
      const float len = glm::length(t);
      normals.push_back(len > 0.0f ? t / len : Vec3(0.0f, 0.0f, 1.0f));
    }
  }
  if (want_uvs) {
    if (src->uvs.size() == src->positions.size())
      uvs.insert(uvs.end(), src->uvs.begin(), src->uvs.end());
    else
      uvs.resize(positions.size(), Vec2(0.0f));
  }
  indices.reserve(indices.size() + src->indices.size());
  for (size_t i = 0; i + 2 < src->indices.size(); i += 3) {
    const uint32_t a = src->indices[i] + base, b = src->indices[i + 1] + base, c = src->indices[i + 2] + base;
    indices.push_back(a);
    indices.push_back(mirror ? c : b);
    indices.push_back(mirror ? b : c);
  }
  Box3 added;
  for (size_t i = base; i < positions.size(); ++i) added.expand(positions[i]);
  bounds.expand(added);
}

void Mesh::validate(const std::string& source) const {
  if (!normals.empty() && normals.size() != positions.size())
    throw Error(source, std::to_string(normals.size()) + " normals for " + std::to_string(positions.size()) +
                            " vertices (expected none or one per vertex)");
  if (!uvs.empty() && uvs.size() != positions.size())
    throw Error(source, std::to_string(uvs.size()) + " uvs for " + std::to_string(positions.size()) +
                            " vertices (expected none or one per vertex)");
  if (indices.size() % 3 != 0)
    throw Error(source, "index count " + std::to_string(indices.size()) + " is not a multiple of 3");
  for (size_t i = 0; i < positions.size(); ++i)
    if (!isFinite(positions[i])) throw Error(source, "vertex " + std::to_string(i) + ": non-finite coordinate");
  for (size_t i = 0; i < normals.size(); ++i)
    if (!isFinite(normals[i])) throw Error(source, "vertex " + std::to_string(i) + ": non-finite normal");
  for (size_t i = 0; i < uvs.size(); ++i)
    if (!isFinite(uvs[i])) throw Error(source, "vertex " + std::to_string(i) + ": non-finite uv");
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= positions.size())
      throw Error(source, "index " + std::to_string(i) + " (triangle " + std::to_string(i / 3) + "): vertex " +
                              std::to_string(indices[i]) + " out of range (" + std::to_string(positions.size()) +
                              " vertices)");
}

size_t Mesh::byteSize() const {
  return positions.size() * sizeof(Vec3) + normals.size() * sizeof(Vec3) + uvs.size() * sizeof(Vec2) +
         indices.size() * sizeof(uint32_t);
}

}  // namespace farfield::scene
