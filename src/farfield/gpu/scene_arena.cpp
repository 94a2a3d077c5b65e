#include "farfield/gpu/scene_arena.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/gpu/arena_mesh.h"
#include "farfield/gpu/gpu_mesh.h"
#include "farfield/gpu/texture.h"

namespace farfield::gpu {
namespace {

// std430 records of the shaders (gpu_cull.comp.glsl, arena.vert.glsl).
struct GpuCluster {
  float sphere[4];
  float cone_apex[4];  // xyz, w = cutoff
  float cone_axis[4];
  float box_lo[4];
  float box_hi[4];
  uint32_t range[4];  // first index, index count, base vertex, 0
};
static_assert(sizeof(GpuCluster) == 96);
struct GpuObject {
  float model[16];
  float normal[16];   // the inverse transpose of the model's 3x3 part, in the first three columns
  float misc[4];      // x: largest scale of the model's axes; y, z: objectStretch (the least and most it stretches)
  uint32_t info[4];   // object id, flags (kObjectAffine)
};
static_assert(sizeof(GpuObject) == 160);
struct GpuMaterial {
  float base_color[4];
  uint32_t info[4];  // unlit, texture layer, 0, 0
};
// A part's per-instance vertex attributes (arena.vert.glsl): read by the vertex fetch once per draw command, where a
// storage-buffer lookup per vertex made llvmpipe's multi-draws about 30 % slower per triangle.
struct GpuPartRow {
  float model[16];
  float normal[12];      // the object's normal matrix, its three columns (w unused)
  float base_color[4];
  uint32_t info[4];      // object id, unlit, texture layer, 0
};
static_assert(sizeof(GpuPartRow) == 144);

constexpr uint32_t kObjectAffine = 1;  // the shader may cull it (a projective transform is always drawn)
constexpr uint8_t kMirrored = 1, kSimilarity = 2, kAffine = 4;
constexpr uint32_t kConeTestBit = 1u << 31;
constexpr uint32_t kLodBit = 1u << 30;  // an instance of a simplified level (gpu_cull.comp.glsl, continues)

uint8_t transformKind(const Mat4& m) {
  uint8_t kind = 0;
  const bool affine = m[0][3] == 0.0f && m[1][3] == 0.0f && m[2][3] == 0.0f && m[3][3] == 1.0f;
  if (affine) kind |= kAffine;
  const Mat3 linear(m);
  const float det = glm::determinant(linear);
  if (det < 0.0f) kind |= kMirrored;
  // Angles are kept when the axes are orthogonal and of equal length (a rotation, a uniform scale, a mirror).
  const Vec3 a = linear[0], b = linear[1], c = linear[2];
  const float la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
  const float scale = std::max({la, lb, lc});
  const float tol = 1e-4f * scale * scale;
  if (affine && det != 0.0f && std::abs(la - lb) <= 1e-4f * scale && std::abs(la - lc) <= 1e-4f * scale &&
      std::abs(glm::dot(a, b)) <= tol && std::abs(glm::dot(a, c)) <= tol && std::abs(glm::dot(b, c)) <= tol)
    kind |= kSimilarity;
  return kind;
}

GpuObject gpuObject(const scene::Object& object) {
  GpuObject g{};
  const Mat4& m = object.transform;
  std::copy(glm::value_ptr(m), glm::value_ptr(m) + 16, g.model);
  const Mat3 linear(m);
  const Mat3 normal = glm::determinant(linear) != 0.0f ? glm::transpose(glm::inverse(linear)) : Mat3(1.0f);
  const Mat4 normal4(normal);
  std::copy(glm::value_ptr(normal4), glm::value_ptr(normal4) + 16, g.normal);
  g.misc[0] = std::max({glm::length(linear[0]), glm::length(linear[1]), glm::length(linear[2])});
  const auto [least, most] = objectStretch(m);
  g.misc[1] = float(least);
  g.misc[2] = float(most);
  g.info[0] = object.id;
  g.info[1] = (transformKind(m) & kAffine) ? kObjectAffine : 0u;
  return g;
}

GLuint makeBuffer(const void* data, size_t bytes, size_t& total) {
  total += bytes;
  return createStorageBuffer(bytes, data, GL_DYNAMIC_STORAGE_BIT);
}

}  // namespace

uint32_t createStorageBuffer(size_t bytes, const void* data, uint32_t flags) {
  // An empty buffer still gets a name and 16 bytes, so bindings stay valid for a scene without triangles; fewer
  // bytes than that are copied into a zeroed block first (the driver reads all 16 from `data`).
  std::array<uint8_t, 16> small{};
  if (data && bytes < small.size()) {
    std::memcpy(small.data(), data, bytes);
    data = small.data();
  }
  GLuint buffer = 0;
  glCreateBuffers(1, &buffer);
  glNamedBufferStorage(buffer, GLsizeiptr(std::max<size_t>(bytes, small.size())), data, GLbitfield(flags));
  return buffer;
}

bool coneRejects(const ArenaCluster& cluster, const Vec3& eye) {
  if (!(cluster.cone_cutoff < 1.0f)) return false;
  const Vec3 d = cluster.cone_apex - eye;
  const float length = glm::length(d);
  if (!(length > 0.0f)) return false;
  // Margin: a nearly edge-on triangle that rounding turns towards the eye must still be drawn (as facesAway's).
  return glm::dot(d / length, cluster.cone_axis) >= cluster.cone_cutoff + 1e-3f;
}

std::pair<double, double> objectStretch(const Mat4& model) {
  const Mat3 linear(model);
  const double det = double(glm::determinant(linear));
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return {0.0, 0.0};
  if (transformKind(model) & kSimilarity) {
    const double s = double(glm::length(linear[0]));
    return {s, s};
  }
  const auto frobenius = [](const Mat3& m) {
    double sum = 0.0;
    for (int c = 0; c < 3; ++c) sum += double(glm::dot(m[c], m[c]));
    return std::sqrt(sum);
  };
  // The spectral norm is at most the Frobenius norm: |L v| <= |L|_F |v|, and |v| <= |L^-1|_F |L v|.
  return {1.0 / frobenius(glm::inverse(linear)), frobenius(linear)};
}

double partLodErrorPx(const ArenaPart& part, const Mat4& model, const Vec3& eye, double pixels_per_unit) {
  const double inf = std::numeric_limits<double>::infinity();
  if (part.lod_instance_count == 0 || part.bounds.empty()) return inf;
  if (!(model[0][3] == 0.0f && model[1][3] == 0.0f && model[2][3] == 0.0f && model[3][3] == 1.0f)) return inf;
  const auto [least, most] = objectStretch(model);
  if (!(least > 0.0)) return inf;
  // The eye in the object's own space, and its distance to the part's box there; the world distance to any point of
  // the part is at least that times the least stretch, and the error at most the level's times the most.
  const Mat3 linear(model);
  const Vec3 local = glm::inverse(linear) * (eye - Vec3(model[3]));
  const Vec3 gap = glm::max(glm::max(part.bounds.lo - local, local - part.bounds.hi), Vec3(0.0f));
  const double distance = double(glm::length(gap)) * least;
  if (!(distance > 0.0)) return inf;
  return double(part.lod_error) * most * pixels_per_unit / distance;
}

SceneArena::SceneArena(const scene::Scene& scene, const ArenaOptions& options) : scene_(&scene) {
  FF_CHECK(options.max_vertices >= 3 && options.max_vertices <= 255);
  FF_CHECK(options.max_triangles >= 4 && options.max_triangles <= 512 && options.max_triangles % 4 == 0);

  // ---- meshes: clusters, vertices and indices, cut on worker threads, then laid end to end ----
  std::vector<ArenaMesh> cut(scene.meshes.size());
  {
    std::atomic<size_t> next{0};
    std::exception_ptr failure;
    std::mutex failure_mutex;
    auto work = [&] {
      for (size_t m = next++; m < cut.size(); m = next++) {
        try {
          cut[m] = clusterArenaMesh(scene.meshes[m], options);
        } catch (const Error& e) {
          const std::lock_guard<std::mutex> lock(failure_mutex);
          if (!failure) failure = std::make_exception_ptr(Error("scene mesh " + std::to_string(m), e.what()));
          next = cut.size();
        }
      }
    };
    const size_t threads = std::clamp<size_t>(std::thread::hardware_concurrency(), 1, 16);
    std::vector<std::thread> pool;
    for (size_t t = 1; t < threads && t < cut.size(); ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
  }
  std::vector<GpuVertex> vertices;
  std::vector<uint32_t> indices;
  mesh_clusters_.reserve(scene.meshes.size());
  for (ArenaMesh& mesh : cut) {
    const uint32_t first_cluster = uint32_t(clusters_.size());
    const uint32_t base_vertex = uint32_t(vertices.size()), base_index = uint32_t(indices.size());
    vertices.insert(vertices.end(), mesh.vertices.begin(), mesh.vertices.end());
    indices.insert(indices.end(), mesh.indices.begin(), mesh.indices.end());
    for (ArenaCluster cluster : mesh.clusters) {
      cluster.first_index += base_index;
      cluster.base_vertex = base_vertex;
      clusters_.push_back(cluster);
    }
    mesh_clusters_.emplace_back(first_cluster, uint32_t(mesh.clusters.size()) - mesh.lod_clusters);
    mesh_lod_.emplace_back(mesh.lod_clusters, mesh.lod_error);
    mesh = ArenaMesh{};  // its memory back before the next one is copied
  }

  // ---- textures: one array per image size, one layer per distinct image ----
  std::map<std::pair<int, int>, std::vector<const image::ColorImage*>> by_size;
  std::unordered_map<const image::ColorImage*, std::pair<int, int>> layer_of;  // image -> (array, layer)
  for (const scene::Material& m : scene.materials)
    if (m.texture && !m.texture->empty() && !layer_of.count(m.texture.get())) {
      auto& layers = by_size[{m.texture->width(), m.texture->height()}];
      layer_of[m.texture.get()] = {-1, int(layers.size())};
      layers.push_back(m.texture.get());
    }
  for (auto& [size, images] : by_size) {
    const int array = int(texture_arrays_.size());
    texture_arrays_.push_back(makeColorTextureArray(images));
    gpu_bytes_ += colorTextureArrayBytes(size.first, size.second, int(images.size()));
    for (const image::ColorImage* image : images) layer_of[image].first = array;
  }

  // ---- materials ----
  std::vector<GpuMaterial> materials(std::max<size_t>(scene.materials.size(), 1));
  std::vector<int> material_array(scene.materials.size(), -1);
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const scene::Material& m = scene.materials[i];
    GpuMaterial& g = materials[i];
    std::copy(glm::value_ptr(m.base_color), glm::value_ptr(m.base_color) + 4, g.base_color);
    g.info[0] = m.unlit ? 1u : 0u;
    if (m.texture && !m.texture->empty()) {
      const auto [array, layer] = layer_of.at(m.texture.get());
      material_array[i] = array;
      g.info[1] = uint32_t(layer);
    }
  }
  material_layer_.resize(scene.materials.size());
  for (size_t i = 0; i < scene.materials.size(); ++i) material_layer_[i] = materials[i].info[1];

  // ---- objects and instances, grouped ----
  object_kind_.resize(scene.objects.size());
  std::map<std::tuple<int, bool, bool>, uint32_t> group_of;
  struct Pending {
    ArenaInstance instance;
    std::tuple<int, bool, bool> key;
    uint32_t part;
    bool lod;  // of the part's simplified level (after its full level's, in the same group)
  };
  std::vector<Pending> pending;
  object_parts_.assign(scene.objects.size() + 1, 0);
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const scene::Object& object = scene.objects[o];
    const uint8_t kind = transformKind(object.transform);
    object_kind_[o] = kind;
    object_parts_[o] = uint32_t(parts_.size());
    for (const scene::Part& part : object.parts) {
      if (part.mesh >= scene.meshes.size() || part.material >= scene.materials.size())
        throw Error("object " + std::to_string(object.id) + " ('" + object.name + "')",
                    "part refers to mesh " + std::to_string(part.mesh) + " / material " +
                        std::to_string(part.material) + " of " + std::to_string(scene.meshes.size()) + " / " +
                        std::to_string(scene.materials.size()));
      const scene::Material& material = scene.materials[part.material];
      const auto key = std::make_tuple(material_array[part.material], material.double_sided, bool(kind & kMirrored));
      group_of.emplace(key, 0);
      const auto [first, n] = mesh_clusters_[part.mesh];
      const auto [lod_n, lod_error] = mesh_lod_[part.mesh];
      const uint32_t part_index = uint32_t(parts_.size());
      ArenaPart arena_part;
      arena_part.object = uint32_t(o);
      arena_part.material = part.material;
      arena_part.lod_error = lod_error;
      for (uint32_t c = first; c < first + n; ++c) arena_part.bounds.expand(clusters_[c].bounds);
      parts_.push_back(arena_part);
      for (uint32_t c = first; c < first + n + lod_n; ++c) {
        ArenaInstance instance;
        instance.cluster = c;
        instance.object = uint32_t(o);
        instance.material = part.material;
        instance.cone_test = !material.double_sided && (kind & kSimilarity) && clusters_[c].cone_cutoff < 1.0f;
        pending.push_back({instance, key, part_index, c >= first + n});
      }
    }
  }
  object_parts_[scene.objects.size()] = uint32_t(parts_.size());
  for (auto& [key, index] : group_of) {
    index = uint32_t(groups_.size());
    MaterialGroup g;
    g.texture_array = std::get<0>(key);
    g.double_sided = std::get<1>(key);
    g.mirrored = std::get<2>(key);
    groups_.push_back(g);
  }
  for (Pending& p : pending) p.instance.group = group_of.at(p.key);
  std::stable_sort(pending.begin(), pending.end(),
                   [](const Pending& a, const Pending& b) { return a.instance.group < b.instance.group; });
  instances_.reserve(pending.size());
  std::vector<uint32_t> gpu_instances;
  gpu_instances.reserve(4 * pending.size());
  for (const Pending& p : pending) {
    const ArenaInstance& in = p.instance;
    MaterialGroup& g = groups_[in.group];
    if (g.instance_count == 0) g.first_instance = uint32_t(instances_.size());
    ++g.instance_count;
    ArenaPart& part = parts_[p.part];
    if (p.lod) {
      lod_triangles_ += clusters_[in.cluster].index_count / 3;
      ++part.lod_instance_count;
    } else {
      g.triangles += clusters_[in.cluster].index_count / 3;
      triangles_ += clusters_[in.cluster].index_count / 3;
      if (part.instance_count == 0) part.first_instance = uint32_t(instances_.size());
      ++part.instance_count;
    }
    instances_.push_back(in);
    gpu_instances.insert(gpu_instances.end(),
                         {in.cluster, in.object, in.material,
                          in.group | (in.cone_test ? kConeTestBit : 0u) | (p.lod ? kLodBit : 0u)});
  }

  // ---- GPU buffers ----
  std::vector<GpuCluster> gpu_clusters(clusters_.size());
  for (size_t c = 0; c < clusters_.size(); ++c) {
    const ArenaCluster& a = clusters_[c];
    GpuCluster& g = gpu_clusters[c];
    g = {{a.center.x, a.center.y, a.center.z, a.radius},
         {a.cone_apex.x, a.cone_apex.y, a.cone_apex.z, a.cone_cutoff},
         {a.cone_axis.x, a.cone_axis.y, a.cone_axis.z, 0.0f},
         {a.bounds.lo.x, a.bounds.lo.y, a.bounds.lo.z, 0.0f},
         {a.bounds.hi.x, a.bounds.hi.y, a.bounds.hi.z, 0.0f},
         {a.first_index, a.index_count, a.base_vertex, 0u}};
  }
  // Parts: object, first instance, count, simplified level's count; box lo, simplified level's error; box hi
  // (gpu_cull.comp.glsl's Part).
  std::vector<float> gpu_parts;
  gpu_parts.reserve(12 * parts_.size());
  for (const ArenaPart& part : parts_) {
    const uint32_t info[4] = {part.object, part.first_instance, part.instance_count, part.lod_instance_count};
    float words[4];
    std::memcpy(words, info, sizeof(info));
    const Box3 b = part.bounds.empty() ? Box3::fromPoints(Vec3(0.0f), Vec3(0.0f)) : part.bounds;
    gpu_parts.insert(gpu_parts.end(), {words[0], words[1], words[2], words[3], b.lo.x, b.lo.y, b.lo.z,
                                       part.lod_error, b.hi.x, b.hi.y, b.hi.z, 0.0f});
  }
  buffers_.parts = makeBuffer(gpu_parts.data(), gpu_parts.size() * sizeof(float), gpu_bytes_);
  vertex_count_ = vertices.size();
  index_count_ = indices.size();
  vertex_buffer_ = makeBuffer(vertices.data(), vertices.size() * sizeof(GpuVertex), gpu_bytes_);
  index_buffer_ = makeBuffer(indices.data(), indices.size() * sizeof(uint32_t), gpu_bytes_);
  part_rows_ = makeBuffer(nullptr, parts_.size() * sizeof(GpuPartRow), gpu_bytes_);
  uploadPartRows(0, uint32_t(parts_.size()));
  buffers_.clusters = makeBuffer(gpu_clusters.data(), gpu_clusters.size() * sizeof(GpuCluster), gpu_bytes_);
  buffers_.instances = makeBuffer(gpu_instances.data(), gpu_instances.size() * sizeof(uint32_t), gpu_bytes_);
  buffers_.materials = makeBuffer(materials.data(), materials.size() * sizeof(GpuMaterial), gpu_bytes_);
  buffers_.objects = makeBuffer(nullptr, scene.objects.size() * sizeof(GpuObject), gpu_bytes_);
  uploadObjects(0, uint32_t(scene.objects.size()));

  const GLuint vao = makeVertexArray(vertex_buffer_, index_buffer_);
  // The part's row, per instance: a draw's baseInstance (gpu_cull.comp.glsl's emit stage writes the part) picks it.
  glVertexArrayVertexBuffer(vao, 1, part_rows_, 0, sizeof(GpuPartRow));
  glVertexArrayBindingDivisor(vao, 1, 1);
  for (GLuint location = 3; location <= 10; ++location) {  // model (4), normal matrix (3), base colour
    glEnableVertexArrayAttrib(vao, location);
    glVertexArrayAttribFormat(vao, location, 4, GL_FLOAT, GL_FALSE, (location - 3) * 4 * sizeof(float));
    glVertexArrayAttribBinding(vao, location, 1);
  }
  glEnableVertexArrayAttrib(vao, 11);
  glVertexArrayAttribIFormat(vao, 11, 4, GL_UNSIGNED_INT, offsetof(GpuPartRow, info));
  glVertexArrayAttribBinding(vao, 11, 1);
  buffers_.vertex_array = vao;
}

SceneArena::~SceneArena() {
  if (buffers_.vertex_array) glDeleteVertexArrays(1, &buffers_.vertex_array);
  const GLuint buffers[] = {vertex_buffer_,      index_buffer_,    part_rows_,         buffers_.clusters,
                            buffers_.instances,  buffers_.objects, buffers_.materials, buffers_.parts};
  glDeleteBuffers(GLsizei(std::size(buffers)), buffers);
  if (!texture_arrays_.empty()) glDeleteTextures(GLsizei(texture_arrays_.size()), texture_arrays_.data());
}

std::vector<uint32_t> SceneArena::readIndices() const {
  std::vector<uint32_t> indices(index_count_);
  if (index_count_) glGetNamedBufferSubData(index_buffer_, 0, GLsizeiptr(index_count_ * sizeof(uint32_t)), indices.data());
  return indices;
}

std::vector<Vec3> SceneArena::readVertexPositions() const {
  std::vector<GpuVertex> vertices(vertex_count_);
  if (vertex_count_)
    glGetNamedBufferSubData(vertex_buffer_, 0, GLsizeiptr(vertex_count_ * sizeof(GpuVertex)), vertices.data());
  std::vector<Vec3> positions(vertex_count_);
  for (size_t i = 0; i < vertex_count_; ++i)
    positions[i] = Vec3(vertices[i].position[0], vertices[i].position[1], vertices[i].position[2]);
  return positions;
}

void SceneArena::uploadObjects(uint32_t first, uint32_t count) {
  if (count == 0) return;
  std::vector<GpuObject> objects(count);
  for (uint32_t i = 0; i < count; ++i) objects[i] = gpuObject(scene_->objects[first + i]);
  glNamedBufferSubData(buffers_.objects, GLintptr(first) * GLintptr(sizeof(GpuObject)),
                       GLsizeiptr(count * sizeof(GpuObject)), objects.data());
}

void SceneArena::uploadPartRows(uint32_t first, uint32_t count) {
  if (count == 0) return;
  std::vector<GpuPartRow> rows(count);
  for (uint32_t i = 0; i < count; ++i) {
    const ArenaPart& part = parts_[first + i];
    const GpuObject o = gpuObject(scene_->objects[part.object]);
    const scene::Material& m = scene_->materials[part.material];
    GpuPartRow& r = rows[i];
    std::copy(o.model, o.model + 16, r.model);
    std::copy(o.normal, o.normal + 12, r.normal);
    std::copy(glm::value_ptr(m.base_color), glm::value_ptr(m.base_color) + 4, r.base_color);
    r.info[0] = o.info[0];
    r.info[1] = m.unlit ? 1u : 0u;
    r.info[2] = material_layer_[part.material];
    r.info[3] = 0u;
  }
  glNamedBufferSubData(part_rows_, GLintptr(first) * GLintptr(sizeof(GpuPartRow)),
                       GLsizeiptr(count * sizeof(GpuPartRow)), rows.data());
}

void SceneArena::updateTransforms(std::span<const uint32_t> ids) {
  for (uint32_t id : ids) {
    if (id == 0 || id > scene_->objects.size())
      throw Error("object id " + std::to_string(id),
                  "out of range (the scene has " + std::to_string(scene_->objects.size()) + " objects, ids from 1)");
    const uint8_t kind = transformKind(scene_->objects[id - 1].transform);
    FF_CHECK((kind & (kMirrored | kSimilarity)) == (object_kind_[id - 1] & (kMirrored | kSimilarity)));
    uploadObjects(id - 1, 1);
    uploadPartRows(object_parts_[id - 1], object_parts_[id] - object_parts_[id - 1]);
  }
}

}  // namespace farfield::gpu
