// The viewer's loop: input -> camera -> the mode's frame into the render target -> reference check when asked ->
// screenshots of the frame -> the frame shown in the window -> panels -> screenshot of the window -> swap.
#include "farfield/view/viewer.h"

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/timer.h"
#include "farfield/extract/ground_height.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/texture.h"
#include "farfield/gpu/window_frame.h"
#include "farfield/image/png_io.h"
#include "farfield/view/camera_recorder.h"
#include "farfield/view/database_modes.h"
#include "farfield/view/frame_history.h"
#include "farfield/view/mode_renderer.h"
#include "farfield/view/panels.h"
#include "farfield/view/reference_check.h"
#include "farfield/view/street_map_overlay.h"

namespace fs = std::filesystem;

namespace farfield::view {
namespace {

// Dear ImGui's context and its GLFW and OpenGL 3 backends, shut down in reverse order.
struct Gui {
  explicit Gui(GLFWwindow* window) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini: every run starts with the same layout
    ImGui::StyleColorsDark();
    ImGui::GetStyle().Alpha = 0.94f;
    ImGui_ImplGlfw_InitForOpenGL(window, true);
    ImGui_ImplOpenGL3_Init("#version 450");
  }
  ~Gui() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  Gui(const Gui&) = delete;
  Gui& operator=(const Gui&) = delete;
};

class Viewer {
 public:
  Viewer(const scene::Scene& scene, const ViewerOptions& options, gpu::Context& context)
      : scene_(scene),
        options_(options),
        context_(context),
        gpu_scene_(scene),
        bvh_(scene),
        target_(options.width, options.height),
        reference_target_(options.width, options.height),
        reference_items_(gpu_scene_.drawItems()) {
    panel_.tint = options.tint;
    panel_.show_map = options.show_map;
    panel_.check_every_frame = options.check_every_frame;
    panel_.t_max_ms = options.t_max_ms;
    panel_.navigation = options.navigation;
    panel_.camera = &controller_.settings();
    panel_.history = &history_;
    screenshots_.insert(options.screenshot_at.begin(), options.screenshot_at.end());
    if (!options.replay.empty()) player_ = PathPlayer(gen::loadCameraPath(options.replay), false);
    else if (!options.path.empty()) player_ = PathPlayer(gen::loadCameraPath(options.path), true);
    recording_ = !options.record.empty();
  }

  // Opens the database, the map's street graph and the first mode. Throws farfield::Error.
  void open() {
    database_ = databaseModes(options_.impostors);
    panel_.modes = database_.modes;
    std::string streets = options_.streets;
    if (streets.empty()) streets = database_.streets_file;
    if (streets.empty() && !options_.scene_file.empty()) {
      const std::string next_to_scene = gen::streetsPathFor(options_.scene_file);
      std::error_code ec;
      if (fs::exists(next_to_scene, ec)) streets = next_to_scene;
    }
    if (!streets.empty()) graph_ = urban::StreetGraph::load(streets);
    std::vector<uint32_t> all(scene_.objects.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = uint32_t(i + 1);
    ground_ = std::make_unique<extract::GroundHeight>(scene_, all);
    ModeSettings settings;
    settings.database = options_.impostors;
    settings.error_px = options_.error_px;
    settings.terrain = options_.terrain;
    settings.terrain_scale = options_.terrain_scale;
    settings.terrain_technique = options_.terrain_technique;
    settings.t_max_ms = options_.t_max_ms;
    panel_.gpu_budget_bytes = settings.gpu_budget_bytes;
    modes_ = std::make_unique<ModeRenderer>(scene_, gpu_scene_, bvh_, renderer_, target_, settings);
    selectMode(options_.mode.empty() ? defaultMode(database_) : options_.mode);
    startingPose();
    if (options_.crowd.agents > 0) {
      if (!graph_)
        throw Error("--crowd", "needs the city's street graph (CITY.streets.json next to the scene, or --streets)");
      const extract::GroundHeight* ground = ground_.get();
      crowd_ = std::make_unique<ViewerCrowd>(
          *graph_, [ground](float x, float y) { return ground->at(x, y); }, options_.crowd, options_.height);
      panel_.crowd = true;
      FF_INFO("crowd: " << crowd_->agentCount() << " agents, atlases baked in " << crowd_->bakeSeconds() << " s");
    }
  }

  // The crowd over the mode's frame, its time and counts added to the frame's.
  void drawCrowd(double dt) {
    const bool replaying = player_.active() && !player_.realTime();
    crowd_time_ = replaying ? double(player_.frame()) / 30.0 : crowd_time_ + dt;
    const ViewerCrowdFrame f = crowd_->draw(camera_, float(crowd_time_), renderer_.light(), target_);
    panel_.frame.cpu_ms += f.ms;
    panel_.frame.triangles += f.stats.draw.triangles;
    panel_.frame.draw_calls += f.stats.draw.draw_calls;
    panel_.crowd_geometry = f.stats.geometry;
    panel_.crowd_impostors = f.stats.impostors;
  }

  void run() {
    Stopwatch clock;
    while (true) {
      if (context_.shouldClose() && !closing_) closing_ = true;  // polls events
      if (closing_) break;
      const double dt = std::min(clock.seconds(), 0.1);
      clock.restart();
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      if (fatal_.empty()) {
        try {
          step(dt);
        } catch (const Error& e) {
          fail(e.what());
        }
      }
      int fb_width = 0, fb_height = 0;
      context_.framebufferSize(fb_width, fb_height);
      gpu::clearWindow(fb_width, fb_height, Vec4(0.1f, 0.1f, 0.12f, 1.0f));
      if (shown_ > 0) gpu::showFrame(target_, fb_width, fb_height);
      if (fatal_.empty() && shown_ == 1 && !laid_out_) {
        // Dear ImGui sizes auto-resized windows in their first frame without drawing them: lay the panels out once
        // before the first frame is shown, so that a screenshot of it has them.
        drawPanels();
        ImGui::EndFrame();
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        laid_out_ = true;
      }
      if (fatal_.empty()) drawPanels();
      if (!fatal_.empty()) {
        if (options_.exit_at_end) throw Error(fatal_);
        if (drawErrorModal(fatal_, true)) closing_ = true;
      } else if (!notice_.empty() && drawErrorModal(notice_, false)) {
        notice_.clear();
      }
      ImGui::Render();
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
      if (window_shot_) {
        image::writePng(*window_shot_, gpu::readWindow(fb_width, fb_height));
        panel_.message = "wrote " + *window_shot_;
        window_shot_.reset();
      }
      context_.swapBuffers();
      if (fatal_.empty()) advance(dt);
    }
    if (!fatal_.empty()) throw Error(fatal_);
    if (!options_.record.empty()) recorder_.save(options_.record);
  }

  void fail(const std::string& message) {
    fatal_ = message;
    if (!options_.exit_at_end) std::fprintf(stderr, "error: %s\n", message.c_str());
  }

 private:
  void selectMode(const std::string& mode) {
    const auto it = std::find(database_.modes.begin(), database_.modes.end(), mode);
    if (it == database_.modes.end()) {
      std::string known;
      for (const std::string& m : database_.modes) known += (known.empty() ? "" : ", ") + m;
      throw Error("--mode " + mode, "not offered here (modes: " + known + ")");
    }
    modes_->select(mode);
    panel_.mode_index = int(it - database_.modes.begin());
    history_.reset();
    check_.reset();
  }

  // A street of the map (the first baked cell of a pipeline store) at walking height, else above the scene.
  void startingPose() {
    if (player_.active()) {
      controller_.setPose(player_.camera(options_.width, options_.height));
      return;
    }
    if (graph_ && graph_->streetCount() > 0) {
      uint32_t e = 0;
      if (database_.kind == DatabaseKind::Pipeline) {
        const store::StoreIndex index = store::readIndex(options_.impostors);
        if (!index.cells.empty()) e = index.cells.front().half_edge;
      }
      const Vec2 p = graph_->originPosition(e) + graph_->direction(e) * std::min(5.0f, graph_->length(e) * 0.25f);
      const float z = ground_->at(p.x, p.y, 0.0f) + kWalkEyeHeight;
      const Vec2 ahead = p + graph_->direction(e);
      controller_.setPose(Vec3(p, z), Vec3(ahead, z));
    } else {
      const Box3 b = scene_.bounds();
      const Vec3 c = b.empty() ? Vec3(0.0f) : (b.lo + b.hi) * 0.5f;
      const float r = b.empty() ? 10.0f : glm::length(b.extent()) * 0.5f;
      controller_.setPose(c + Vec3(0.0f, -1.6f * r, 0.7f * r), c);
      controller_.settings().speed = std::max(1.0f, r * 0.25f);
    }
    if (panel_.navigation == Navigation::Walk) controller_.snapToGround(groundFunction());
  }

  GroundFunction groundFunction() const {
    const extract::GroundHeight* ground = ground_.get();
    return [ground](float x, float y, float fallback) { return ground->at(x, y, fallback); };
  }

  void handleInput(double dt) {
    const ImGuiIO& io = ImGui::GetIO();
    ControlInput input;
    input.dt = dt;
    if (!io.WantCaptureKeyboard) {
      const auto down = [](int key) { return ImGui::IsKeyDown(key) ? 1.0f : 0.0f; };
      const auto pressed = [](int key) { return ImGui::IsKeyPressed(key, false); };
      input.forward = down(GLFW_KEY_W) - down(GLFW_KEY_S);
      input.right = down(GLFW_KEY_D) - down(GLFW_KEY_A);
      input.up = down(GLFW_KEY_E) - down(GLFW_KEY_Q);
      input.fast = io.KeyShift;
      if (pressed(GLFW_KEY_ESCAPE)) closing_ = true;
      if (pressed(GLFW_KEY_TAB)) toggleNavigation();
      if (pressed(GLFW_KEY_T)) panel_.tint = !panel_.tint;
      if (pressed(GLFW_KEY_M)) panel_.show_map = !panel_.show_map;
      if (pressed(GLFW_KEY_R)) check_requested_ = true;
      if (pressed(GLFW_KEY_P) && player_.active()) player_.setPaused(!player_.paused());
      if (pressed(GLFW_KEY_K)) toggleRecording();
      if (pressed(GLFW_KEY_F12)) {
        window_shot_ = (fs::path(options_.out_dir) / ("screenshot_" + std::to_string(shown_) + ".png")).string();
      }
      for (int k = 0; k < 9; ++k)
        if (pressed(GLFW_KEY_1 + k) && size_t(k) < database_.modes.size()) trySelect(database_.modes[size_t(k)]);
    }
    if (!io.WantCaptureMouse && (ImGui::IsMouseDown(0) || ImGui::IsMouseDown(1))) {
      input.look_x = io.MouseDelta.x;
      input.look_y = io.MouseDelta.y;
    }
    const bool moving = input.forward != 0.0f || input.right != 0.0f || input.up != 0.0f || input.look_x != 0.0f ||
                        input.look_y != 0.0f;
    if (moving && player_.active() && !player_.paused()) player_.setPaused(true);  // the user takes over
    if (!player_.active() || player_.paused())
      controller_.update(input, panel_.navigation, groundFunction());
  }

  void toggleNavigation() {
    panel_.navigation = panel_.navigation == Navigation::Fly ? Navigation::Walk : Navigation::Fly;
    if (panel_.navigation == Navigation::Walk) controller_.snapToGround(groundFunction());
  }

  void toggleRecording() {
    if (!recording_) {
      recorder_.clear();
      recording_ = true;
      return;
    }
    recording_ = false;
    const std::string file = options_.record.empty() ? (fs::path(options_.out_dir) / "view_path.json").string()
                                                     : options_.record;
    if (recorder_.size() == 0) return;
    recorder_.save(file);
    panel_.message = "wrote " + std::to_string(recorder_.size()) + " cameras to " + file;
  }

  void trySelect(const std::string& mode) {
    try {
      selectMode(mode);
    } catch (const Error& e) {
      notice_ = e.what();
    }
  }

  // One frame: camera, render, measures, screenshots of the frame.
  void step(double dt) {
    handleInput(dt);
    camera_ = player_.active() && !player_.paused() ? player_.camera(options_.width, options_.height)
                                                     : controller_.camera(options_.width, options_.height);
    if (player_.active() && !player_.paused()) controller_.setPose(camera_);
    try {
      modes_->setTMaxMs(panel_.t_max_ms);  // the governed mode keeps the panel's t_max
    } catch (const Error& e) {
      notice_ = e.what();
    }
    panel_.frame = modes_->render(camera_, shown_, panel_.tint);
    if (crowd_) drawCrowd(dt);
    const runtime::FramePlan* plan = panel_.frame.plan;
    const runtime::Walkthrough* walkthrough = modes_->walkthrough();
    panel_.bound_px = plan ? plan->report.bound_px : panel_.frame.kept_bound_px;
    if (walkthrough && panel_.bound_px <= 0.0) panel_.bound_px = walkthrough->errorBoundPx();
    history_.add(panel_.frame.cpu_ms, panel_.frame.gpu_ms, panel_.t_max_ms, plan && plan->report.layers_unchecked > 0);
    if (recording_) recorder_.add(camera_);
    ++shown_;

    const size_t number = player_.active() && !player_.realTime() ? player_.frame() : shown_ - 1;
    const bool screenshot = screenshots_.count(number) != 0 && !taken_.count(number);
    if (screenshot) {
      taken_.insert(number);
      fs::create_directories(options_.out_dir);
      image::writePng((fs::path(options_.out_dir) / ("frame_" + std::to_string(number) + ".png")).string(),
                      target_.readColor());
      window_shot_ = (fs::path(options_.out_dir) / ("window_" + std::to_string(number) + ".png")).string();
    }
    if (check_requested_ || panel_.check_every_frame) {
      check_requested_ = false;
      if (panel_.tint || crowd_) modes_->redraw(camera_, shown_ - 1, false);
      check_ = checkAgainstReference(renderer_, reference_items_, camera_, target_, reference_target_,
                                     scene_.objects.size(), panel_.bound_px);
      check_->frame = shown_ - 1;
      history_.addCheck(check_->over_bound);
      heatmap_texture_ = gpu::Texture::fromImage(check_->heatmap, false);
      parallax_texture_ = gpu::Texture::fromImage(check_->parallax, false);
      // The tinted frame again, and the crowd (the reference has none, so the check measured the frame without).
      if (panel_.tint || crowd_) modes_->redraw(camera_, shown_ - 1, panel_.tint);
      if (crowd_) crowd_->draw(camera_, float(crowd_time_), renderer_.light(), target_);
    }
  }

  void drawPanels() {
    panel_.path_status.clear();
    if (player_.frameCount() > 0) {
      char text[128];
      std::snprintf(text, sizeof(text), "path frame %zu (0..%zu)%s%s", player_.frame(), player_.frameCount() - 1,
                    player_.finished() ? " (ended)" : "", player_.paused() ? " (paused: P)" : "");
      panel_.path_status = text;
    }
    panel_.record_status = recording_ ? "recording: " + std::to_string(recorder_.size()) + " cameras (K stops)" : "";
    const PanelActions actions = drawMainPanel(panel_);
    if (actions.select_mode) trySelect(*actions.select_mode);
    if (actions.navigation_changed && panel_.navigation == Navigation::Walk)
      controller_.snapToGround(groundFunction());
    if (actions.check_now) check_requested_ = true;
    if (panel_.show_map) {
      const ImGuiViewport* viewport = ImGui::GetMainViewport();
      ImGui::SetNextWindowPos(ImVec2(viewport->Size.x - 8, 8), ImGuiCond_FirstUseEver, ImVec2(1, 0));
      if (ImGui::Begin("Map", &panel_.show_map, ImGuiWindowFlags_AlwaysAutoResize)) {
        MapOverlay overlay;
        overlay.graph = graph_ ? &*graph_ : nullptr;
        if (const runtime::FramePlan* plan = panel_.frame.plan) {
          overlay.cell = plan->report.cell;
          overlay.cpv = plan->report.cpv;
        }
        overlay.placement = database_.placement.get();
        drawStreetMap(overlay, camera_, std::clamp(0.38f * std::min(viewport->Size.x, viewport->Size.y), 120.0f, 320.0f));
        ImGui::Text("%s, eye %.0f %.0f %.1f m", navigationName(panel_.navigation), camera_.eye.x, camera_.eye.y,
                    camera_.eye.z);
      }
      ImGui::End();
    }
    if (check_) drawReferencePanel(*check_, heatmap_texture_.handle(), parallax_texture_.handle());
  }

  void advance(double dt) {
    const bool was_active = player_.active();
    player_.advance(dt);
    if (!options_.exit_at_end) return;
    if (was_active && player_.finished()) closing_ = true;
    // Without a replay: close once every screenshot asked for is taken.
    if (player_.frameCount() == 0 && taken_.size() == screenshots_.size()) closing_ = true;
  }

  const scene::Scene& scene_;
  const ViewerOptions& options_;
  gpu::Context& context_;
  gpu::GpuScene gpu_scene_;
  scene::Bvh bvh_;
  gpu::Renderer renderer_;
  gpu::RenderTarget target_, reference_target_;
  std::vector<gpu::DrawItem> reference_items_;
  DatabaseModes database_;
  std::optional<urban::StreetGraph> graph_;
  std::unique_ptr<extract::GroundHeight> ground_;
  std::unique_ptr<ModeRenderer> modes_;
  std::unique_ptr<ViewerCrowd> crowd_;
  double crowd_time_ = 0.0;  // seconds
  CameraController controller_;
  PathPlayer player_;
  CameraRecorder recorder_;
  bool recording_ = false;
  FrameHistory history_;
  PanelState panel_;
  Camera camera_;
  size_t shown_ = 0;
  std::set<size_t> screenshots_, taken_;
  std::optional<std::string> window_shot_;
  bool check_requested_ = false;
  std::optional<ReferenceCheck> check_;
  gpu::Texture heatmap_texture_, parallax_texture_;
  std::string fatal_, notice_;
  bool closing_ = false;
  bool laid_out_ = false;
};

}  // namespace

void checkViewerOptions(const ViewerOptions& o) {
  if (o.width < 16 || o.height < 16 || o.width > 16384 || o.height > 16384)
    throw Error("--size", "window size must be 16..16384 pixels each, got " + std::to_string(o.width) + "x" +
                              std::to_string(o.height));
  if (!(o.t_max_ms >= 0.0)) throw Error("--tmax", "must be a number of ms >= 0");
  if (!(o.error_px >= 0.0) || !std::isfinite(o.error_px)) throw Error("--error-px", "must be a number of pixels >= 0");
  if (!o.path.empty() && !o.replay.empty()) throw Error("--path/--replay", "give one camera path, not both");
  if (!(o.terrain_scale > 0.0f) || !std::isfinite(o.terrain_scale))
    throw Error("--terrain-scale", "must be a finite number > 0");
  if (o.terrain_technique != "lod-sprite-gpu" && o.terrain_technique != "high-gpu" &&
      o.terrain_technique != "lod-sprite" && o.terrain_technique != "high")
    throw Error("--terrain-technique",
                "'" + o.terrain_technique + "' is not lod-sprite-gpu, high-gpu, lod-sprite or high");
  if (!o.screenshot_at.empty() && o.out_dir.empty()) throw Error("--screenshot-at", "needs -o DIR");
  if (o.exit_at_end && o.replay.empty() && o.screenshot_at.empty())
    throw Error("--exit", "needs --replay or --screenshot-at (otherwise nothing would be shown)");
  if (o.crowd.agents > 0) {
    if (o.crowd.models.size() > 2)
      throw Error("--crowd-models", "one or two skinned glTF files (heights 1.75 m and 0.8 m), or none: the built-in "
                                    "figures");
    for (const std::string& f : o.crowd.models)
      if (!fs::exists(f)) throw Error(f, "no such file (--crowd-models)");
    if (!(o.crowd.error_px > 0.0) || !std::isfinite(o.crowd.error_px))
      throw Error("--crowd-error-px", "must be a number of pixels > 0");
    if (!(o.crowd.lod_px >= 0.0) || !std::isfinite(o.crowd.lod_px))
      throw Error("--crowd-lod-px", "must be a number of pixels >= 0");
  }
}

void runViewer(const scene::Scene& scene, const ViewerOptions& options) {
  checkViewerOptions(options);
  // Cheap checks before the window opens: the camera paths and the street graph named on the command line.
  if (!options.replay.empty()) gen::loadCameraPath(options.replay);
  if (!options.path.empty()) gen::loadCameraPath(options.path);
  if (!options.streets.empty()) urban::StreetGraph::load(options.streets);
  gpu::ContextOptions context_options;
  context_options.platform = gpu::Platform::Window;
  context_options.window_width = options.width;
  context_options.window_height = options.height;
  context_options.window_title =
      "Farfield: " + (options.scene_file.empty() ? std::string("scene") : options.scene_file);
  const std::unique_ptr<gpu::Context> context = gpu::Context::create(context_options);
  const Gui gui(static_cast<GLFWwindow*>(context->nativeWindow()));
  std::optional<Viewer> viewer;
  try {
    viewer.emplace(scene, options, *context);
    viewer->open();
  } catch (const Error& e) {
    if (options.exit_at_end || !viewer) throw;
    viewer->fail(e.what());
  }
  viewer->run();
}

}  // namespace farfield::view
