#include "farfield/eval/crowd_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/timer.h"
#include "farfield/eval/crowd_metrics.h"
#include "farfield/eval/gpu_crowd_input.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/gpu_crowd.h"
#include "farfield/gpu/gpu_culler.h"
#include "farfield/eval/crowd_walk.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/mode.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gen/city.h"
#include "farfield/gen/crowd.h"
#include "farfield/gpu/occlusion_culler.h"
#include "farfield/image/metrics.h"
#include "farfield/image/png_io.h"

namespace fs = std::filesystem;

namespace farfield::eval {
namespace {

struct ModeSpec {
  std::string name;
  runtime::CrowdPolicy policy;
  bool palette = false;  // drawn by the palette-skinning runtime (CrowdBenchOptions::compare_skinning)
  bool gpu = false;      // the GPU crowd (CrowdBenchOptions::gpu_crowd)
};

std::vector<ModeSpec> modeSpecs(bool compare_skinning, bool gpu_crowd) {
  std::vector<ModeSpec> specs{{"crowd-geometry", runtime::CrowdPolicy::Geometry},
                              {"crowd-impostor", runtime::CrowdPolicy::Impostor},
                              {"crowd-mixed", runtime::CrowdPolicy::Mixed}};
  if (compare_skinning) {
    specs.push_back({"crowd-geometry-palette", runtime::CrowdPolicy::Geometry, true});
    specs.push_back({"crowd-mixed-palette", runtime::CrowdPolicy::Mixed, true});
  }
  if (gpu_crowd) {
    specs.push_back({"crowd-geometry-gpu", runtime::CrowdPolicy::Geometry, false, true});
    specs.push_back({"crowd-impostor-gpu", runtime::CrowdPolicy::Impostor, false, true});
    specs.push_back({"crowd-mixed-gpu", runtime::CrowdPolicy::Mixed, false, true});
  }
  return specs;
}

// An elevated path: the pedestrian walk raised by 14 m (a first-floor balcony, a bus roof), looking down the street
// to a point on the ground 50 m ahead.
gen::CameraPath elevated(const gen::CameraPath& walk) {
  gen::CameraPath out = walk;
  out.kind = "elevated";
  for (gen::PathFrame& f : out.frames) {
    Vec3 forward = f.at - f.eye;
    forward.z = 0.0f;
    forward = glm::length(forward) > 1e-6f ? glm::normalize(forward) : Vec3(1, 0, 0);
    const float ground = f.eye.z - 1.7f;
    f.eye.z += 14.0f;
    f.at = Vec3(f.eye.x, f.eye.y, ground) + forward * 50.0f;
  }
  return out;
}

// The crowd into `target` (holding the city), with or without the agents' shadows.
runtime::CrowdFrameStats drawCrowd(runtime::CrowdRuntime& rt, const Camera& camera,
                                   std::span<const runtime::CrowdAgentState> states, runtime::CrowdPolicy policy,
                                   const gpu::LightSettings& light, const gpu::RenderTarget& target,
                                   const CrowdBenchOptions& options) {
  runtime::CrowdShadowOptions shadow = options.shadow;
  shadow.impostor_casters = options.impostor_shadows && policy == runtime::CrowdPolicy::Mixed;
  return drawCrowdFrame(rt, camera, states, policy, light, target, options.shadows, shadow);
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, v);
  return buf;
}

std::string thousands(size_t v) {
  const std::string digits = std::to_string(v);
  std::string out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out.push_back(',');
    out.push_back(digits[i]);
  }
  return out;
}

}  // namespace

namespace {

// The run as a Markdown table with the city, models, atlases and bake time above it.
std::string crowdMarkdown(const CrowdBenchResult& result, const CrowdBenchOptions& options) {
  std::ostringstream md;
  md << "- city: generated, " << options.blocks << " blocks, detail " << options.detail << ", seed " << options.city_seed
     << " (" << thousands(result.city_triangles) << " triangles, drawn in every mode as "
     << (options.city_cpu ? "culled-cpu draws it: frustum, facing and occlusion culled on the CPU, depth read back"
                          : "culled draws it: the GPU-driven frame, no readback")
     << ")\n";
  md << "- size " << options.width << "x" << options.height << ", " << options.frames << " measured frames per run (every "
     << options.frame_step << "th frame of a 30 fps street walk, seed " << options.path_seed << "), one warm-up frame"
     << (options.timing_passes > 1 ? ", each frame's time the fastest of " + std::to_string(options.timing_passes) +
                                         " passes over the path"
                                   : std::string())
     << "\n";
  md << "- renderer: " << result.renderer << "\n";
  for (size_t m = 0; m < result.layouts.size(); ++m) {
    const gpu::AtlasLayout& l = result.layouts[m];
    const runtime::CrowdAtlasChoice& c = result.atlas_choices[m];
    md << "- " << result.model_names[m] << ": " << thousands(result.model_triangles[m]) << " triangles"
       << (result.model_cutout[m] ? " (texels cut out)" : " (opaque: no cut-out test)") << "; atlas "
       << (c.from_bound ? "chosen from the bound (" + fmt("%.2f", options.runtime.error_px) + " px from " +
                              fmt("%.1f", options.runtime.bound_switch_m) + " m on)"
                        : std::string("fixed"))
       << ": " << l.azimuths << "x" << l.elevations << (l.octahedral ? " octahedral" : "") << " views x " << l.frames
       << " frames (frame error "
       << fmt("%.3f", c.frame_error_m) << " m), cells " << l.cell_width << "x" << l.cell_height << " texels ("
       << fmt("%.3f", c.texel_m) << " m), " << fmt("%.1f", double(result.atlas_bytes[m]) / 1048576.0)
       << " MiB uncompressed (" << fmt("%.0f", double(result.atlas_bytes[m]) / 1024.0 / l.frames)
       << " KiB per frame, the lecture: about 256 KB compressed); switch to impostor beyond "
       << fmt("%.1f", result.switch_m[m]) << " m\n";
  }
  if (options.runtime.blend_views) md << "- impostors blend the four views around the direction to the eye\n";
  if (options.agent_occlusion) {
    md << "- agents hidden behind the city left out in every mode (not in the reference), per frame:";
    for (const CrowdRun& run : result.runs)
      md << " " << thousands(run.agents) << " " << run.path << " "
         << fmt("%.0f", run.modes.empty() ? 0.0 : run.modes[0].occluded) << " of "
         << fmt("%.0f", run.modes.empty() ? 0.0 : run.modes[0].in_view) << " in view;";
    md << "\n";
  }
  if (options.shadows)
    md << "- shadows: one " << options.shadow.map_size << "x" << options.shadow.map_size << " map, receivers within "
       << fmt("%.0f", options.shadow.distance_m) << " m, in the reference and every mode"
       << (options.impostor_shadows ? " (crowd-mixed's geometry agents cast as impostors)" : "") << "\n";
  md << "- skinning: "
     << (options.runtime.skinning == gpu::Skinning::BakedPoses
             ? "baked poses (each palette pose's vertices skinned once, read per agent)"
             : "palette (four joint matrices blended per vertex)")
     << ", in the reference and every mode\n";
  if (options.runtime.geometry_ms > 0.0)
    md << "- crowd-mixed's geometry budget in time: " << fmt("%.1f", options.runtime.geometry_ms)
       << " ms of skinned drawing a frame, as triangles at the measured time per triangle (moving average)\n";
  if (options.runtime.max_geometry_triangles > 0)
    md << "- crowd-mixed's geometry budget: " << thousands(size_t(options.runtime.max_geometry_triangles))
       << " skinned triangles a frame, the nearest agents first; the others inside their switch distance drawn as "
          "impostors (\"over the budget\")"
       << (options.runtime.budget_coarsens
               ? "; coarser levels of detail too (\"coarsened for the budget\"), each step the least error on screen"
               : "")
       << "\n";
  if (options.gpu_crowd && options.runtime.budget_coarsens)
    md << "- crowd-mixed-gpu does not coarsen for the budget (--budget-coarsens is the CPU path's): the agents its "
          "budget leaves out are impostors\n";
  if (options.runtime.geometry_lod_px > 0.0) {
    md << "- crowd-mixed's skinned agents at the coarsest level of detail within "
       << fmt("%.2f", options.runtime.geometry_lod_px) << " px (levels held over every palette pose; "
       << fmt("%.1f", result.lod_seconds) << " s to build; a level's error "
       << (options.runtime.lod_texture ? "the larger of its distance to the mesh and its texture deviation"
                                       : "its distance to the mesh alone")
       << ", given as distance / texture deviation):";
    for (size_t m = 0; m < result.level_m.size(); ++m) {
      md << " " << result.model_names[m];
      for (size_t l = 0; l < result.level_m[m].size(); ++l)
        md << (l == 0 ? " " : ", ") << thousands(size_t(result.level_triangles[m][l])) << " triangles "
           << fmt("%.1f", result.level_surface_m[m][l] * 100.0) << " / "
           << fmt("%.1f", result.level_texture_m[m][l] * 100.0) << " cm";
      md << ";";
    }
    md << "\n";
  }
  md << "- bake: " << fmt("%.2f", result.bake_seconds) << " s for all models\n\n";
  md << "| agents | path | mode | median ms | crowd ms | crowd own CPU ms | speedup | crowd speedup | "
        "geometry / impostor agents | triangles | PSNR dB (min) | >8/255 | popping mean / max (ref change) | "
        "shadow casters / receiver px off |\n";
  md << "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const CrowdRun& run : result.runs)
    for (const CrowdModeResult& r : run.modes)
      md << "| " << thousands(run.agents) << " | " << run.path << " | " << r.name << " | " << fmt("%.1f", r.wall.median)
         << " | " << fmt("%.1f", r.crowd.median) << " | " << fmt("%.3f", r.crowd_cpu.median) << " | "
         << fmt("%.2fx", r.speedup) << " | "
         << fmt("%.2fx", r.crowd_speedup) << " | " << fmt("%.0f", r.geometry_agents) << " / "
         << fmt("%.0f", r.impostor_agents)
         << (r.over_budget > 0.0 ? " (" + fmt("%.0f", r.over_budget) + " over the budget)" : std::string())
         << (r.coarser > 0.0 ? " (" + fmt("%.0f", r.coarser) + " coarser)" : std::string())
         << (r.coarsened > 0.0 ? " (" + fmt("%.0f", r.coarsened) + " coarsened for the budget)" : std::string())
         << " | "
         << thousands(size_t(r.triangles)) << " | "
         << fmt("%.1f", r.psnr_mean) << " (" << fmt("%.1f", r.psnr_min) << ") | " << fmt("%.3f", r.bad_share_mean)
         << " | " << fmt("%.2f", r.popping_mean) << " / " << fmt("%.2f", r.popping_max) << " ("
         << fmt("%.2f", run.reference_popping_mean) << ") | " << fmt("%.0f", r.shadow_casters) << " / "
         << fmt("%.0f", r.receiver_bad_pixels) << " |\n";
  md << "\nThe CPU modes' agent states (poses and phases of every agent, eval::crowdAgentStates) are made before the "
        "crowd pass, outside its time:";
  for (const CrowdRun& run : result.runs) md << " " << fmt("%.2f", run.cpu_states_ms) << " ms (" << thousands(run.agents) << ", " << run.path << ")";
  md << ". The crowd-*-gpu modes simulate every agent inside it.\n";
  if (options.runtime.geometry_ms > 0.0) {
    md << "\ncrowd-mixed's skinned draws against the " << fmt("%.1f", options.runtime.geometry_ms)
       << " ms budget (the frames that drew skinned agents):\n";
    for (const CrowdRun& run : result.runs)
      for (const CrowdModeResult& r : run.modes)
        if (r.skinned_ms.count > 0)
          md << "- " << thousands(run.agents) << " agents, " << run.path << ", " << r.name << ": median "
             << fmt("%.2f", r.skinned_ms.median) << " ms, max " << fmt("%.2f", r.skinned_ms.max) << " ms; "
             << r.skinned_over << " of " << r.skinned_ms.count << " frames over\n";
  }
  return md.str();
}

// crowd.json and crowd.md in the output directory.
void writeCrowdReport(const CrowdBenchResult& result, const CrowdBenchOptions& options) {
  nlohmann::json j;
  j["renderer"] = result.renderer;
  j["city"] = {{"blocks", options.blocks}, {"detail", options.detail}, {"seed", options.city_seed},
               {"triangles", result.city_triangles}, {"gen_seconds", result.city_seconds}};
  j["size"] = {options.width, options.height};
  j["bake_seconds"] = result.bake_seconds;
  j["max_geometry_triangles"] = options.runtime.max_geometry_triangles;
  j["budget_coarsens"] = options.runtime.budget_coarsens;
  j["skinning"] = options.runtime.skinning == gpu::Skinning::BakedPoses ? "baked-poses" : "palette";
  j["geometry_lod_px"] = options.runtime.geometry_lod_px;
  j["lod_seconds"] = result.lod_seconds;
  for (size_t m = 0; m < result.layouts.size(); ++m) {
    const gpu::AtlasLayout& l = result.layouts[m];
    const runtime::CrowdAtlasChoice& c = result.atlas_choices[m];
    j["models"].push_back({{"file", result.model_names[m]}, {"triangles", result.model_triangles[m]},
                           {"cutout", bool(result.model_cutout[m])},
                           {"azimuths", l.azimuths}, {"elevations", l.elevations},
                           {"octahedral", l.octahedral}, {"frames", l.frames},
                           {"cell", {l.cell_width, l.cell_height}}, {"texel_m", c.texel_m},
                           {"frame_error_m", c.frame_error_m}, {"from_bound", c.from_bound},
                           {"atlas_bytes", result.atlas_bytes[m]},
                           {"atlas_kib_per_frame", double(result.atlas_bytes[m]) / 1024.0 / l.frames},
                           {"switch_m", result.switch_m[m]}, {"level_triangles", result.level_triangles[m]},
                           {"level_m", result.level_m[m]}, {"level_surface_m", result.level_surface_m[m]},
                           {"level_texture_m", result.level_texture_m[m]}});
  }
  for (const CrowdRun& run : result.runs)
    for (const CrowdModeResult& r : run.modes)
      j["runs"].push_back({{"agents", run.agents}, {"path", run.path}, {"mode", r.name},
                           {"median_ms", r.wall.median}, {"p95_ms", r.wall.p95}, {"crowd_median_ms", r.crowd.median},
                           {"crowd_own_cpu_median_ms", r.crowd_cpu.median}, {"cpu_states_ms", run.cpu_states_ms},
                           {"speedup", r.speedup}, {"crowd_speedup", r.crowd_speedup}, {"psnr_db_mean", r.psnr_mean},
                           {"psnr_db_min", r.psnr_min}, {"bad_pixel_share_mean", r.bad_share_mean},
                           {"crowd_pixels_mean", r.crowd_pixels_mean}, {"popping_mean", r.popping_mean},
                           {"popping_max", r.popping_max}, {"reference_change_mean", run.reference_popping_mean},
                           {"geometry_agents", r.geometry_agents}, {"impostor_agents", r.impostor_agents},
                           {"in_view", r.in_view}, {"occluded", r.occluded}, {"over_budget_agents", r.over_budget},
                           {"coarser_agents", r.coarser}, {"coarsened_for_budget_agents", r.coarsened},
                           {"triangles", r.triangles},
                           {"shadow_casters", r.shadow_casters}, {"shadow_texel_m", r.shadow_texel_m},
                           {"receiver_bad_pixels", r.receiver_bad_pixels},
                           {"skinned_ms_median", r.skinned_ms.median}, {"skinned_ms_max", r.skinned_ms.max},
                           {"skinned_frames", r.skinned_ms.count}, {"skinned_frames_over_budget", r.skinned_over}});
  std::ofstream(fs::path(options.out_dir) / "crowd.json") << j.dump(2) << "\n";
  std::ofstream(fs::path(options.out_dir) / "crowd.md") << result.markdown;
}

}  // namespace

CrowdBenchResult runCrowdBench(gpu::Context& context, const CrowdBenchOptions& options) {
  if (options.model_heights.size() < options.models.size() || options.model_shares.size() < options.models.size() ||
      options.model_facing_deg.size() < options.models.size())
    throw Error("crowd bench", "one height, facing and share per model (at most " +
                                   std::to_string(options.model_heights.size()) + " models)");
  if (options.frames < 2) throw Error("crowd bench", "need at least 2 frames (popping compares consecutive frames)");
  if (options.timing_passes < 1) throw Error("crowd bench", "need at least one timing pass");
  if (options.width < 16 || options.height < 16) throw Error("crowd bench", "frame size too small");
  context.makeCurrent();
  CrowdBenchResult result;
  result.renderer = context.description();

  CrowdModels crowd_models =
      crowdModels(options.models, options.model_heights, options.model_facing_deg, options.model_shares);
  const std::vector<scene::SkinnedModel>& models = crowd_models.models;
  const std::vector<runtime::CrowdModelOptions>& model_options = crowd_models.options;
  result.model_names = crowd_models.names;

  Stopwatch city_clock;
  gen::CityOptions co;
  co.blocks = options.blocks;
  co.detail = options.detail;
  co.seed = options.city_seed;
  gen::City city = gen::generateCity(co);
  result.city_seconds = city_clock.seconds();
  for (const scene::Mesh& mesh : city.scene.meshes) result.city_triangles += mesh.triangleCount();
  ModeRunResources res(city.scene, options.width, options.height, {});
  gpu::Renderer& renderer = res.renderer;
  gpu::RenderTarget& target = res.target;
  gpu::RenderTarget reference_target(options.width, options.height);

  runtime::CrowdRuntimeOptions rt_options = options.runtime;
  rt_options.bound_focal_px = double(options.height) / (2.0 * std::tan(double(Camera{}.fov_y) / 2.0));
  rt_options.region_tints = gen::crowdRegionTints(options.crowd_seed, options.outfits);
  runtime::CrowdRuntime rt(models, model_options, rt_options);
  result.bake_seconds = rt.bakeSeconds();
  std::unique_ptr<runtime::CrowdRuntime> rt_palette;
  if (options.compare_skinning && rt_options.skinning != gpu::Skinning::Palette) {
    runtime::CrowdRuntimeOptions palette_options = rt_options;
    palette_options.skinning = gpu::Skinning::Palette;
    rt_palette = std::make_unique<runtime::CrowdRuntime>(models, model_options, palette_options);
  }
  for (size_t m = 0; m < rt.modelCount(); ++m) {
    result.layouts.push_back(rt.impostor(m).layout);
    result.atlas_choices.push_back(rt.atlasChoice(m));
    result.atlas_bytes.push_back(rt.impostor(m).byteSize());
    result.model_triangles.push_back(rt.modelTriangles(m));
    result.model_cutout.push_back(rt.gpuModel(m).cutout());
    result.level_triangles.emplace_back();
    for (size_t l = 0; l < rt.gpuModel(m).levelCount(); ++l)
      result.level_triangles.back().push_back(rt.gpuModel(m).triangleCount(l));
    const std::span<const double> level_m = rt.levelDistances(m);
    result.level_m.emplace_back(level_m.begin(), level_m.end());
    const std::span<const double> level_surface_m = rt.levelSurfaceDistances(m);
    result.level_surface_m.emplace_back(level_surface_m.begin(), level_surface_m.end());
    const std::span<const double> level_texture_m = rt.levelTextureDeviations(m);
    result.level_texture_m.emplace_back(level_texture_m.begin(), level_texture_m.end());
  }
  result.lod_seconds = rt.lodSeconds();

  gen::StreetWalkOptions wo;
  wo.frames = int(options.frames * options.frame_step + 1);
  wo.seed = options.path_seed;
  const gen::CameraPath walk = gen::streetWalk(city.streets, wo);
  {
    const Camera c = pathCamera(walk, 0, options.width, options.height);
    for (size_t m = 0; m < rt.modelCount(); ++m) result.switch_m.push_back(rt.switchDistances(m, c).both());
  }
  if (!options.out_dir.empty()) fs::create_directories(fs::path(options.out_dir) / "frames");
  const std::vector<ModeSpec> specs = modeSpecs(options.compare_skinning, options.gpu_crowd);
  const gpu::LightSettings light = renderer.light();
  gpu::installGlCounters();  // the crowd pass's own CPU time: its wall time less the time inside GL calls
  std::unique_ptr<gpu::GpuCuller> city_gpu;
  if (!options.city_cpu) {
    city_gpu = std::make_unique<gpu::GpuCuller>(res.context.arena());
    city_gpu->setAllObjects();
  }

  for (const std::string& path_name : options.paths) {
    if (path_name != "pedestrian" && path_name != "elevated")
      throw Error("crowd bench", "unknown path '" + path_name + "' (pedestrian, elevated)");
    const gen::CameraPath path = path_name == "pedestrian" ? walk : elevated(walk);
    for (size_t count : options.agent_counts) {
      gen::CrowdOptions cro;
      cro.agents = count;
      cro.seed = options.crowd_seed;
      cro.model_shares = crowd_models.shares;
      cro.outfits = options.outfits;
      const gen::Crowd crowd = gen::generateCrowd(city.streets, cro);
      std::unique_ptr<gpu::GpuCrowd> gpu_crowd;
      if (options.gpu_crowd)
        gpu_crowd = std::make_unique<gpu::GpuCrowd>(gpuCrowdRoutes(crowd), gpuCrowdAgents(crowd, kCrowdIdBit),
                                                    rt.gpuCrowdModels(kCrowdNominalSpeed));
      FF_INFO("crowd bench: " << count << " agents, " << path_name << " path");
      CrowdRun run;
      run.agents = count;
      run.path = path_name;
      std::vector<std::vector<double>> wall(specs.size()), crowd_ms(specs.size()), crowd_cpu(specs.size()),
          psnr(specs.size()),
          bad(specs.size()), pixels(specs.size()), popping(specs.size()), geo(specs.size()), imp(specs.size()),
          in_view(specs.size()), tris(specs.size()), casters(specs.size()), shadow_texel(specs.size()),
          receiver_bad(specs.size()), occluded(specs.size()), over_budget(specs.size()), coarser(specs.size()),
          coarsened(specs.size()), skinned(specs.size());
      std::vector<image::ColorImage> prev(specs.size());
      std::vector<image::IdImage> prev_ids(specs.size());
      image::ColorImage prev_ref;
      image::IdImage prev_ref_ids;
      double ref_change = 0.0;
      std::vector<uint32_t> ids;
      std::vector<gpu::DrawItem> items;
      std::vector<Box3> item_bounds;
      gpu::OcclusionCuller city_culler;
      if (city_gpu) city_gpu->resetHistory();  // a new walk: no clusters visible "last frame"
      const size_t sample_every = options.samples > 0 ? std::max<size_t>(1, options.frames / size_t(options.samples)) : 0;
      // Path frame k's camera, agents and city items.
      float frame_time = 0.0f;  // the path frame's time, seconds (the GPU crowd's simulation)
      std::vector<double> states_ms;  // per frame: making the CPU modes' agent states
      auto setUpFrame = [&](size_t k, size_t& pf, Camera& camera, std::vector<runtime::CrowdAgentState>& states) {
        pf = std::min(k * options.frame_step, path.frames.size() - 1);
        frame_time = float(pf) / path.fps;
        camera = pathCamera(path, pf, options.width, options.height);
        const Stopwatch states_clock;
        states = crowdAgentStates(crowd, rt, float(pf) / path.fps);
        states_ms.push_back(states_clock.milliseconds());
        ids.clear();
        items.clear();
        item_bounds.clear();
        res.bvh.queryFrustum(Frustum::fromMatrix(camera.viewProjection()), ids);
        std::sort(ids.begin(), ids.end());
        if (!ids.empty()) res.gpu_scene.appendDrawItems(ids, items, camera, &item_bounds);
      };
      // Mode m's frame into `target`, timed: the city as the culled mode draws it (occlusion culling is exact: the
      // reference's city pixels), then the crowd.
      struct Timed {
        double total = 0.0, crowd = 0.0, crowd_cpu = 0.0;
        double skinned = -1.0;  // crowd-mixed's measured skinned draws under runtime.geometry_ms; -1: none
        runtime::CrowdFrameStats stats;
      };
      auto drawTimed = [&](size_t m, const Camera& camera, std::span<const runtime::CrowdAgentState> states) {
        Timed out;
        Stopwatch clock;
        target.bindForOpaquePass();
        target.clear(light.sky_color);
        if (city_gpu) city_gpu->draw(camera, target, gpu::RenderMode::Shaded, light);
        else city_culler.draw(renderer, camera, items, item_bounds, target);
        rt.finish();
        const double city_ms = clock.milliseconds();
        runtime::CrowdRuntime& mode_rt = specs[m].palette && rt_palette ? *rt_palette : rt;
        const gpu::GlCounters gl_before = gpu::glCounters();
        if (specs[m].gpu) {
          gpu_crowd->simulate(frame_time);
          target.bindForOpaquePass();
          out.stats = options.shadows ? rt.drawGpuShadowed(camera, *gpu_crowd, specs[m].policy, light, target,
                                                           options.shadow, options.agent_occlusion)
                                      : rt.drawGpu(camera, *gpu_crowd, specs[m].policy, light,
                                                   options.agent_occlusion ? &target : nullptr);
        } else {
          if (options.agent_occlusion) mode_rt.cullBehind(target);
          out.stats = drawCrowd(mode_rt, camera, states, specs[m].policy, light, target, options);
        }
        mode_rt.finish();
        out.total = clock.milliseconds();
        out.crowd = out.total - city_ms;
        const gpu::GlCounters gl_used = gpu::glCounters() - gl_before;
        out.crowd_cpu = std::max(0.0, out.crowd - gl_used.driver_ms - gl_used.measure_ms);  // as frame_runner.cpp
        if (specs[m].gpu) {  // the lists' sizes, read after the timed frame
          const std::vector<gpu::GpuCrowdCommand> commands = gpu_crowd->readCommands();
          for (size_t m2 = 0; m2 < gpu_crowd->modelCount(); ++m2) {  // the camera's lists, each level's
            for (size_t l = 0; l < gpu_crowd->levelCount(m2); ++l) {
              const uint64_t n = commands[gpu_crowd->levelCommand(m2, l)].instance_count;
              out.stats.geometry += n;
              out.stats.coarser += l > 0 ? n : 0;
              out.stats.draw.triangles += n * rt.gpuModel(m2).triangleCount(l);
            }
            out.stats.impostors += commands[2 * m2 + 1].instance_count;
            out.stats.draw.triangles += 2 * uint64_t(commands[2 * m2 + 1].instance_count);
          }
          for (size_t m2 = 0; options.shadows && m2 < gpu_crowd->modelCount(); ++m2) {
            out.stats.shadow_casters += commands[gpu_crowd->casterList(m2, true)].instance_count;
            for (size_t l = 0; l < gpu_crowd->levelCount(m2); ++l)
              out.stats.shadow_casters += commands[gpu_crowd->levelCommand(m2, l, true)].instance_count;
          }
          const gpu::GpuCrowd::Counts counts = gpu_crowd->readCounts();
          out.stats.in_view = counts.in_view;
          out.stats.occluded = counts.occluded;
          out.stats.over_budget = counts.over_budget;
        }
        if (options.runtime.geometry_ms > 0.0 && specs[m].policy == runtime::CrowdPolicy::Mixed &&
            out.stats.geometry > 0)
          out.skinned = specs[m].gpu ? rt.collectGpuGeometryMs(*gpu_crowd) : mode_rt.collectGeometryMs();
        return out;
      };
      for (size_t k = 0; k <= options.frames; ++k) {  // k = 0: the untimed warm-up frame
        size_t pf = 0;
        Camera camera;
        std::vector<runtime::CrowdAgentState> states;
        setUpFrame(k, pf, camera, states);
        // Reference: the city and every agent as skinned geometry.
        reference_target.bindForOpaquePass();
        reference_target.clear(light.sky_color);
        renderer.draw(camera, items, reference_target);
        drawCrowd(rt, camera, states, runtime::CrowdPolicy::Geometry, light, reference_target, options);
        rt.finish();
        const image::ColorImage ref = reference_target.readColor();
        const image::IdImage ref_ids = reference_target.readIds();
        const bool sample = k > 0 && sample_every > 0 && !options.out_dir.empty() && (k - 1) % sample_every == 0;
        std::ostringstream tag_stream;  // (not string + literal: GCC 12 warns falsely with -Wrestrict)
        tag_stream << "a" << count << "_" << path_name << "_f" << pf;
        const std::string tag = tag_stream.str();
        if (sample) image::writePng((fs::path(options.out_dir) / "frames" / (tag + "_reference.png")).string(), ref);
        for (size_t j = 0; j < specs.size(); ++j) {
          const size_t m = (j + k) % specs.size();  // rotated order
          const Timed timed = drawTimed(m, camera, states);
          const runtime::CrowdFrameStats& st = timed.stats;
          if (k == 0) continue;
          wall[m].push_back(timed.total);
          crowd_ms[m].push_back(timed.crowd);
          crowd_cpu[m].push_back(timed.crowd_cpu);
          skinned[m].push_back(timed.skinned);
          geo[m].push_back(double(st.geometry));
          imp[m].push_back(double(st.impostors));
          in_view[m].push_back(double(st.in_view));
          occluded[m].push_back(double(st.occluded));
          over_budget[m].push_back(double(st.over_budget));
          coarser[m].push_back(double(st.coarser));
          coarsened[m].push_back(double(st.coarsened));
          tris[m].push_back(double(st.draw.triangles));
          casters[m].push_back(double(st.shadow_casters));
          shadow_texel[m].push_back(double(st.shadow_texel_m));
          image::ColorImage frame = target.readColor();
          image::IdImage frame_ids = target.readIds();
          const CrowdPixelError e = crowdPixelError(ref, ref_ids, frame, frame_ids);
          psnr[m].push_back(e.psnr_db);
          bad[m].push_back(e.bad_share);
          pixels[m].push_back(double(e.pixels));
          receiver_bad[m].push_back(double(receiverBadPixels(ref, ref_ids, frame, frame_ids)));
          if (k > 1)
            popping[m].push_back(crowdPopping(prev[m], prev_ids[m], frame, frame_ids, prev_ref, prev_ref_ids, ref, ref_ids));
          if (sample) {
            const fs::path dir = fs::path(options.out_dir) / "frames";
            image::writePng((dir / (tag + "_" + specs[m].name + ".png")).string(), frame);
            image::writePng((dir / (tag + "_" + specs[m].name + "_diff.png")).string(), image::diffHeatmap(ref, frame));
          }
          prev[m] = std::move(frame);
          prev_ids[m] = std::move(frame_ids);
        }
        if (k > 1) {
          // The reference's own change on its crowd pixels, for scale.
          const CrowdPixelError change = crowdPixelError(prev_ref, prev_ref_ids, ref, ref_ids, 8);
          ref_change += change.mae;
        }
        prev_ref = ref;
        prev_ref_ids = ref_ids;
      }
      // Further timing passes over the same frames (no images): each frame's fastest render is kept, so that a slow
      // spell of the machine during one pass does not decide a mode's time.
      for (int pass = 1; pass < options.timing_passes; ++pass) {
        for (size_t k = 1; k <= options.frames; ++k) {
          size_t pf = 0;
          Camera camera;
          std::vector<runtime::CrowdAgentState> states;
          setUpFrame(k, pf, camera, states);
          for (size_t j = 0; j < specs.size(); ++j) {
            const size_t m = (j + k + size_t(pass)) % specs.size();
            const Timed timed = drawTimed(m, camera, states);
            wall[m][k - 1] = std::min(wall[m][k - 1], timed.total);
            crowd_ms[m][k - 1] = std::min(crowd_ms[m][k - 1], timed.crowd);
            crowd_cpu[m][k - 1] = std::min(crowd_cpu[m][k - 1], timed.crowd_cpu);
            if (timed.skinned >= 0.0)
              skinned[m][k - 1] = skinned[m][k - 1] < 0.0 ? timed.skinned : std::min(skinned[m][k - 1], timed.skinned);
          }
        }
      }
      run.reference_popping_mean = options.frames > 1 ? ref_change / double(options.frames - 1) : 0.0;
      for (size_t k = 1; k < states_ms.size(); ++k) run.cpu_states_ms += states_ms[k] / double(states_ms.size() - 1);
      auto mean = [](const std::vector<double>& v) {
        double s = 0.0;
        for (double x : v) s += x;
        return v.empty() ? 0.0 : s / double(v.size());
      };
      for (size_t m = 0; m < specs.size(); ++m) {
        CrowdModeResult r;
        r.name = specs[m].name;
        r.wall = summarize(wall[m]);
        r.crowd = summarize(crowd_ms[m]);
        r.crowd_cpu = summarize(crowd_cpu[m]);
        std::vector<double> timed_skinned;
        for (double v : skinned[m])
          if (v >= 0.0) timed_skinned.push_back(v);
        r.skinned_ms = summarize(timed_skinned);
        r.skinned_over = size_t(std::count_if(timed_skinned.begin(), timed_skinned.end(),
                                              [&](double v) { return v > options.runtime.geometry_ms; }));
        r.psnr_mean = mean(psnr[m]);
        r.psnr_min = psnr[m].empty() ? 0.0 : *std::min_element(psnr[m].begin(), psnr[m].end());
        r.bad_share_mean = mean(bad[m]);
        r.crowd_pixels_mean = mean(pixels[m]);
        r.popping_mean = mean(popping[m]);
        r.popping_max = popping[m].empty() ? 0.0 : *std::max_element(popping[m].begin(), popping[m].end());
        r.geometry_agents = mean(geo[m]);
        r.impostor_agents = mean(imp[m]);
        r.in_view = mean(in_view[m]);
        r.occluded = mean(occluded[m]);
        r.over_budget = mean(over_budget[m]);
        r.coarser = mean(coarser[m]);
        r.coarsened = mean(coarsened[m]);
        r.triangles = mean(tris[m]);
        r.shadow_casters = mean(casters[m]);
        r.shadow_texel_m = mean(shadow_texel[m]);
        r.receiver_bad_pixels = mean(receiver_bad[m]);
        run.modes.push_back(r);
      }
      for (CrowdModeResult& r : run.modes) {
        r.speedup = r.wall.median > 0.0 ? run.modes[0].wall.median / r.wall.median : 0.0;
        r.crowd_speedup = r.crowd.median > 0.0 ? run.modes[0].crowd.median / r.crowd.median : 0.0;
      }
      result.runs.push_back(std::move(run));
    }
  }

  result.markdown = crowdMarkdown(result, options);
  if (!options.out_dir.empty()) writeCrowdReport(result, options);
  return result;
}

}  // namespace farfield::eval
