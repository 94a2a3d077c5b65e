// Triangle mesh: positions, normals, uvs (per vertex), 32-bit indices (three per triangle), bounds.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"

namespace farfield::scene {

struct Mesh {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  // empty or one per position
  // empty or one per position; glTF convention: (0, 0) is the top-left of the texture image (its row 0) and v grows
  // down the rows, so uploading row 0 first (glTexImage2D) samples it at v = 0
  std::vector<Vec2> uvs;
  std::vector<uint32_t> indices;
  Box3 bounds;  // of positions, kept current by computeBounds()

  size_t vertexCount() const { return positions.size(); }
  size_t triangleCount() const { return indices.size() / 3; }
  void computeBounds();
  // Area-weighted smooth normals over shared vertices.
  void computeNormals();
  // Appends another mesh transformed by m (normals by the inverse transpose).
  void append(const Mesh& other, const Mat4& m = Mat4(1.0f));
  // Throws farfield::Error naming `source` when the mesh is unusable: non-finite positions, normals or uvs,
  // indices out of range, an index count not a multiple of 3, attribute arrays of the wrong length.
  void validate(const std::string& source) const;
  // Bytes of vertex and index data.
  size_t byteSize() const;
};

}  // namespace farfield::scene
