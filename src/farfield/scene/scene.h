// Scene: meshes, materials and objects (with an optional parent/child hierarchy through Object::parent).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "farfield/scene/material.h"
#include "farfield/scene/mesh.h"
#include "farfield/scene/object.h"

namespace farfield::scene {

struct SceneStats {
  size_t objects = 0;
  size_t meshes = 0;
  size_t materials = 0;
  size_t textures = 0;
  uint64_t triangles = 0;  // instanced: each object counts the triangles of all its parts
  uint64_t vertices = 0;
  size_t geometry_bytes = 0;
  size_t texture_bytes = 0;
  Box3 bounds;
};

class Scene {
 public:
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Object> objects;  // objects[i].id == i + 1

  uint32_t addMesh(Mesh mesh);
  uint32_t addMaterial(Material material);
  // Assigns the id (index + 1), computes world bounds; returns the id.
  uint32_t addObject(Object object);
  const Object& object(uint32_t id) const;  // by id (1-based)

  void updateBounds();  // recompute mesh bounds and object world bounds
  Box3 bounds() const;
  uint64_t triangleCount() const;
  SceneStats stats() const;
  // Throws farfield::Error naming `source` for bad meshes, dangling part indices or ids out of order.
  void validate(const std::string& source) const;
};

}  // namespace farfield::scene
