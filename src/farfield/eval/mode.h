// Benchmark modes: the one thing that differs between the techniques the walkthrough benchmark compares.
//
// A mode turns a camera into a frame. It either returns draw items for the harness to draw in one pass (full
// geometry, view-frustum culling, near geometry plus impostor quads drawn by the standard renderer), or draws
// passes itself (impostors with their own programs, dynamic impostor updates rendered into textures inside the
// frame), or both. The harness times the whole frame the same way for every mode: from the call of Mode::frame()
// (so culling and selection on the CPU count) through the clear, every pass and glFinish.
//
// Modes are created by name from a registry. Built in: "full" (every object), "culled" (the GPU-driven frame:
// eval/gpu_culled_mode.h), "culled-cpu" and "frustum" (culling on the CPU). Later modules add theirs with registerMode()
// (or a static RegisterMode object in a translation unit that the executable links for certain: static libraries
// drop object files nothing refers to) without touching the harness.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/gpu_timer.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/scene_arena.h"
#include "farfield/scene/bvh.h"
#include "farfield/scene/scene.h"

namespace farfield::eval {

// What modes are built from. The harness fills it once per run and keeps everything it points to alive (and the
// OpenGL context current) for the whole run.
struct ModeContext {
  const scene::Scene* scene = nullptr;
  const gpu::GpuScene* gpu_scene = nullptr;  // the scene's meshes, textures and materials on the GPU
  const scene::Bvh* bvh = nullptr;           // over the scene's objects
  gpu::Renderer* renderer = nullptr;         // the renderer the harness draws with
  int width = 0;                             // frame size, pixels
  int height = 0;
  // The run's frame budget (ms; `--tmax`), unset without one: the governed modes (eval/governed_mode.h) keep it.
  std::optional<double> t_max_ms;
  // Whether the harness reads the frames' object ids (the bench's item buffers); false (a walk): a mode may leave
  // them unwritten where that saves work (the governed mode's lower resolutions then scale up colour alone).
  bool ids_read = true;
  // Free-form options of the run ("--mode-option key=value"), e.g. {"impostor_dir": "baked/city"}. A mode reads
  // the keys it knows; keys are shared by all modes of a run.
  std::map<std::string, std::string> options;
  // Keys the modes asked for (option(), requireOption()), shared by the copies of a context: see
  // eval/mode_options.h, checkEveryOptionRead.
  std::shared_ptr<std::set<std::string>> read_keys = std::make_shared<std::set<std::string>>();

  // The scene's geometry arena (gpu/scene_arena.h) for the GPU-driven modes: made on first use (the context current)
  // and shared by the copies of this context.
  const gpu::SceneArena& arena() const;
  struct ArenaSlot {
    std::unique_ptr<gpu::SceneArena> arena;
    double build_s = 0.0;  // how long making it took
    // Whether it is made with simplified levels (gpu::ArenaOptions::lod_ratio): a mode that draws them (governed)
    // asks before the run's modes are prepared; they cost build time (measuring each level's deviation).
    bool simplified_levels = false;
  };
  std::shared_ptr<ArenaSlot> arena_slot = std::make_shared<ArenaSlot>();

  // The option's value, or fallback when absent.
  std::string option(const std::string& key, const std::string& fallback = {}) const;
  // The option's value; throws farfield::Error naming the mode and the key when absent.
  const std::string& requireOption(const std::string& key, const std::string& mode_name) const;
};

// What a run of modes over a scene draws with: the scene on the GPU, its BVH, a renderer, the frame target, and the
// ModeContext pointing at them. Needs a current context; keep it alive for the whole run.
struct ModeRunResources {
  ModeRunResources(const scene::Scene& scene, int width, int height, std::map<std::string, std::string> options);
  ModeRunResources(const ModeRunResources&) = delete;
  ModeRunResources& operator=(const ModeRunResources&) = delete;

  gpu::GpuScene gpu_scene;
  scene::Bvh bvh;
  gpu::Renderer renderer;
  gpu::RenderTarget target;
  ModeContext context;
};

// One frame of one mode, handed to Mode::frame(). Made by the harness.
class FrameContext {
 public:
  // timer: started with the first pass the mode draws itself (may be null: no GPU time for such frames).
  FrameContext(const Camera& camera, size_t path_frame, gpu::Renderer& renderer, gpu::RenderTarget& target,
               std::vector<gpu::DrawItem>& items, gpu::GpuTimer* timer = nullptr);

  const Camera& camera() const { return camera_; }
  // Index of this frame in the camera path (modes with temporal state, e.g. caches, may use it).
  size_t pathFrame() const { return path_frame_; }
  gpu::Renderer& renderer() { return renderer_; }

  // The main pass: draw items the harness draws with the shared renderer after frame() returns, on top of any
  // passes the mode drew itself. Starts empty each frame; its capacity is kept between frames.
  std::vector<gpu::DrawItem>& items() { return items_; }
  // Instead of filling items(): a prebuilt list that outlives the frame (e.g. all of the scene's items).
  void submit(std::span<const gpu::DrawItem> items) { submitted_ = items; has_submitted_ = true; }
  // What the harness draws in the main pass: the submitted list if any, else items().
  std::span<const gpu::DrawItem> mainItems() const {
    return has_submitted_ ? submitted_ : std::span<const gpu::DrawItem>(items_);
  }

  // Draws a pass into the frame's target now with the shared renderer (Renderer::draw: no clear, no wait). The
  // target is cleared to the renderer's sky colour before the first pass. Its triangles, draw calls and objects
  // count towards the frame.
  gpu::FrameStats drawPass(std::span<const gpu::DrawItem> items,
                           gpu::RenderMode mode = gpu::RenderMode::Shaded);
  // Call before any GPU work of the mode's own (its own programs on the frame's target, impostor updates rendered
  // into other targets): clears the frame's target and starts the frame's GPU timer, both once per frame. Returns
  // the frame's target. The mode reports what it drew with addStats().
  //
  // Inside frame() draw with Renderer::draw or the mode's own programs, never with Renderer::render: render() waits
  // for the GPU (a stall no real frame would have) and its GL_TIME_ELAPSED query cannot nest in the harness's.
  gpu::RenderTarget& beginOwnPass();
  // beginOwnPass for a pass that writes every pixel's colour, id and depth itself (gpu::TargetUpscaler): the frame's
  // GPU timer starts, and the target is not cleared first.
  gpu::RenderTarget& beginOwnPassOverwritingAll();
  void addStats(const gpu::FrameStats& stats);

  // Harness side, after Mode::frame(): the main pass. The target is cleared first (and the timer started) when the
  // mode drew no pass of its own; the main items are drawn on top. Returns what the passes and the main pass drew.
  gpu::FrameStats drawMainPass();

 private:
  // Once per frame, before its first pass: starts the frame's timer and clears the target (unless `clear` is false).
  void clearOnce(bool clear = true);

  const Camera& camera_;
  size_t path_frame_;
  gpu::Renderer& renderer_;
  gpu::RenderTarget& target_;
  std::vector<gpu::DrawItem>& items_;
  gpu::GpuTimer* timer_;
  std::span<const gpu::DrawItem> submitted_;
  bool has_submitted_ = false;
  bool drew_passes_ = false;
  gpu::FrameStats pass_stats_;
};

// What a frame governor decided for one frame of a mode (eval/governed_mode.h, runtime/frame_governor.h).
struct FrameGovernance {
  size_t level = 0;           // 0 = the mode's own frame; higher = coarser
  double predicted_ms = 0.0;  // the cost model's prediction of the frame at that level
  double corrected_ms = 0.0;  // ... corrected by the measured times of earlier frames
  double bound_scale = 1.0;   // the error bound kept / the promised bound (1: not relaxed)
};

class GpuCullRun;

class Mode {
 public:
  virtual ~Mode() = default;
  // The registry name ("full", "culled", ...).
  virtual std::string name() const = 0;
  // Once per run before the warm-up frame, with the context current: load baked data, upload GPU resources.
  // Not timed. Throws farfield::Error for bad inputs (missing directory, wrong format).
  virtual void prepare(const ModeContext& /*context*/) {}
  // Produces one frame (see FrameContext). Timed as a whole by the harness.
  virtual void frame(FrameContext& frame) = 0;
  // Numbers about the run the mode wants reported (bench.json "modes.<name>.info"), e.g. impostor count, bytes.
  virtual std::map<std::string, double> info() const { return {}; }
  // What the GPU counted of the mode's last frame of this path frame, read back late (a GPU-driven mode knows its
  // triangles and objects only then): the harness asks after it has waited for the frame and adds them to what the
  // frame's passes reported. None by default.
  virtual std::optional<gpu::FrameStats> lateFrameStats(size_t /*path_frame*/) { return std::nullopt; }
  // The harness's measured wall time of the frame just drawn (after its wait; outside the timed part). A mode that
  // closes a loop on its frame time (a governor) takes it; in an engine it would come from a timer query read late.
  virtual void frameMeasured(size_t /*path_frame*/, double /*wall_ms*/) {}
  // The run that draws the mode's geometry through the arena with gpu_occlusion (eval/gpu_culled_mode.h), if any: a
  // governor times both occlusion variants of each level at its calibration. None by default.
  virtual GpuCullRun* gpuCullRun() { return nullptr; }
  // Lets the mode draw its geometry with the arena's simplified levels where their error projects to at most `px`
  // pixels (gpu::GpuCuller::setLodErrorPx; 0: full detail) from the next frame on. Returns false for a mode that
  // cannot (its geometry is not drawn through the arena), which then draws as before.
  virtual bool setGeometryErrorPx(double /*px*/) { return false; }
  // What a governor decided for the frame just drawn; none for modes without one.
  virtual std::optional<FrameGovernance> governance(size_t /*path_frame*/) const { return std::nullopt; }
  // Whether the frame just drawn drew an impostor; none for modes that draw none by design.
  virtual std::optional<bool> drewImpostors() const { return std::nullopt; }
  // Work for later frames done now, within `budget_ms` of this frame (a governor's slack): the walkthrough modes load
  // the impostors or cells they will soon need (runtime::Walkthrough::loadAhead). Returns the milliseconds spent;
  // 0 for modes with nothing to read ahead. Called inside the timed frame, after the mode's frame().
  virtual double readAhead(const Camera& /*camera*/, double /*budget_ms*/) { return 0.0; }
  // What the mode knows of the next frame's load before drawing it, in triangles (the placed walkthrough: the visible
  // set of the region holding the eye; runtime::Walkthrough::expectedTriangles); a governor scales its prediction by
  // it (runtime::GovernorLoop::decide). 0: unknown.
  virtual double planWorkload(const Camera& /*camera*/) const { return 0.0; }
};

// The measured path frames that drew an impostor (per path frame: whether the frame drew one) into a mode's info():
// frames_with_impostors, and the longest stretch of consecutive measured frames that all did
// (impostor_stretch_first_frame, impostor_stretch_last_frame: path frames; impostor_stretch_frames: measured frames
// in it; none without such a frame).
void addImpostorFrames(const std::map<size_t, bool>& frames, std::map<std::string, double>& info);

// Makes a mode; cheap (heavy work belongs in prepare()). May throw farfield::Error for bad options.
using ModeFactory = std::function<std::unique_ptr<Mode>(const ModeContext& context)>;

// Adds (or replaces) a mode in the process-wide registry. The built-in modes are always there.
void registerMode(const std::string& name, const std::string& description, ModeFactory factory);
// Registered names, sorted.
std::vector<std::string> modeNames();
std::string modeDescription(const std::string& name);  // "" for an unknown name
bool hasMode(const std::string& name);
// Throws farfield::Error for an unknown name, listing the known ones.
std::unique_ptr<Mode> createMode(const std::string& name, const ModeContext& context);
// Throws farfield::Error listing the known modes when a name is unknown (check a list before rendering anything).
void checkModeNames(std::span<const std::string> names);

// "key=value" items (from repeated --mode-option) into ModeContext::options; a later key wins. Throws
// farfield::Error naming --mode-option for an item without '=' or with an empty key.
std::map<std::string, std::string> parseModeOptions(const std::vector<std::string>& items);

// Static registration helper: `static farfield::eval::RegisterMode reg("impostor", "...", factory);`
struct RegisterMode {
  RegisterMode(const std::string& name, const std::string& description, ModeFactory factory) {
    registerMode(name, description, std::move(factory));
  }
};

}  // namespace farfield::eval
