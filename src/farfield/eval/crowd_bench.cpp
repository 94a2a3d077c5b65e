#include "farfield/eval/crowd_bench.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <span>
#include <sstream>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/timer.h"
#include "farfield/eval/crowd_bench_report.h"
#include "farfield/eval/crowd_metrics.h"
#include "farfield/eval/gpu_crowd_input.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/gpu_crowd.h"
#include "farfield/gpu/gpu_culler.h"
#include "farfield/gpu/stage_clock.h"
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
  // The GPU's time of each timed frame, marked before the city, between the city and the crowd, and after the crowd
  // (timestamps: they may lie inside the crowd's own timer of its skinned draws), read after the frame's end.
  gpu::StageClock gpu_clock(3, 2);
  result.gpu_time_queries = gpu_clock.source() == gpu::GpuTimer::Source::Query;
  uint64_t gpu_frame = 0;

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
          gpu_ms(specs.size()), crowd_gpu(specs.size()),
          draws(specs.size()), uploads(specs.size()), syncs(specs.size()), psnr(specs.size()),
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
        double gpu = 0.0, crowd_gpu = 0.0;  // the GPU's time: the city and the crowd, the crowd alone
        gpu::GlCounters gl;    // the crowd pass's GL calls (its draws, uploads and waits for the GPU)
        double skinned = -1.0;  // crowd-mixed's measured skinned draws under runtime.geometry_ms; -1: none
        runtime::CrowdFrameStats stats;
      };
      auto drawTimed = [&](size_t m, const Camera& camera, std::span<const runtime::CrowdAgentState> states) {
        Timed out;
        gpu_clock.beginFrame(gpu_frame++);
        Stopwatch clock;
        target.bindForOpaquePass();
        target.clear(light.sky_color);
        if (city_gpu) city_gpu->draw(camera, target, gpu::RenderMode::Shaded, light);
        else city_culler.draw(renderer, camera, items, item_bounds, target);
        gpu_clock.mark(1);
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
        gpu_clock.mark(2);
        {
          const gpu::GlMeasurement harness;  // the timed frame's end: the harness's wait, not the crowd's
          mode_rt.finish();
        }
        out.total = clock.milliseconds();
        out.crowd = out.total - city_ms;
        out.gl = gpu::glCounters() - gl_before;
        gpu_clock.finished([&](uint64_t, std::span<const double> stage_ms) {
          out.gpu = stage_ms[0] + stage_ms[1];
          out.crowd_gpu = stage_ms[1];
        });
        out.crowd_cpu = std::max(0.0, out.crowd - out.gl.driver_ms - out.gl.measure_ms);  // as frame_runner.cpp
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
          gpu_ms[m].push_back(timed.gpu);
          crowd_gpu[m].push_back(timed.crowd_gpu);
          draws[m].push_back(double(timed.gl.draw_calls));
          uploads[m].push_back(double(timed.gl.upload_bytes));
          syncs[m].push_back(double(timed.gl.syncs));
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
            gpu_ms[m][k - 1] = std::min(gpu_ms[m][k - 1], timed.gpu);
            crowd_gpu[m][k - 1] = std::min(crowd_gpu[m][k - 1], timed.crowd_gpu);
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
        r.gpu = summarize(gpu_ms[m]);
        r.crowd_gpu = summarize(crowd_gpu[m]);
        r.draw_calls = mean(draws[m]);
        r.upload_bytes = mean(uploads[m]);
        r.syncs = mean(syncs[m]);
        r.syncs_max = syncs[m].empty() ? 0.0 : *std::max_element(syncs[m].begin(), syncs[m].end());
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
