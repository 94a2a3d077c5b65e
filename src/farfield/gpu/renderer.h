// Renderer: draws a list of (mesh, material, transform, object id) with one directional light, base colour and
// texture, back-face culling, reversed-Z depth; writes colour and object ids (a second colour attachment) in
// one pass. Per-frame statistics: triangles, draw calls, wall time (with glFinish), GPU time (GL_TIME_ELAPSED).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/gpu_mesh.h"
#include "farfield/gpu/mesh_clusters.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/texture.h"
#include "farfield/scene/scene.h"

namespace farfield::gpu {

// Colour = base colour times the texture (if any); with a texture, texels whose resulting alpha is below 0.5 are
// cut out (not drawn, no depth, no id), which is what billboard and impostor textures with transparent
// backgrounds need. A null DrawItem::material draws with the default (white, lit, single-sided).
struct GpuMaterial {
  Vec4 base_color{1.0f};
  const Texture* texture = nullptr;  // may be null
  bool unlit = false;
  bool double_sided = false;
  // Projective texturing (image-based impostors): when set, the texture coordinate of a point is
  // texture_projection * (object-space position, 1) divided by its w, instead of the mesh's interpolated uvs. With an
  // impostor's creation camera (uv = its image position) every point shows exactly the texel captured there,
  // whatever the depths of its triangle's vertices.
  bool projective_texture = false;
  Mat4 texture_projection{1.0f};
  // Per-texel object ids (R32UI, read at the same texture coordinate as `texture`, nearest texel; only with a
  // texture): the id buffer gets the texel's id instead of DrawItem::object_id where it is not 0. An impostor drawn
  // with the ids of its capture then tells, pixel by pixel, which object it shows (bench: parallax error).
  const Texture* id_texture = nullptr;
};

struct DrawItem {
  const GpuMesh* mesh = nullptr;
  const GpuMaterial* material = nullptr;
  Mat4 transform{1.0f};
  uint32_t object_id = 0;
  // The triangles drawn: indices [first_index, first_index + index_count) of the mesh; index_count 0 = all of them.
  // A range must lie inside the mesh and hold whole triangles (GpuScene's culled items are such ranges).
  uint32_t first_index = 0;
  uint32_t index_count = 0;

  uint64_t triangleCount() const {
    return mesh ? (index_count ? index_count : mesh->indexCount()) / 3 : 0;
  }
};

enum class RenderMode {
  Shaded,      // lit, textured colour + ids
  ItemBuffer,  // ids only (colour gets a flat false colour of the id, background black); no texture sampling
};

struct LightSettings {
  Vec3 direction{-0.4f, -0.3f, -0.85f};  // direction the light travels (towards the ground)
  Vec3 color{1.0f, 0.97f, 0.92f};
  float ambient = 0.35f;
  Vec4 sky_color{0.62f, 0.74f, 0.88f, 1.0f};  // clear colour
};

struct FrameStats {
  uint64_t triangles = 0;
  uint32_t draw_calls = 0;
  uint32_t objects = 0;  // distinct object ids drawn
  double wall_ms = 0.0;  // CPU wall time from the first command to glFinish
  double gpu_ms = 0.0;   // GL_TIME_ELAPSED, at most wall_ms (see GpuTimer); 0 from draw()
};

class Renderer {
 public:
  Renderer();  // needs a current context
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  LightSettings& light() { return light_; }
  // Depth ties (coplanar surfaces of different objects): by default the first item drawn keeps the pixel
  // (GL_GREATER); with last_wins_ties the last one does (GL_GEQUAL). The pixels where the two frames differ are those
  // whose content depends on draw order, which any renderer resolves its own way; comparisons leave them out.
  void setLastWinsTies(bool last_wins_ties) { last_wins_ties_ = last_wins_ties; }
  // Clears the target, draws the items and waits for the GPU (glFinish) so the wall time is the frame's.
  FrameStats render(const Camera& camera, std::span<const DrawItem> items, RenderTarget& target,
                    RenderMode mode = RenderMode::Shaded);
  // Draws without clearing and without waiting (for composing several passes into one frame).
  FrameStats draw(const Camera& camera, std::span<const DrawItem> items, RenderTarget& target,
                  RenderMode mode = RenderMode::Shaded);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  LightSettings light_;
  bool last_wins_ties_ = false;
};

struct GpuSceneOptions {
  // Culling units of the culling overloads of GpuScene::appendDrawItems: each mesh is split into spatial clusters of
  // at most this many triangles, then by facing (clusterTriangles). Smaller clusters drop more triangles out of view
  // but cost more draw calls (llvmpipe: about 7.5 us per draw call, 0.1-0.25 us per triangle). On the demo city's
  // car path (640x360) 2048 gave the lowest culled/full time of 1024-8192 (at 64x36, where geometry dominates:
  // 0.076 against 0.081 for 1024, about 0.10 for 4096 and 8192; 1024 doubles the draw calls for 3 % fewer triangles).
  uint32_t cluster_triangles = 2048;
  // A facing class holding fewer triangles of a spatial cluster joins its mixed cluster.
  uint32_t min_facing_triangles = 64;
  // Culled clusters of at most this many triangles between two drawn ones of a part are drawn anyway, so the two
  // stay one draw call (which costs more than that many triangles); drawing more never changes a pixel.
  uint32_t bridge_triangles = 48;
};

// What drawing one object whole costs beyond a frame's fixed cost (the cost model's terms).
struct ObjectDrawCost {
  uint64_t triangles = 0;
  uint32_t draws = 0;  // draw items: one per part
};

// A scene's meshes, textures and materials uploaded once; draw items for all or some of its objects.
class GpuScene {
 public:
  // Keeps a pointer to the scene (for its objects), which must outlive the GpuScene. Throws farfield::Error for
  // unusable meshes or textures. Each mesh is uploaded with its triangles reordered into its clusters and its
  // vertices in the order they first use them (reorderedMesh: the same triangles; a whole-mesh draw draws them in
  // cluster order).
  explicit GpuScene(const scene::Scene& scene, const GpuSceneOptions& options = {});
  // One draw item per part of each listed object (ids 1-based); all objects when ids is empty. Throws
  // farfield::Error for an id out of range.
  void appendDrawItems(std::span<const uint32_t> ids, std::vector<DrawItem>& out) const;
  // Only the clusters of the listed objects' parts whose bounds (under the object's current transform) meet the
  // frustum (Frustum::intersects, conservative: a cluster left out draws no pixel of a camera with that
  // view-projection). Runs of consecutive visible clusters of a part become one item (an index range); every item
  // keeps its object's id, material and transform, and items come in the order of the overload above, so the
  // frame is pixel-identical to drawing all items of the listed objects. All objects when ids is empty; throws
  // farfield::Error for an id out of range.
  void appendDrawItems(std::span<const uint32_t> ids, std::vector<DrawItem>& out, const Frustum& frustum) const;
  // The same for the camera's frustum, less the clusters of single-sided materials whose triangles all face away
  // from the camera's eye (facesAway: back-face culling would draw none of their pixels). Pixel-identical to all
  // items of the listed objects drawn with this camera.
  // item_bounds, when given, receives for each item appended the bounds of its clusters in its mesh's own space
  // (the item's transform takes them to the world), parallel to out (occlusion culling tests them).
  void appendDrawItems(std::span<const uint32_t> ids, std::vector<DrawItem>& out, const Camera& camera,
                       std::vector<Box3>* item_bounds = nullptr) const;
  std::vector<DrawItem> drawItems() const;
  const scene::Scene& scene() const { return *scene_; }
  // Per object id (index 0 unused, size objects + 1): the triangles and draw items of appendDrawItems for it alone.
  std::vector<ObjectDrawCost> objectDrawCosts() const;
  size_t gpuBytes() const;
  // Clusters of scene mesh `mesh` (index ranges of meshes()[mesh], bounds in mesh space) and their facing groups.
  std::span<const MeshCluster> clusters(uint32_t mesh) const { return clusters_.at(mesh); }
  std::span<const FacingGroup> facing(uint32_t mesh) const { return facing_.at(mesh); }
  const std::vector<GpuMesh>& meshes() const { return meshes_; }

 private:
  const scene::Object& checkedObject(uint32_t id) const;
  void checkParts(const scene::Object& object) const;
  void appendCulled(std::span<const uint32_t> ids, std::vector<DrawItem>& out, const Frustum& frustum,
                    const Vec3* eye, std::vector<Box3>* item_bounds) const;

  const scene::Scene* scene_;
  std::vector<GpuMesh> meshes_;
  std::vector<std::vector<MeshCluster>> clusters_;  // per mesh
  std::vector<std::vector<FacingGroup>> facing_;    // per mesh
  uint32_t bridge_indices_ = 0;
  std::vector<Texture> textures_;
  std::vector<GpuMaterial> materials_;
};

}  // namespace farfield::gpu
