// Crowd runtime: per frame, each agent in view is drawn as skinned instanced geometry or as a multi-view impostor
// (Tecchia, Loscos and Chrysanthou; Steed's lecture part 3), chosen by the impostor's promises: geometry where a
// texel of the atlas would cover more than a pixel (Dobbyn et al.'s switch) or where the view quantisation error
// would exceed the error bound; the nearest view and animation frame per agent otherwise. Agents are tinted per
// colour region by their outfit, identically in both representations, and may cast shadows onto the city and the
// ground through one shadow map (drawShadowed).
#pragma once

#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/crowd_renderer.h"
#include "farfield/gpu/gpu_crowd.h"
#include "farfield/gpu/gpu_timer.h"
#include "farfield/gpu/late_readback.h"
#include "farfield/gpu/occlusion_culler.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/shadow_map.h"
#include "farfield/impostor/multi_view.h"
#include "farfield/runtime/crowd_shadows.h"
#include "farfield/runtime/triangle_rate.h"
#include "farfield/scene/skin.h"

namespace farfield::runtime {

// Object-id bit of agents: pixels with it set do not receive the crowd's shadows (CrowdShadowOptions).
inline constexpr uint32_t kAgentIdBit = 0x80000000u;

// What the caller (a crowd simulation, eval's generated crowd) gives per agent and frame.
struct CrowdAgentState {
  uint32_t model = 0;
  Vec3 position{0.0f};  // feet
  float heading = 0.0f;  // radians about +z, facing
  float phase = 0.0f;    // animation phase in [0, 1)
  Vec4 tint{1.0f};
  uint32_t outfit = 0;     // row of CrowdRuntimeOptions::region_tints (mod the outfit count)
  uint32_t object_id = 0;  // for the id buffer
};

struct CrowdModelOptions {
  float height_m = 1.75f;      // the model is scaled to this height (animated bounds)
  float facing_deg = 90.0f;    // turn about +z that brings the model's front to +x (glTF fronts +Z: 90 after Z up)
  std::string animation = "walk";  // name looked up by SkinnedModel::findAnimation
};

enum class CrowdPolicy { Geometry, Impostor, Mixed };

struct CrowdRuntimeOptions {
  int palette_poses = 64;  // skinned poses per animation cycle (geometry)
  // The atlas, fixed: frames per cycle (divides palette_poses), views (32 x 8 as in the lecture), texel (metres).
  int frames = 16;
  impostor::ViewGrid grid;
  float texel_m = 0.03f;
  double error_px = 2.0;  // the error bound (pixels): Mixed's switch (view, texel and frame errors)
  // Or chosen per model from the error bound (atlas_from_bound; frames, grid and texel_m above are then not used):
  // for impostors from bound_switch_m metres on at a camera of bound_focal_px (pixels per unit tangent), the texel
  // and views of impostor::chooseForBound and the fewest frames dividing palette_poses whose frame error
  // (impostor::framesForBound) stays under error_px there.
  bool atlas_from_bound = false;
  double bound_switch_m = 20.0;
  double bound_focal_px = 443.4;  // 512 px at 60 degrees
  // Impostors blend the four views around their direction to the eye instead of showing the nearest (an option,
  // as octahedral impostors blend their three nearest views); shadow casters keep the nearest view to the light.
  bool blend_views = false;
  // Colour-region tints: outfit o, region r at o * scene::kColorRegions + r; empty = one outfit of white.
  std::vector<Vec4> region_tints;
  // Mixed's geometry budget (skinned triangles a frame; 0: none) for the agents in view nearer than their switch
  // distance. Where their levels of detail (geometry_lod_px) exceed it, agents become impostors inside their switch
  // distance (CrowdFrameStats::over_budget), or with budget_coarsens also take coarser levels
  // (CrowdFrameStats::coarsened), one step at a time, each to the agent whose next step shows the least error on
  // screen: a level's distance to the mesh, or an impostor's error, which grows as 1 / distance from the bound at the
  // switch (levels that show more than the impostor are skipped). For one model the impostors are the farthest
  // agents. Where the error bound gives way to the frame's cost, the largest error on screen ends as small as the
  // budget allows. Agents
  // outside the view then cast their shadows as impostors. A crowd as dense near the camera as far from it costs
  // geometry in proportion to its density without it (100,000 agents on the default city: 59 skinned agents a frame).
  uint64_t max_geometry_triangles = 0;
  // Mixed's geometry budget in milliseconds of skinned drawing a frame (0: none), beside or instead of the triangles
  // above (the smaller holds): each frame's skinned draws are timed (gpu::GpuTimer), and the budget in triangles is
  // geometry_ms over the moving average of the measured time per triangle times the largest measured / predicted
  // ratio of the last 16 frames (runtime::TriangleRate; 10,000 triangles before the first measurement). A frame's
  // measurement is read when the next frame is prepared (the GPU path: when the GPU has finished it, frames later).
  double geometry_ms = 0.0;
  // Under the budget, coarser levels as well as impostors (above). Off by default: on the crowd bench's walks the
  // coarser levels kept the budget at a lower PSNR than impostors of the farthest (docs/BENCHMARKS.md, Crowds).
  bool budget_coarsens = false;
  // Mixed's skinned agents at levels of detail that hold in every pose (scene::deformingLevels over the palette's
  // poses in agent space, each level's error measured over every palette pose): an agent drawn as geometry takes
  // the coarsest level whose error (lod_texture) stays within geometry_lod_px pixels at its distance; 0: the mesh
  // alone. The Geometry policy (the baseline) always draws the mesh.
  double geometry_lod_px = 0.0;
  // A level's error for that rule is the larger of its distance to the mesh and its texture deviation (how far it
  // moves a texel, scene::textureDeviation): a textured figure's colours move with its triangles inside its outline
  // too, and a pixel bound is a bound on how far anything on screen moves. Off: the distance alone.
  bool lod_texture = true;
  // The levels' triangles as fractions of the mesh's: close steps, so that the rule finds a level near each distance.
  std::vector<double> lod_ratios{0.5, 0.35, 0.25, 0.18, 0.125, 0.09, 0.0625};
  // How skinned agents reach their palette pose (gpu::Skinning), in every policy and the atlas bake: the same images;
  // the baked poses are faster on llvmpipe, the palette the smaller (joint matrices instead of vertices per pose).
  gpu::Skinning skinning = gpu::Skinning::BakedPoses;
};

// The crowd's shadows (drawShadowed).
struct CrowdShadowOptions {
  // 1024 and 60 m: on llvmpipe (2 cores, 512x512, 10,000 agents) a 2048 map cost about 20 ms more a frame than
  // 1024 (docs/BENCHMARKS.md, Crowds); within 60 m a map texel is about 6 cm, beyond it shadows are a few pixels.
  int map_size = 1024;         // texels per side
  float distance_m = 60.0f;    // receivers up to this far along the view
  float bias_m = 0.03f;        // depth bias, metres along the light
  uint32_t agent_id_mask = kAgentIdBit;  // pixels whose id has these bits receive no shadow
  // Under the Mixed policy, the agents drawn as geometry cast as impostors too (their view towards the light): a quad
  // instead of a skinned mesh in the shadow map, for shadows that differ from the geometry's by the impostor's view
  // and frame quantisation. The Geometry policy always casts geometry.
  bool impostor_casters = false;
};

// What the atlas of a model holds and why (CrowdRuntimeOptions).
struct CrowdAtlasChoice {
  impostor::ViewGrid grid;
  int frames = 0;
  float texel_m = 0.0f;
  double frame_error_m = 0.0;  // impostor::frameError of the frames
  bool from_bound = false;
};

// Agents drawn in a frame, by representation.
struct CrowdFrameStats {
  size_t in_view = 0;
  size_t occluded = 0;  // of in_view: left out behind the depth given to cullBehind
  size_t geometry = 0;
  size_t impostors = 0;
  size_t over_budget = 0;  // of impostors: inside their switch distance, left out of Mixed's geometry budget
  size_t coarser = 0;      // of geometry: drawn at a level of detail coarser than the mesh (geometry_lod_px)
  size_t coarsened = 0;    // of geometry: at a level coarser than geometry_lod_px gives them, for the budget
  size_t shadow_casters = 0;  // drawShadowed: agents drawn into the shadow map
  float shadow_texel_m = 0.0f;
  uint64_t budget_triangles = 0;  // Mixed under a budget: this frame's skinned triangles allowed (0: no budget)
  double geometry_ms = 0.0;       // with geometry_ms: the last measured skinned draws (the previous frame's), ms
  gpu::FrameStats draw;
};

class CrowdRuntime {
 public:
  // Uploads each model with its pose palette and bakes its atlas (needs a current context). Throws
  // farfield::Error for a model without animations or options out of range.
  CrowdRuntime(std::span<const scene::SkinnedModel> models, std::span<const CrowdModelOptions> model_options,
               const CrowdRuntimeOptions& options);
  ~CrowdRuntime();

  // Draws the agents into the bound target (no clear, no wait) with the camera's frustum culling (bounding
  // spheres) and the policy: Geometry = all skinned, Impostor = all impostors, Mixed = the switch above.
  CrowdFrameStats draw(const Camera& camera, std::span<const CrowdAgentState> agents, CrowdPolicy policy,
                       const gpu::LightSettings& light);
  // As draw, into `target` (already holding the city; left bound for an opaque pass), with the agents' shadows:
  // every agent whose shadow may fall on what the camera sees within shadows.distance_m casts into one shadow map
  // from the light, in the representation the policy gives it (impostors show their view towards the light), and
  // the target's receivers are darkened (gpu::ShadowReceiver).
  CrowdFrameStats drawShadowed(const Camera& camera, std::span<const CrowdAgentState> agents, CrowdPolicy policy,
                               const gpu::LightSettings& light, const gpu::RenderTarget& target,
                               const CrowdShadowOptions& shadows = {});

  // The runtime's models as the GPU crowd's (gpu/gpu_crowd.h; issue 45): bounding spheres, strides (the walk cycle
  // played at its own rate at nominal_speed m/s), palette poses, atlas frames and view grids, the meshes' index
  // ranges. Throws farfield::Error for an octahedral atlas (its nearest view is not on the GPU yet).
  std::vector<gpu::GpuCrowdModel> gpuCrowdModels(float nominal_speed) const;
  // The crowd's frame from a GPU crowd of these models simulated to the frame's time (GpuCrowd::simulate): culled
  // and classified on the GPU by the policy (Mixed: switchDistances), drawn by one indirect draw per model and
  // representation, the meshes at level 0. With occluders (the target holding the city, the camera's size), the
  // agents hidden behind its depth are left out first (GpuCrowd::occludeBehind, cullBehind's test). No readback and
  // no per-agent upload. Mixed's budget in triangles (max_geometry_triangles) holds here too, on the GPU
  // (GpuCrowd::setGeometryBudget: impostors of the farthest, by distance buckets), and so does the budget in
  // milliseconds (geometry_ms: the skinned draws timed by gpu::LateTimer and their triangles copied by
  // GpuCrowd::captureCommands, both read frames later without waiting; on a software rasterizer the timer's clock
  // waits for the work, as a measurement), blended views and levels of detail (geometry_lod_px: GpuCrowd::
  // setLevelScale, a draw per level; casters at their drawn level); not on this path yet: budget_coarsens. The stats
  // count draw calls and the budget only (the agents are counted on the GPU: GpuCrowd::readCommands, readCounts).
  CrowdFrameStats drawGpu(const Camera& camera, gpu::GpuCrowd& crowd, CrowdPolicy policy,
                          const gpu::LightSettings& light, const gpu::RenderTarget* occluders = nullptr);
  // As drawGpu into `target` (holding the city), with the agents' shadows: the map fitted to the receivers the
  // camera sees within shadows.distance_m (runtime::fitShadowReceivers: the casters are known on the GPU only), the
  // agents whose spheres reach into it cast in the representation the policy gives them (GpuCrowd::castShadows), and
  // the target's receivers are darkened (gpu::ShadowReceiver). occlude: agents behind the target's depth left out
  // (their shadows still cast). shadows.impostor_casters is not on this path; under a budget, casters are cast as
  // they are drawn, and those not drawn as impostors (castsAsImpostor's rule).
  CrowdFrameStats drawGpuShadowed(const Camera& camera, gpu::GpuCrowd& crowd, CrowdPolicy policy,
                                  const gpu::LightSettings& light, const gpu::RenderTarget& target,
                                  const CrowdShadowOptions& shadows = {}, bool occlude = false);

  // Occlusion culling of the next draw or drawShadowed call (that call only): agents whose bounding box lies behind
  // `target`'s current depth (the city, drawn first) over the box's whole footprint are left out (gpu::DepthPyramid;
  // exact: such an agent would draw no pixel). Reads the depth back (a wait for the GPU). Shadow casters are chosen
  // without it: a hidden agent may shadow what is seen. The target must be the camera's size.
  void cullBehind(const gpu::RenderTarget& target);
  // Waits for the GPU (frame timings).
  void finish() const { renderer_.finish(); }
  // With CrowdRuntimeOptions::geometry_ms: the time of the last timed frame's skinned draws (ms; waits for it), taken
  // into the budget's cost per triangle now rather than when the next frame is prepared; 0 before any.
  double collectGeometryMs();
  // The GPU path's collectGeometryMs: the skinned draws' times and triangles that the GPU has finished (no wait),
  // taken into the budget's cost per triangle; returns the latest time (ms), 0 before any.
  double collectGpuGeometryMs(gpu::GpuCrowd& crowd);
  // The budget's current cost per skinned triangle (ms; 0 before the first measurement).
  double msPerSkinnedTriangle() const { return triangle_rate_.msPerTriangle(); }
  // The switch distance of model m for a camera (metres; Dobbyn's texel rule and the view error bound).
  impostor::SwitchDistances switchDistances(size_t m, const Camera& camera) const;
  size_t modelCount() const { return models_.size(); }
  const impostor::MultiViewImpostor& impostor(size_t m) const { return *models_[m].impostor; }
  const CrowdAtlasChoice& atlasChoice(size_t m) const { return models_[m].choice; }
  const gpu::SkinnedGpuModel& gpuModel(size_t m) const { return *models_[m].gpu; }
  double bakeSeconds() const;
  size_t atlasBytes() const;
  float cycleSeconds(size_t m) const { return models_[m].cycle_s; }
  uint64_t modelTriangles(size_t m) const { return models_[m].gpu->triangleCount(); }
  // Model m's levels of detail: level 0 is the mesh (error 0); their errors for the rule in agent metres (lod_texture).
  std::span<const double> levelDistances(size_t m) const { return models_[m].level_m; }
  // Their distances to the mesh and texture deviations (scene::textureDeviation) apart, in agent metres; with
  // lod_texture levelDistances are the larger of the two, without it the first.
  std::span<const double> levelSurfaceDistances(size_t m) const { return models_[m].level_surface_m; }
  std::span<const double> levelTextureDeviations(size_t m) const { return models_[m].level_texture_m; }
  double lodSeconds() const { return lod_seconds_; }
  // After draw or drawShadowed: agent i's level of detail if that call drew it as geometry; -1 for an impostor or an
  // agent not drawn (out of view, hidden, or i past the agents given).
  int drawnLevel(size_t i) const {
    return i < drawn_.size() && drawn_[i] == Drawn::Geometry ? int(level_[i]) : -1;
  }

 private:
  struct Model {
    std::unique_ptr<gpu::SkinnedGpuModel> gpu;
    std::unique_ptr<impostor::MultiViewImpostor> impostor;
    Vec3 centre{0.0f};  // agent space
    float radius = 1.0f;
    float cycle_s = 1.0f;
    CrowdAtlasChoice choice;
    std::vector<double> level_m{0.0};  // per level of detail: its error for the rule (agent metres)
    std::vector<double> level_surface_m{0.0};  // per level of detail: its distance to the mesh (agent metres)
    std::vector<double> level_texture_m{0.0};  // per level of detail: its texture deviation (agent metres)
  };
  // The camera's focal length in pixels (its image height over the field of view).
  static double focalOf(const Camera& camera);
  // The GPU path's frame set up for a policy: Mixed's triangle budget given to the crowd, and the switch distances
  // per model returned; throws farfield::Error for a crowd of other models.
  std::vector<float> prepareGpuCrowd(gpu::GpuCrowd& crowd, const Camera& camera, CrowdPolicy policy);
  // The GPU path's camera lists, drawn.
  CrowdFrameStats drawGpuLists(const Camera& camera, gpu::GpuCrowd& crowd, const gpu::LightSettings& light);
  // Agents' GPU records by model and representation (culled with the camera's frustum unless null).
  struct Lists {
    std::vector<std::vector<std::vector<gpu::CrowdAgentGpu>>> geometry;  // per model, per level of detail
    std::vector<std::vector<gpu::CrowdAgentGpu>> impostors;               // per model
  };
  void clearLists(Lists& lists);
  void classify(const Camera& camera, std::span<const CrowdAgentState> agents, CrowdPolicy policy,
                CrowdFrameStats& stats);
  // Mixed under a geometry budget: near_'s agents (inside their switch) into the lists, at coarser levels or as
  // impostors as the budget asks (CrowdRuntimeOptions::max_geometry_triangles), the least error on screen first.
  void fitBudget(const Camera& camera, std::span<const CrowdAgentState> agents, CrowdFrameStats& stats);
  // Whether agent i casts its shadow as an impostor: under Mixed as classify drew it (after classify).
  bool castsAsImpostor(const Camera& camera, const CrowdAgentState& a, uint32_t i, CrowdPolicy policy,
                       const CrowdShadowOptions& shadows) const;
  // Agent i into this frame's lists, as an impostor (its nearest view to the eye) or as geometry at `level`.
  void addToLists(const Camera& camera, const CrowdAgentState& a, uint32_t i, bool impostor, uint32_t level);
  // The level of detail an agent `distance` metres from the eye takes as geometry under the policy (Mixed: the
  // coarsest within geometry_lod_px).
  uint32_t levelFor(const CrowdAgentState& a, float distance, CrowdPolicy policy) const;
  // Whether the box around the sphere lies behind cullBehind's depth over its whole footprint.
  bool hidden(const Mat4& view_proj, const Vec3& centre, float radius) const;
  CrowdFrameStats drawLists(const Camera& camera, const gpu::LightSettings& light, CrowdFrameStats stats);
  void castShadows(const Camera& camera, std::span<const CrowdAgentState> agents, CrowdPolicy policy,
                   const gpu::LightSettings& light, const CrowdShadowOptions& shadows, CrowdFrameStats& stats);
  gpu::CrowdAgentGpu record(const CrowdAgentState& a) const;
  // Once a frame, for the casters and the classification: each model's switch distance for the camera (switch_m_)
  // and each agent's bounding sphere in the world (spheres_). Throws farfield::Error for an agent of a model out of
  // range.
  void prepareFrame(const Camera& camera, std::span<const CrowdAgentState> agents);

  CrowdRuntimeOptions options_;
  gpu::CrowdRenderer renderer_;
  std::vector<Model> models_;
  Lists lists_, caster_lists_;  // reused per frame
  std::vector<CasterSphere> spheres_;  // prepareFrame: per agent, this frame
  // classify: per agent, how this frame draws it (castShadows casts it alike).
  enum class Drawn : uint8_t { NotDrawn, Geometry, Impostor };
  std::vector<Drawn> drawn_;
  std::vector<uint32_t> level_;  // classify: per agent drawn as geometry, its level of detail
  std::vector<std::pair<float, uint32_t>> near_;  // classify: (distance, agent) inside the switch, under a budget
  std::vector<uint32_t> near_level_;             // fitBudget: per near_ entry, its level (max: an impostor)
  std::vector<double> impostor_m_;  // prepareFrame: per model, an impostor's error inside its switch (see fitBudget)
  std::vector<double> switch_m_;       // prepareFrame: per model, this frame's camera
  double lod_m_per_m_ = 0.0;           // prepareFrame: a level's allowed distance per metre from the eye
  // The geometry budget: budgeted() says whether there is one, budget_triangles_ is this frame's (prepareFrame).
  bool budgeted() const { return options_.max_geometry_triangles > 0 || options_.geometry_ms > 0.0; }
  uint64_t budget_triangles_ = 0;
  // geometry_ms: the skinned draws' timer, whether it holds an unread frame and how many triangles that frame drew.
  TriangleRate triangle_rate_;
  std::unique_ptr<gpu::GpuTimer> geometry_timer_;
  bool geometry_timed_ = false;
  uint64_t timed_triangles_ = 0;
  double last_geometry_ms_ = 0.0;
  // The GPU path's: its timer, its frame count, and times and triangles by frame until both have arrived.
  std::unique_ptr<gpu::LateTimer> gpu_geometry_timer_;
  uint64_t gpu_frame_ = 0;
  std::map<uint64_t, double> gpu_ms_;
  std::map<uint64_t, uint64_t> gpu_triangles_;
  gpu::DepthPyramid occluders_;  // cullBehind's depth, for the next draw
  std::vector<float> depth_rows_;
  bool cull_next_ = false;
  double lod_seconds_ = 0.0;
  std::unique_ptr<gpu::ShadowMap> shadow_map_;
  std::unique_ptr<gpu::ShadowReceiver> receiver_;
  gpu::ShadowProjection shadow_projection_;
  std::vector<glm::ivec4> shadow_screen_;  // where the casters' shadows can fall (ShadowFit::screen_rects)
};

}  // namespace farfield::runtime
