#include "farfield/gpu/renderer.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <unordered_map>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/gpu_timer.h"
#include "farfield/gpu/program.h"

namespace farfield::gpu {
namespace {

// Program variants. Textured materials get their own variant because its alpha test (discard) stops the driver
// from testing depth before shading, which the untextured majority should keep.
enum Variant : int { kShadedPlain = 0, kShadedTextured = 1, kItemBuffer = 2, kVariantCount = 3 };

struct Locations {
  int view_proj = -1, model = -1, normal_matrix = -1, object_id = -1;
  int base_color = -1, unlit = -1, light_dir = -1, light_color = -1, ambient = -1;
  int projective_texture = -1, texture_projection = -1, has_ids = -1;
};

const GpuMaterial& defaultMaterial() {
  static const GpuMaterial material;
  return material;
}

}  // namespace

struct Renderer::Impl {
  std::array<Program, kVariantCount> programs;
  std::array<Locations, kVariantCount> locations;
  GpuTimer timer;
  std::vector<uint32_t> order;  // draw order (indices into the item list), reused across frames
  std::vector<uint32_t> ids;    // object ids drawn, for the distinct count

  Impl() {
    programs[kShadedPlain] = Program::fromEmbedded("mesh.vert.glsl", "mesh.frag.glsl");
    programs[kShadedTextured] = Program::fromEmbedded("mesh.vert.glsl", "mesh.frag.glsl", "#define FF_TEXTURED 1");
    programs[kItemBuffer] = Program::fromEmbedded("mesh.vert.glsl", "mesh.frag.glsl", "#define FF_ITEM_BUFFER 1");
    // Uniform locations are looked up once: per-draw work is a handful of glUniform calls and one draw.
    for (int v = 0; v < kVariantCount; ++v) {
      const Program& p = programs[v];
      Locations& l = locations[v];
      l.view_proj = p.uniformLocation("u_view_proj");
      l.model = p.uniformLocation("u_model");
      l.normal_matrix = p.uniformLocation("u_normal_matrix");
      l.object_id = p.uniformLocation("u_object_id");
      l.base_color = p.uniformLocation("u_base_color");
      l.unlit = p.uniformLocation("u_unlit");
      l.light_dir = p.uniformLocation("u_light_dir");
      l.light_color = p.uniformLocation("u_light_color");
      l.ambient = p.uniformLocation("u_ambient");
      l.projective_texture = p.uniformLocation("u_projective_texture");
      l.texture_projection = p.uniformLocation("u_texture_projection");
      l.has_ids = p.uniformLocation("u_has_ids");
    }
  }
};

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {}
Renderer::~Renderer() = default;

FrameStats Renderer::render(const Camera& camera, std::span<const DrawItem> items, RenderTarget& target,
                            RenderMode mode) {
  Stopwatch wall;
  // Bind before the query starts: llvmpipe times a query from the first command on the bound framebuffer and
  // returned nonsense for a query that began while another framebuffer was bound.
  target.bind();
  impl_->timer.begin();
  target.clear(mode == RenderMode::ItemBuffer ? Vec4(0.0f, 0.0f, 0.0f, 1.0f) : light_.sky_color);
  FrameStats stats = draw(camera, items, target, mode);
  impl_->timer.end();
  glFinish();
  stats.wall_ms = wall.milliseconds();
  stats.gpu_ms = std::min(impl_->timer.elapsedMs(), stats.wall_ms);
  return stats;
}

FrameStats Renderer::draw(const Camera& camera, std::span<const DrawItem> items, RenderTarget& target,
                          RenderMode mode) {
  camera.validate("camera");
  Stopwatch wall;
  Impl& im = *impl_;
  FrameStats stats;

  target.bindForOpaquePass();
  if (last_wins_ties_) glDepthFunc(GL_GEQUAL);

  // Per-frame uniforms on every variant (cheap, and the loop below then only switches programs).
  const Mat4 view_proj = camera.viewProjection();
  Vec3 light_dir = light_.direction;
  light_dir = glm::length(light_dir) > 0.0f ? glm::normalize(light_dir) : Vec3(0.0f, 0.0f, -1.0f);
  for (int v = 0; v < kVariantCount; ++v) {
    const GLuint h = im.programs[v].handle();
    const Locations& l = im.locations[v];
    glProgramUniformMatrix4fv(h, l.view_proj, 1, GL_FALSE, glm::value_ptr(view_proj));
    if (l.light_dir >= 0) glProgramUniform3fv(h, l.light_dir, 1, glm::value_ptr(light_dir));
    if (l.light_color >= 0) glProgramUniform3fv(h, l.light_color, 1, glm::value_ptr(light_.color));
    if (l.ambient >= 0) glProgramUniform1f(h, l.ambient, light_.ambient);
  }

  // Sort by program variant, culling, texture, material and mesh so consecutive draws share state. The sort is
  // stable, so items with equal state keep their order; only surfaces at exactly equal depth (coplanar, drawn with
  // different materials) can resolve differently from the submission order.
  auto materialOf = [&](const DrawItem& item) -> const GpuMaterial& {
    return item.material ? *item.material : defaultMaterial();
  };
  auto variantOf = [&](const GpuMaterial& m) {
    if (mode == RenderMode::ItemBuffer) return int(kItemBuffer);
    return m.texture ? int(kShadedTextured) : int(kShadedPlain);
  };
  auto less = [&](uint32_t a, uint32_t b) {
    const DrawItem& ia = items[a];
    const DrawItem& ib = items[b];
    const GpuMaterial& ma = materialOf(ia);
    const GpuMaterial& mb = materialOf(ib);
    const int va = variantOf(ma), vb = variantOf(mb);
    if (va != vb) return va < vb;
    if (ma.double_sided != mb.double_sided) return mb.double_sided;
    const uint32_t ta = ma.texture ? ma.texture->handle() : 0, tb = mb.texture ? mb.texture->handle() : 0;
    if (ta != tb) return ta < tb;
    if (&ma != &mb) return std::less<const GpuMaterial*>()(&ma, &mb);
    return std::less<const GpuMesh*>()(ia.mesh, ib.mesh);
  };
  im.order.resize(items.size());
  for (uint32_t i = 0; i < uint32_t(items.size()); ++i) im.order[i] = i;
  if (!std::is_sorted(im.order.begin(), im.order.end(), less))
    std::stable_sort(im.order.begin(), im.order.end(), less);

  im.ids.clear();
  int current_variant = -1;
  const GpuMaterial* current_material = nullptr;
  GLuint current_texture = 0;
  GLuint current_vao = 0;
  int cull = 1;          // culling enabled (set above)
  bool mirrored = false;  // glFrontFace(GL_CW) for transforms that flip handedness
  for (uint32_t index : im.order) {
    const DrawItem& item = items[index];
    if (!item.mesh || item.mesh->indexCount() == 0 || item.mesh->vertexArray() == 0) continue;
    const uint32_t index_count = item.index_count ? item.index_count : item.mesh->indexCount();
    FF_CHECK(index_count % 3 == 0 && item.first_index <= item.mesh->indexCount() &&
             index_count <= item.mesh->indexCount() - item.first_index);
    const GpuMaterial& material = materialOf(item);
    const int variant = variantOf(material);
    const Locations& l = im.locations[variant];
    if (variant != current_variant) {
      im.programs[variant].use();
      current_variant = variant;
      current_material = nullptr;  // material uniforms live in the program
    }
    if (&material != current_material) {
      current_material = &material;
      if (variant != kItemBuffer) {
        glUniform4fv(l.base_color, 1, glm::value_ptr(material.base_color));
        glUniform1i(l.unlit, material.unlit ? 1 : 0);
      }
      if (variant == kShadedTextured) {
        glUniform1i(l.projective_texture, material.projective_texture ? 1 : 0);
        if (material.projective_texture)
          glUniformMatrix4fv(l.texture_projection, 1, GL_FALSE, glm::value_ptr(material.texture_projection));
      }
      if (variant == kShadedTextured && material.texture->handle() != current_texture) {
        current_texture = material.texture->handle();
        glBindTextureUnit(0, current_texture);
      }
      if (variant == kShadedTextured) {
        glUniform1i(l.has_ids, material.id_texture ? 1 : 0);
        if (material.id_texture) glBindTextureUnit(1, material.id_texture->handle());
      }
      const int want_cull = material.double_sided ? 0 : 1;
      if (want_cull != cull) {
        if (want_cull)
          glEnable(GL_CULL_FACE);
        else
          glDisable(GL_CULL_FACE);
        cull = want_cull;
      }
    }
    const Mat3 linear(item.transform);
    const bool flip = glm::determinant(linear) < 0.0f;
    if (flip != mirrored) {
      glFrontFace(flip ? GL_CW : GL_CCW);
      mirrored = flip;
    }
    glUniformMatrix4fv(l.model, 1, GL_FALSE, glm::value_ptr(item.transform));
    if (l.normal_matrix >= 0) {
      const Mat3 normal_matrix = glm::transpose(glm::inverse(linear));
      glUniformMatrix3fv(l.normal_matrix, 1, GL_FALSE, glm::value_ptr(normal_matrix));
    }
    glUniform1ui(l.object_id, item.object_id);
    if (item.mesh->vertexArray() != current_vao) {
      current_vao = item.mesh->vertexArray();
      glBindVertexArray(current_vao);
    }
    glDrawElements(GL_TRIANGLES, GLsizei(index_count), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(uintptr_t(item.first_index) * sizeof(uint32_t)));
    stats.triangles += index_count / 3;
    ++stats.draw_calls;
    im.ids.push_back(item.object_id);
  }
  glBindVertexArray(0);
  if (mirrored) glFrontFace(GL_CCW);
  if (last_wins_ties_) glDepthFunc(GL_GREATER);

  std::sort(im.ids.begin(), im.ids.end());
  stats.objects = uint32_t(std::unique(im.ids.begin(), im.ids.end()) - im.ids.begin());
  stats.wall_ms = wall.milliseconds();
  return stats;
}

// ---------------------------------------------------------------------------------------------------------------

GpuScene::GpuScene(const scene::Scene& scene, const GpuSceneOptions& options)
    : scene_(&scene), bridge_indices_(3 * options.bridge_triangles) {
  meshes_.reserve(scene.meshes.size());
  clusters_.reserve(scene.meshes.size());
  facing_.reserve(scene.meshes.size());
  for (size_t i = 0; i < scene.meshes.size(); ++i) {
    try {
      // Only the GPU copy is reordered: clusters become contiguous index ranges of the one buffer (over short
      // vertex ranges), so culling costs no memory and a whole-mesh draw stays one draw call.
      ClusteredIndices clustered =
          clusterTriangles(scene.meshes[i], options.cluster_triangles, options.min_facing_triangles);
      meshes_.emplace_back(reorderedMesh(scene.meshes[i], clustered));
      clusters_.push_back(std::move(clustered.clusters));
      facing_.push_back(std::move(clustered.facing));
    } catch (const Error& e) {
      throw Error("scene mesh " + std::to_string(i), e.what());
    }
  }
  // One texture per distinct image: materials sharing an image share the GPU copy. Textures are all made before
  // any material points at them, so the pointers stay valid.
  std::unordered_map<const image::ColorImage*, size_t> texture_index;
  std::vector<long> material_texture(scene.materials.size(), -1);
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const auto& image = scene.materials[i].texture;
    if (!image || image->empty()) continue;
    auto [it, inserted] = texture_index.emplace(image.get(), textures_.size());
    if (inserted) {
      try {
        textures_.push_back(Texture::fromImage(*image));
      } catch (const Error& e) {
        throw Error("material '" + scene.materials[i].name + "' texture", e.what());
      }
    }
    material_texture[i] = long(it->second);
  }
  materials_.reserve(scene.materials.size());
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const scene::Material& m = scene.materials[i];
    GpuMaterial g;
    g.base_color = m.base_color;
    g.texture = material_texture[i] >= 0 ? &textures_[size_t(material_texture[i])] : nullptr;
    g.unlit = m.unlit;
    g.double_sided = m.double_sided;
    materials_.push_back(g);
  }
}

const scene::Object& GpuScene::checkedObject(uint32_t id) const {
  const auto& objects = scene_->objects;
  if (id == 0 || id > objects.size())
    throw Error("object id " + std::to_string(id),
                "out of range (the scene has " + std::to_string(objects.size()) + " objects, ids from 1)");
  return objects[id - 1];
}

void GpuScene::checkParts(const scene::Object& object) const {
  for (const scene::Part& part : object.parts)
    if (part.mesh >= meshes_.size() || part.material >= materials_.size())
      throw Error("object " + std::to_string(object.id) + " ('" + object.name + "')",
                  "part refers to mesh " + std::to_string(part.mesh) + " / material " +
                      std::to_string(part.material) + " of " + std::to_string(meshes_.size()) + " / " +
                      std::to_string(materials_.size()));
}

void GpuScene::appendDrawItems(std::span<const uint32_t> ids, std::vector<DrawItem>& out) const {
  auto append = [&](const scene::Object& object) {
    checkParts(object);
    for (const scene::Part& part : object.parts)
      out.push_back({&meshes_[part.mesh], &materials_[part.material], object.transform, object.id});
  };
  if (ids.empty()) {
    for (const auto& object : scene_->objects) append(object);
    return;
  }
  for (uint32_t id : ids) append(checkedObject(id));
}

void GpuScene::appendDrawItems(std::span<const uint32_t> ids, std::vector<DrawItem>& out,
                               const Frustum& frustum) const {
  appendCulled(ids, out, frustum, nullptr, nullptr);
}

void GpuScene::appendDrawItems(std::span<const uint32_t> ids, std::vector<DrawItem>& out, const Camera& camera,
                               std::vector<Box3>* item_bounds) const {
  appendCulled(ids, out, Frustum::fromMatrix(camera.viewProjection()), &camera.eye, item_bounds);
}

void GpuScene::appendCulled(std::span<const uint32_t> ids, std::vector<DrawItem>& out, const Frustum& frustum,
                            const Vec3* eye, std::vector<Box3>* item_bounds) const {
  auto append = [&](const scene::Object& object) {
    checkParts(object);
    // The planes in the object's own space (a world plane p met by the point M x is the plane p M in x), so the
    // clusters' mesh-space boxes are tested as they are, without growing them into world-axis boxes.
    Frustum local;
    for (size_t k = 0; k < frustum.planes.size(); ++k) local.planes[k] = frustum.planes[k] * object.transform;
    // The eye in the object's own space, for the facing test; only for affine transforms (a mirror is fine: the
    // renderer flips the front face with it, so facing is decided in mesh space as without it).
    const Mat4& m = object.transform;
    const bool affine = m[0][3] == 0.0f && m[1][3] == 0.0f && m[2][3] == 0.0f && m[3][3] == 1.0f;
    const bool test_facing = eye && affine && glm::determinant(Mat3(m)) != 0.0f;
    const Vec3 local_eye = test_facing ? Vec3(glm::inverse(m) * Vec4(*eye, 1.0f)) : Vec3(0.0f);
    for (const scene::Part& part : object.parts) {
      const GpuMesh* mesh = &meshes_[part.mesh];
      const GpuMaterial* material = &materials_[part.material];
      const bool facing = test_facing && !material->double_sided;
      const std::vector<FacingGroup>& groups = facing_[part.mesh];
      // Whether this part's last item may still grow, and where its indices end.
      bool open = false;
      uint32_t open_end = 0;
      for (const MeshCluster& cluster : clusters_[part.mesh]) {
        const bool drawn = local.intersects(cluster.bounds) && !(facing && facesAway(cluster, groups, local_eye));
        if (!drawn) continue;
        if (open && cluster.first_index - open_end <= bridge_indices_) {
          out.back().index_count = cluster.first_index + cluster.index_count - out.back().first_index;
          if (item_bounds) item_bounds->back().expand(cluster.bounds);
        } else {
          out.push_back({mesh, material, object.transform, object.id, cluster.first_index, cluster.index_count});
          if (item_bounds) item_bounds->push_back(cluster.bounds);
          open = true;
        }
        open_end = cluster.first_index + cluster.index_count;
      }
    }
  };
  if (ids.empty()) {
    for (const auto& object : scene_->objects) append(object);
    return;
  }
  for (uint32_t id : ids) append(checkedObject(id));
}

std::vector<DrawItem> GpuScene::drawItems() const {
  std::vector<DrawItem> items;
  appendDrawItems({}, items);
  return items;
}

std::vector<ObjectDrawCost> GpuScene::objectDrawCosts() const {
  std::vector<ObjectDrawCost> cost(scene_->objects.size() + 1);
  std::vector<DrawItem> items;
  for (const scene::Object& o : scene_->objects) {
    items.clear();
    const uint32_t id = o.id;
    appendDrawItems(std::span<const uint32_t>(&id, 1), items);
    for (const DrawItem& item : items) cost[id].triangles += item.triangleCount();
    cost[id].draws = uint32_t(items.size());
  }
  return cost;
}

size_t GpuScene::gpuBytes() const {
  size_t bytes = 0;
  for (const auto& m : meshes_) bytes += m.byteSize();
  // The clusters' bounds and ranges live in CPU memory and are not counted.
  for (const auto& t : textures_) bytes += t.byteSize();
  return bytes;
}

}  // namespace farfield::gpu
