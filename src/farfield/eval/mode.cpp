#include "farfield/eval/mode.h"

#include <algorithm>
#include <optional>
#include <mutex>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/eval/gpu_culled_mode.h"
#include "farfield/eval/governed_mode.h"
#include "farfield/eval/occlusion_pass.h"

namespace farfield::eval {

std::string ModeContext::option(const std::string& key, const std::string& fallback) const {
  read_keys->insert(key);
  auto it = options.find(key);
  return it == options.end() ? fallback : it->second;
}

const std::string& ModeContext::requireOption(const std::string& key, const std::string& mode_name) const {
  read_keys->insert(key);
  auto it = options.find(key);
  if (it == options.end())
    throw Error("mode '" + mode_name + "'", "needs the option '" + key + "' (--mode-option " + key + "=VALUE)");
  return it->second;
}

const gpu::SceneArena& ModeContext::arena() const {
  FF_CHECK_MSG(scene != nullptr, "ModeContext::arena() needs the scene");
  if (!arena_slot->arena) {
    Stopwatch clock;
    gpu::ArenaOptions options;
    options.lod_ratio = arena_slot->simplified_levels ? 0.25f : 0.0f;
    arena_slot->arena = std::make_unique<gpu::SceneArena>(*scene, options);
    arena_slot->build_s = clock.seconds();
  }
  return *arena_slot->arena;
}

std::map<std::string, std::string> parseModeOptions(const std::vector<std::string>& items) {
  std::map<std::string, std::string> options;
  for (const std::string& item : items) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw Error("--mode-option", "expected key=value, got '" + item + "'");
    options[item.substr(0, eq)] = item.substr(eq + 1);
  }
  return options;
}

// ---------------------------------------------------------------------------------------------------------------
// FrameContext

FrameContext::FrameContext(const Camera& camera, size_t path_frame, gpu::Renderer& renderer,
                           gpu::RenderTarget& target, std::vector<gpu::DrawItem>& items, gpu::GpuTimer* timer)
    : camera_(camera),
      path_frame_(path_frame),
      renderer_(renderer),
      target_(target),
      items_(items),
      timer_(timer) {
  items_.clear();
}

void FrameContext::clearOnce(bool clear) {
  if (drew_passes_) return;
  drew_passes_ = true;
  if (timer_) timer_->begin();
  if (clear) target_.clear(renderer_.light().sky_color);
}

gpu::FrameStats FrameContext::drawPass(std::span<const gpu::DrawItem> items, gpu::RenderMode mode) {
  clearOnce();
  gpu::FrameStats stats = renderer_.draw(camera_, items, target_, mode);
  addStats(stats);
  return stats;
}

gpu::FrameStats FrameContext::drawMainPass() {
  if (!drew_passes_) {
    target_.bind();  // before the timer's query starts (see Renderer::render)
    clearOnce();
  }
  gpu::FrameStats stats = pass_stats_;
  if (!mainItems().empty()) {
    const gpu::FrameStats main = renderer_.draw(camera_, mainItems(), target_);
    stats.triangles += main.triangles;
    stats.draw_calls += main.draw_calls;
    stats.objects += main.objects;
  }
  return stats;
}

gpu::RenderTarget& FrameContext::beginOwnPass() {
  clearOnce();
  return target_;
}

gpu::RenderTarget& FrameContext::beginOwnPassOverwritingAll() {
  clearOnce(false);
  return target_;
}

void FrameContext::addStats(const gpu::FrameStats& stats) {
  pass_stats_.triangles += stats.triangles;
  pass_stats_.draw_calls += stats.draw_calls;
  // Distinct objects across passes are not tracked; an object drawn in two passes counts twice. Modes that care
  // report a corrected figure through info().
  pass_stats_.objects += stats.objects;
}

// ---------------------------------------------------------------------------------------------------------------
// Built-in modes

namespace {

// Every object of the scene, every frame: the baseline every other mode is measured against.
class FullMode final : public Mode {
 public:
  std::string name() const override { return "full"; }
  void prepare(const ModeContext& context) override { items_ = context.gpu_scene->drawItems(); }
  void frame(FrameContext& frame) override { frame.submit(items_); }
  std::map<std::string, double> info() const override { return {{"draw_items", double(items_.size())}}; }

 private:
  std::vector<gpu::DrawItem> items_;
};

// View-frustum culling on the CPU: object bounds through the BVH, then the clusters of those objects' meshes
// (GpuScene's culling units: in the frustum and not all facing away); what a plain renderer does before any impostor.
// With occlusion (the "culled-cpu" mode, "culled" before the GPU-driven frame), the nearest clusters are drawn first,
// their depth read back, and the others hidden behind it dropped (gpu::OcclusionCuller: exact, the frame stays the
// frame of "frustum").
class CulledMode final : public Mode {
 public:
  CulledMode(const ModeContext& context, bool occlusion) : gpu_scene_(context.gpu_scene), bvh_(context.bvh) {
    if (occlusion) occlusion_.emplace(occluderShareOption(context, "culled-cpu"));
  }
  std::string name() const override { return occlusion_ ? "culled-cpu" : "frustum"; }
  void frame(FrameContext& frame) override {
    ids_.clear();
    bvh_->queryFrustum(Frustum::fromMatrix(frame.camera().viewProjection()), ids_);
    // GpuScene::appendDrawItems takes an empty list as "all objects": nothing visible must draw nothing.
    if (ids_.empty()) return;
    // Same order as "full" (ascending ids), so objects at equal depth resolve the same way in both modes.
    std::sort(ids_.begin(), ids_.end());
    if (!occlusion_) {
      gpu_scene_->appendDrawItems(ids_, frame.items(), frame.camera());
      return;
    }
    candidates_.clear();
    bounds_.clear();
    gpu_scene_->appendDrawItems(ids_, candidates_, frame.camera(), &bounds_);
    occlusion_->run(frame, candidates_, bounds_);
  }
  std::map<std::string, double> info() const override {
    if (!occlusion_) return {};
    return occlusion_->info();
  }

 private:
  const gpu::GpuScene* gpu_scene_;
  const scene::Bvh* bvh_;
  std::optional<OcclusionPass> occlusion_;
  std::vector<uint32_t> ids_;
  std::vector<gpu::DrawItem> candidates_;
  std::vector<Box3> bounds_;
};

struct Entry {
  std::string description;
  ModeFactory factory;
};

struct Registry {
  std::mutex mutex;
  std::map<std::string, Entry> entries;
};

// Built-ins are added here rather than by static objects in their own files: the eval library is static, and the
// linker would drop a file that nothing refers to, registration included.
Registry& registry() {
  static Registry* r = [] {
    auto* reg = new Registry;
    reg->entries["full"] = {"every object of the scene (the baseline)",
                            [](const ModeContext&) { return std::make_unique<FullMode>(); }};
    reg->entries["culled"] = {"the GPU-driven frame: the scene's clusters culled by compute shaders (frustum, normal "
                              "cones, two-phase hierarchical-Z occlusion), one multi-draw per material group",
                              [](const ModeContext& c) { return std::make_unique<GpuCulledMode>(c); }};
    reg->entries["governed"] = {"another mode (--mode-option governed=MODE, default culled) under a frame governor "
                                "that keeps --tmax in a closed loop, coarsening the render resolution before a frame "
                                "would exceed it; every coarsened frame reported with the bound it kept",
                                [](const ModeContext& c) { return std::make_unique<GovernedMode>(c); }};
    reg->entries["culled-cpu"] = {"clusters in the view frustum (BVH), not facing away, not hidden behind the nearest "
                                  "ones (culled on the CPU, the occluders' depth read back)",
                                  [](const ModeContext& c) { return std::make_unique<CulledMode>(c, true); }};
    reg->entries["frustum"] = {"clusters in the view frustum (BVH) and not facing away: culled without occlusion",
                               [](const ModeContext& c) { return std::make_unique<CulledMode>(c, false); }};
    return reg;
  }();
  return *r;
}

std::string knownList() {
  std::string list;
  for (const auto& name : modeNames()) list += (list.empty() ? "" : ", ") + name;
  return list;
}

}  // namespace

void registerMode(const std::string& name, const std::string& description, ModeFactory factory) {
  FF_CHECK(!name.empty() && factory);
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.entries[name] = {description, std::move(factory)};
}

std::vector<std::string> modeNames() {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& [name, entry] : r.entries) names.push_back(name);
  return names;  // std::map keeps them sorted
}

std::string modeDescription(const std::string& name) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  auto it = r.entries.find(name);
  return it == r.entries.end() ? std::string() : it->second.description;
}

bool hasMode(const std::string& name) {
  Registry& r = registry();
  std::lock_guard<std::mutex> lock(r.mutex);
  return r.entries.count(name) != 0;
}

void checkModeNames(std::span<const std::string> names) {
  for (const auto& name : names)
    if (!hasMode(name)) throw Error("mode '" + name + "'", "unknown mode; known modes: " + knownList());
}

std::unique_ptr<Mode> createMode(const std::string& name, const ModeContext& context) {
  ModeFactory factory;
  {
    Registry& r = registry();
    std::lock_guard<std::mutex> lock(r.mutex);
    auto it = r.entries.find(name);
    if (it != r.entries.end()) factory = it->second.factory;
  }
  if (!factory) throw Error("mode '" + name + "'", "unknown mode; known modes: " + knownList());
  std::unique_ptr<Mode> mode = factory(context);
  FF_CHECK(mode != nullptr);
  return mode;
}

ModeRunResources::ModeRunResources(const scene::Scene& scene, int width, int height,
                                   std::map<std::string, std::string> options)
    : gpu_scene(scene), bvh(scene), target(width, height) {
  context.scene = &scene;
  context.gpu_scene = &gpu_scene;
  context.bvh = &bvh;
  context.renderer = &renderer;
  context.width = width;
  context.height = height;
  context.options = std::move(options);
}

void addImpostorFrames(const std::map<size_t, bool>& frames, std::map<std::string, double>& info) {
  size_t with = 0, run = 0, best = 0, run_first = 0, best_first = 0, best_last = 0;
  for (const auto& [path_frame, impostor] : frames) {
    if (!impostor) {
      run = 0;
      continue;
    }
    ++with;
    if (run == 0) run_first = path_frame;
    if (++run > best) best = run, best_first = run_first, best_last = path_frame;
  }
  info["frames_with_impostors"] = double(with);
  for (const char* key : {"impostor_stretch_first_frame", "impostor_stretch_last_frame", "impostor_stretch_frames"})
    info.erase(key);
  if (best > 0) {
    info["impostor_stretch_first_frame"] = double(best_first);
    info["impostor_stretch_last_frame"] = double(best_last);
    info["impostor_stretch_frames"] = double(best);
  }
}

}  // namespace farfield::eval
