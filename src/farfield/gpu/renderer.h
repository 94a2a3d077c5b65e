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
};

// A scene's meshes, textures and materials uploaded once; draw items for all or some of its objects.
class GpuScene {
 public:
  // Keeps a pointer to the scene (for its objects), which must outlive the GpuScene. Throws farfield::Error for
  // unusable meshes or textures.
  explicit GpuScene(const scene::Scene& scene);
  // One draw item per part of each listed object (ids 1-based); all objects when ids is empty. Throws
  // farfield::Error for an id out of range.
  void appendDrawItems(std::span<const uint32_t> ids, std::vector<DrawItem>& out) const;
  std::vector<DrawItem> drawItems() const;
  size_t gpuBytes() const;

 private:
  const scene::Scene* scene_;
  std::vector<GpuMesh> meshes_;
  std::vector<Texture> textures_;
  std::vector<GpuMaterial> materials_;
};

}  // namespace farfield::gpu
