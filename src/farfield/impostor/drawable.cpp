// Drawable forms of the mesh impostors (Sillion et al. 1997, section 3.2: "a textured three-dimensional object ...
// visualised efficiently just like other 3D data").
#include "farfield/impostor/drawable.h"

#include <map>

#include "farfield/core/check.h"

namespace farfield::impostor {

SceneImpostor toSceneImpostor(const DepthMeshImpostor& impostor, const std::string& name) {
  SceneImpostor out;
  out.mesh = impostor.mesh;
  out.material.name = name;
  out.material.texture = impostor.texture;
  out.material.unlit = true;
  out.material.double_sided = true;
  return out;
}

std::vector<IdMesh> splitByObjectId(const scene::Mesh& mesh, const std::vector<uint32_t>& triangle_ids) {
  FF_CHECK(triangle_ids.size() == mesh.triangleCount());
  std::map<uint32_t, size_t> slot;
  std::vector<IdMesh> out;
  std::vector<std::vector<uint32_t>> remap;
  for (size_t t = 0; t < triangle_ids.size(); ++t) {
    auto [it, inserted] = slot.emplace(triangle_ids[t], out.size());
    if (inserted) {
      out.push_back({triangle_ids[t], {}});
      remap.emplace_back(mesh.vertexCount(), 0xffffffffu);
    }
    IdMesh& part = out[it->second];
    std::vector<uint32_t>& map = remap[it->second];
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.indices[3 * t + size_t(k)];
      if (map[v] == 0xffffffffu) {
        map[v] = uint32_t(part.mesh.positions.size());
        part.mesh.positions.push_back(mesh.positions[v]);
        if (!mesh.normals.empty()) part.mesh.normals.push_back(mesh.normals[v]);
        if (!mesh.uvs.empty()) part.mesh.uvs.push_back(mesh.uvs[v]);
      }
      part.mesh.indices.push_back(map[v]);
    }
  }
  for (IdMesh& part : out) part.mesh.computeBounds();
  return out;
}

GpuImpostor::GpuImpostor(const DepthMeshImpostor& impostor, const GpuImpostorOptions& options) {
  material_ = std::make_unique<gpu::GpuMaterial>();
  material_->unlit = true;
  material_->double_sided = true;
  if (impostor.empty()) return;
  if (impostor.texture) {
    texture_ = std::make_unique<gpu::Texture>(gpu::Texture::fromImage(*impostor.texture, options.mipmaps));
    texture_->setClampToEdge();
    material_->texture = texture_.get();
    material_->projective_texture = options.projective_texture;
    material_->texture_projection = textureProjection(impostor.camera);
    if (options.id_texture && impostor.ids && impostor.ids->width() == impostor.texture->width() &&
        impostor.ids->height() == impostor.texture->height()) {
      id_texture_ = std::make_unique<gpu::Texture>(gpu::Texture::fromIds(*impostor.ids));
      material_->id_texture = id_texture_.get();
    }
  }
  if (options.split_by_object_id && impostor.triangle_ids.size() == impostor.mesh.triangleCount()) {
    for (IdMesh& part : splitByObjectId(impostor.mesh, impostor.triangle_ids)) {
      meshes_.emplace_back(part.mesh);
      ids_.push_back(part.id);
    }
  } else {
    meshes_.emplace_back(impostor.mesh);
    ids_.push_back(0);
  }
  triangles_ = impostor.mesh.triangleCount();
}

void GpuImpostor::appendDrawItems(std::vector<gpu::DrawItem>& out, uint32_t object_id, const Mat4& transform) const {
  for (size_t i = 0; i < meshes_.size(); ++i)
    out.push_back({&meshes_[i], material_.get(), transform, ids_[i] ? ids_[i] : object_id});
}

size_t GpuImpostor::gpuBytes() const {
  size_t bytes = (texture_ ? texture_->byteSize() : 0) + (id_texture_ ? id_texture_->byteSize() : 0);
  for (const gpu::GpuMesh& m : meshes_) bytes += m.byteSize();
  return bytes;
}

}  // namespace farfield::impostor
