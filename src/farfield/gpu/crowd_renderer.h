// Crowd rendering: skinned models drawn for many agents with one instanced draw per model (joint matrices of a
// palette of sampled poses in a storage buffer, agents in another), and multi-view impostor atlases drawn as one
// instanced camera-facing quad per agent. Also the capture pass that bakes an atlas, the agents' colour regions
// tinted per agent (16 per outfit, the lecture's colour variety) and the shadow casters' depth-only draws.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/program.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/texture.h"
#include "farfield/scene/deforming_lod.h"
#include "farfield/scene/skin.h"

namespace farfield::gpu {

// One agent as the shaders read it (std430, 48 bytes). For skinned draws `index` is the palette pose; for
// impostors it is the animation frame (atlas layer) and `view` the view cell (elevation * azimuths + azimuth).
// `outfit` picks the row of colour-region tints (CrowdRenderer::setRegionTints) that modulates the agent.
struct CrowdAgentGpu {
  Vec4 pos_heading{0.0f};  // xyz metres, w heading (radians about +z)
  Vec4 tint{1.0f};
  uint32_t index = 0;
  uint32_t view = 0;
  uint32_t object_id = 0;
  uint32_t outfit = 0;
};
static_assert(sizeof(CrowdAgentGpu) == 48);

// How a skinned model's vertices reach their pose. Agents only ever take the palette's sampled poses, so each pose
// can be skinned once (on the CPU, scene::skinMesh) and every agent read its pose's vertices: BakedPoses stores
// poses x vertices positions and normals (32 bytes each) and its vertex shader reads one position and one normal
// instead of blending four joint matrices; Palette stores the joint matrices and blends them per vertex (linear
// blend skinning on the GPU). The same images either way; on llvmpipe the baked poses draw skinned agents faster
// (docs/BENCHMARKS.md, Crowds).
enum class Skinning { Palette, BakedPoses };

// A skinned model on the GPU with its pose palette. model_to_agent places the skinned (Z-up) model in agent space:
// feet on z = 0, facing +x, at the agent's scale. Level 0 is the model's mesh; levels 1.. are coarser index buffers
// over the same vertices (scene::deformingLevels), drawn with the same poses.
class SkinnedGpuModel {
 public:
  // poses[p] holds the joint matrices of pose p (one per joint, scene::jointMatrices). Throws farfield::Error for
  // an empty palette, a pose with the wrong joint count (after validateSkinnedModel) or a level whose indices or
  // source triangles are out of range.
  SkinnedGpuModel(const scene::SkinnedModel& model, const Mat4& model_to_agent,
                  const std::vector<std::vector<Mat4>>& poses, std::span<const scene::DeformingLevel> levels = {},
                  Skinning skinning = Skinning::BakedPoses);
  ~SkinnedGpuModel();
  SkinnedGpuModel(const SkinnedGpuModel&) = delete;
  SkinnedGpuModel& operator=(const SkinnedGpuModel&) = delete;

  uint32_t jointCount() const { return joint_count_; }
  uint32_t poseCount() const { return pose_count_; }
  uint32_t indexCount() const { return levels_[0].index_count; }  // the mesh's (level 0)
  // A level's range of the index buffer (level 0: the mesh).
  uint32_t indexCount(size_t level) const { return levels_[level].index_count; }
  uint32_t firstIndex(size_t level) const { return levels_[level].first_index; }
  size_t levelCount() const { return levels_.size(); }
  uint64_t triangleCount(size_t level = 0) const { return levels_[level].index_count / 3; }
  const Mat4& modelToAgent() const { return model_to_agent_; }
  Skinning skinning() const { return skinning_; }
  // Whether some texel's albedo alpha (base colour x texture) is below 0.5, so that drawing must cut it out; without,
  // the fragment shader has no discard and the depth test can run before it.
  bool cutout() const { return cutout_; }
  size_t gpuBytes() const { return bytes_; }

 private:
  friend class CrowdRenderer;
  // palette_: the joint matrices (Palette) or every pose's skinned vertices (BakedPoses), storage binding 0.
  uint32_t vao_ = 0, vbo_ = 0, ibo_ = 0, palette_ = 0, regions_ = 0;
  uint32_t joint_count_ = 0, pose_count_ = 0, vertex_count_ = 0;
  Skinning skinning_ = Skinning::BakedPoses;
  bool cutout_ = true;
  // Per level: its range of the index buffer and its first triangle's colour region in the regions buffer.
  struct Level {
    uint32_t first_index = 0, index_count = 0, first_triangle = 0;
  };
  std::vector<Level> levels_;
  Mat4 model_to_agent_{1.0f};
  Vec4 base_color_{1.0f};
  Texture texture_;
  bool textured_ = false;
  size_t bytes_ = 0;
};

// Geometry of a multi-view atlas (impostor/multi_view.h chooses it): a grid of azimuths x elevations cells of
// cell_width x cell_height texels per layer, one layer per animation frame.
struct AtlasLayout {
  int azimuths = 32;
  int elevations = 8;
  int cell_width = 32;
  int cell_height = 64;
  int frames = 16;
  Vec2 half_size{1.0f};  // metres: the quad's half extent right and up
  Vec3 centre{0.0f};     // agent space
  float radius = 1.0f;   // metres: depth normalisation
  float max_elevation = 1.5707964f;  // radians: ring j at j * max_elevation / elevations (view blending)
  bool octahedral = false;  // the cells are an N x N octahedral map of the hemisphere (impostor::ViewGrid)
  int width() const { return azimuths * cell_width; }
  int height() const { return elevations * cell_height; }
};

// Albedo (RGBA8) and normal + depth (RGBA8) texture arrays of an atlas, linear filtering, clamped. The albedo's alpha
// codes coverage and the colour region (crowd.frag.glsl: 0 = empty, (16 (r + 1) - 1) / 255 = region r).
class ImpostorAtlasGpu {
 public:
  explicit ImpostorAtlasGpu(const AtlasLayout& layout);
  ~ImpostorAtlasGpu();
  ImpostorAtlasGpu(const ImpostorAtlasGpu&) = delete;
  ImpostorAtlasGpu& operator=(const ImpostorAtlasGpu&) = delete;
  const AtlasLayout& layout() const { return layout_; }
  size_t byteSize() const;  // both arrays, uncompressed
  // Readback of one layer (row 0 at the bottom of the layer, as GL stores it); for tests and sample images.
  image::ColorImage readAlbedo(int layer) const;
  image::ColorImage readNormalDepth(int layer) const;

 private:
  friend class CrowdRenderer;
  AtlasLayout layout_;
  uint32_t albedo_ = 0, normal_depth_ = 0, depth_ = 0, fbo_ = 0;
};

// One capture view of a bake: the orthographic view-projection, the unit direction towards the camera and the
// atlas cell it fills.
struct CaptureView {
  Mat4 view_proj{1.0f};
  Vec3 to_camera{1.0f, 0.0f, 0.0f};
  int cell = 0;  // elevation * azimuths + azimuth
};

class CrowdRenderer {
 public:
  CrowdRenderer();  // needs a current context
  ~CrowdRenderer();
  CrowdRenderer(const CrowdRenderer&) = delete;
  CrowdRenderer& operator=(const CrowdRenderer&) = delete;

  // Draw into the bound target (RenderTarget::bindForOpaquePass), no clear, no wait: the agents of one model in one
  // instanced draw. Agents' `index` must be < the model's pose count (FF_CHECK).
  FrameStats drawSkinned(const Camera& camera, const SkinnedGpuModel& model, std::span<const CrowdAgentGpu> agents,
                         const LightSettings& light, size_t level = 0);
  // One instanced draw of quads; agents' `index` < frames and `view` < azimuths * elevations (FF_CHECK). With
  // blend_views, each quad blends the four views around its direction to the eye (bilinear in azimuth and
  // elevation) instead of showing `view`.
  FrameStats drawImpostors(const Camera& camera, const ImpostorAtlasGpu& atlas, std::span<const CrowdAgentGpu> agents,
                           const LightSettings& light, bool blend_views = false);
  // The same draws for agents whose records the GPU wrote (gpu_crowd.h): `bytes` of records at `offset` of the
  // storage buffer `agents`, drawn by the indirect command at `command_offset` of `commands` (its instance count
  // written on the GPU: skinned, a DrawElementsIndirectCommand over the mesh; impostors, a DrawArraysIndirectCommand
  // of 4 vertices). No upload and no wait; the stats count the draw call alone (the agents are known on the GPU).
  // level: the model's level of detail the command draws (its colour regions; the command holds its index range).
  FrameStats drawSkinnedIndirect(const Camera& camera, const SkinnedGpuModel& model, uint32_t agents, size_t offset,
                                 size_t bytes, uint32_t commands, size_t command_offset, const LightSettings& light,
                                 size_t level = 0);
  // blend_views as drawImpostors' (the four views around each quad's direction, found in the vertex shader).
  FrameStats drawImpostorsIndirect(const Camera& camera, const ImpostorAtlasGpu& atlas, uint32_t agents,
                                   size_t offset, size_t bytes, uint32_t commands, size_t command_offset,
                                   const LightSettings& light, bool blend_views = false);
  // The shadow casters' depth-only draws for GPU-written records, as drawSkinnedIndirect and drawImpostorsIndirect.
  FrameStats drawSkinnedDepthIndirect(const Mat4& light_view_proj, const SkinnedGpuModel& model, uint32_t agents,
                                      size_t offset, size_t bytes, uint32_t commands, size_t command_offset,
                                      size_t level = 0);
  FrameStats drawImpostorDepthIndirect(const Mat4& light_view_proj, const Vec3& to_light,
                                       const ImpostorAtlasGpu& atlas, uint32_t agents, size_t offset, size_t bytes,
                                       uint32_t commands, size_t command_offset);
  // Renders pose `pose` of the model (agent at the origin, heading 0) into `layer` of the atlas, one cell per view;
  // clears the layer first. Leaves the default framebuffer state to the caller (rebind your target after).
  void capture(const SkinnedGpuModel& model, uint32_t pose, ImpostorAtlasGpu& atlas, int layer,
               std::span<const CaptureView> views);
  // Waits for the GPU (glFinish): bake timings.
  void finish() const;

  // The colour-region tints of every outfit: outfit o, region r at tints[o * scene::kColorRegions + r] (RGB used).
  // Agents read outfit `outfit mod outfitCount()`. Initially one outfit of white. Throws farfield::Error for an empty
  // table or one that is not a whole number of outfits.
  void setRegionTints(std::span<const Vec4> tints);
  uint32_t outfitCount() const { return outfits_; }

  // Shadow casters, drawn into the bound depth-only target (ShadowMap::bindForCasters) with the light's
  // orthographic view-projection; no colour, no ids. Skinned agents as drawSkinned. Impostor agents as quads facing
  // `to_light` (unit, towards the light), each agent's `view` being its view cell towards the light, with the
  // baked depth per texel.
  FrameStats drawSkinnedDepth(const Mat4& light_view_proj, const SkinnedGpuModel& model,
                              std::span<const CrowdAgentGpu> agents, size_t level = 0);
  FrameStats drawImpostorDepth(const Mat4& light_view_proj, const Vec3& to_light, const ImpostorAtlasGpu& atlas,
                               std::span<const CrowdAgentGpu> agents);

 private:
  uint32_t uploadAgents(std::span<const CrowdAgentGpu> agents);
  void bindModel(const Program& p, const SkinnedGpuModel& model) const;
  // One instanced draw of the model's level for `count` agents (program, model and agents bound), and its counts.
  FrameStats drawAgents(const Program& p, const SkinnedGpuModel& model, size_t count, size_t level) const;
  void bindAtlas(const Program& p, const ImpostorAtlasGpu& atlas) const;
  // One indirect draw of the command at command_offset of `commands` over `vao`: the indexed mesh or a 4-vertex strip.
  void drawIndirect(uint32_t vao, uint32_t commands, size_t command_offset, bool indexed) const;
  // drawSkinned's and drawSkinnedIndirect's program, uniforms and model; the same for the impostor draws.
  const Program& useSkinned(const Camera& camera, const SkinnedGpuModel& model, const LightSettings& light);
  const Program& useImpostors(const Camera& camera, const ImpostorAtlasGpu& atlas, const LightSettings& light,
                              bool blend_views);
  // The skinned programs by skinning ([0] Palette, [1] BakedPoses) and, for drawing, cut-out ([0] none, [1] cut out):
  // the model's (program()). The bake always cuts out.
  const Program& program(const Program (&programs)[2][2], const SkinnedGpuModel& model) const;
  Program skinned_[2][2], skinned_depth_[2][2], capture_[2];
  Program impostor_, impostor_blend_, impostor_depth_;
  uint32_t agents_ = 0, empty_vao_ = 0, tints_ = 0, outfits_ = 0;
};

}  // namespace farfield::gpu
