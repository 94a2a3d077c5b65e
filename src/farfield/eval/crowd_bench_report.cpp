// The crowd bench's report: crowd.md's tables and crowd.json.
#include "farfield/eval/crowd_bench_report.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "farfield/core/number_format.h"

namespace fs = std::filesystem;

namespace farfield::eval {

std::vector<MixedAgainstImpostor> mixedAgainstImpostor(const CrowdRun& run) {
  std::vector<MixedAgainstImpostor> out;
  auto find = [&](const std::string& name) -> const CrowdModeResult* {
    for (const CrowdModeResult& r : run.modes)
      if (r.name == name) return &r;
    return nullptr;
  };
  for (const char* suffix : {"", "-gpu"}) {
    const CrowdModeResult* mixed = find(std::string("crowd-mixed") + suffix);
    const CrowdModeResult* impostor = find(std::string("crowd-impostor") + suffix);
    if (!mixed || !impostor) continue;
    MixedAgainstImpostor c;
    c.mixed = mixed->name;
    c.impostor = impostor->name;
    c.psnr_mean = mixed->psnr_mean;
    c.psnr_min = mixed->psnr_min;
    c.crowd_ratio = impostor->crowd.median > 0.0 ? mixed->crowd.median / impostor->crowd.median : 0.0;
    c.crowd_gpu_ratio = impostor->crowd_gpu.median > 0.0 ? mixed->crowd_gpu.median / impostor->crowd_gpu.median : 0.0;
    c.own_cpu_ms = mixed->crowd_cpu.median;
    out.push_back(c);
  }
  return out;
}

std::string crowdMarkdown(const CrowdBenchResult& result, const CrowdBenchOptions& options) {
  std::ostringstream md;
  md << "- city: generated, " << options.blocks << " blocks, detail " << options.detail << ", seed "
     << options.city_seed << " (" << thousands(result.city_triangles) << " triangles, drawn in every mode as "
     << (options.city_cpu ? "culled-cpu draws it: frustum, facing and occlusion culled on the CPU, depth read back"
                          : "culled draws it: the GPU-driven frame, no readback")
     << ")\n";
  md << "- size " << options.width << "x" << options.height << ", " << options.frames
     << " measured frames per run (every " << options.frame_step << "th frame of a 30 fps street walk, seed "
     << options.path_seed << "), one warm-up frame"
     << (options.timing_passes > 1
             ? ", each frame's time the fastest of " + std::to_string(options.timing_passes) + " passes over the path"
             : std::string())
     << "\n";
  md << "- renderer: " << result.renderer
     << "; GPU ms: the GPU's time of the city and the crowd, crowd GPU ms the crowd pass's ("
     << (result.gpu_time_queries
             ? "timestamp queries, read after the frame"
             : "a software rasterizer: the CPU clock between waits for its work, about the wall time")
     << ")\n";
  for (size_t m = 0; m < result.layouts.size(); ++m) {
    const gpu::AtlasLayout& l = result.layouts[m];
    const runtime::CrowdAtlasChoice& c = result.atlas_choices[m];
    md << "- " << result.model_names[m] << ": " << thousands(result.model_triangles[m]) << " triangles"
       << (result.model_cutout[m] ? " (texels cut out)" : " (opaque: no cut-out test)") << "; atlas "
       << (c.from_bound ? "chosen from the bound (" + formatNumber("%.2f", options.runtime.error_px) + " px from " +
                              formatNumber("%.1f", options.runtime.bound_switch_m) + " m on)"
                        : std::string("fixed"))
       << ": " << l.azimuths << "x" << l.elevations << (l.octahedral ? " octahedral" : "") << " views x " << l.frames
       << " frames (frame error "
       << formatNumber("%.3f", c.frame_error_m) << " m), cells " << l.cell_width << "x" << l.cell_height << " texels ("
       << formatNumber("%.3f", c.texel_m) << " m), " << formatNumber("%.1f", double(result.atlas_bytes[m]) / 1048576.0)
       << " MiB uncompressed (" << formatNumber("%.0f", double(result.atlas_bytes[m]) / 1024.0 / l.frames)
       << " KiB per frame, the lecture: about 256 KB compressed); switch to impostor beyond "
       << formatNumber("%.1f", result.switch_m[m]) << " m\n";
  }
  if (options.runtime.blend_views) md << "- impostors blend the four views around the direction to the eye\n";
  if (options.agent_occlusion) {
    md << "- agents hidden behind the city left out in every mode (not in the reference), per frame:";
    for (const CrowdRun& run : result.runs)
      md << " " << thousands(run.agents) << " " << run.path << " "
         << formatNumber("%.0f", run.modes.empty() ? 0.0 : run.modes[0].occluded) << " of "
         << formatNumber("%.0f", run.modes.empty() ? 0.0 : run.modes[0].in_view) << " in view;";
    md << "\n";
  }
  if (options.shadows)
    md << "- shadows: one " << options.shadow.map_size << "x" << options.shadow.map_size << " map, receivers within "
       << formatNumber("%.0f", options.shadow.distance_m) << " m, in the reference and every mode"
       << (options.impostor_shadows ? " (crowd-mixed's geometry agents cast as impostors)" : "") << "\n";
  md << "- skinning: "
     << (options.runtime.skinning == gpu::Skinning::BakedPoses
             ? "baked poses (each palette pose's vertices skinned once, read per agent)"
             : "palette (four joint matrices blended per vertex)")
     << ", in the reference and every mode\n";
  if (options.runtime.geometry_ms > 0.0)
    md << "- crowd-mixed's geometry budget in time: " << formatNumber("%.1f", options.runtime.geometry_ms)
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
       << formatNumber("%.2f", options.runtime.geometry_lod_px) << " px (levels held over every palette pose; "
       << formatNumber("%.1f", result.lod_seconds) << " s to build; a level's error "
       << (options.runtime.lod_texture ? "the larger of its distance to the mesh and its texture deviation"
                                       : "its distance to the mesh alone")
       << ", given as distance / texture deviation):";
    for (size_t m = 0; m < result.level_m.size(); ++m) {
      md << " " << result.model_names[m];
      for (size_t l = 0; l < result.level_m[m].size(); ++l)
        md << (l == 0 ? " " : ", ") << thousands(size_t(result.level_triangles[m][l])) << " triangles "
           << formatNumber("%.1f", result.level_surface_m[m][l] * 100.0) << " / "
           << formatNumber("%.1f", result.level_texture_m[m][l] * 100.0) << " cm";
      md << ";";
    }
    md << "\n";
  }
  md << "- bake: " << formatNumber("%.2f", result.bake_seconds) << " s for all models\n\n";
  md << "| agents | path | mode | median ms | GPU ms | crowd ms | crowd GPU ms | crowd own CPU ms | "
        "crowd draws / KiB up / syncs | speedup | "
        "crowd speedup | geometry / impostor agents | triangles | PSNR dB (min) | >8/255 | "
        "popping mean / max (ref change) | shadow casters / receiver px off |\n";
  md << "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const CrowdRun& run : result.runs)
    for (const CrowdModeResult& r : run.modes)
      md << "| " << thousands(run.agents) << " | " << run.path << " | " << r.name << " | "
         << formatNumber("%.1f", r.wall.median) << " | " << formatNumber("%.1f", r.gpu.median) << " | "
         << formatNumber("%.1f", r.crowd.median) << " | " << formatNumber("%.2f", r.crowd_gpu.median) << " | "
         << formatNumber("%.3f", r.crowd_cpu.median) << " | " << formatNumber("%.0f", r.draw_calls) << " / "
         << formatNumber("%.1f", r.upload_bytes / 1024.0) << " / " << formatNumber("%.0f", r.syncs) << " | "
         << formatNumber("%.2fx", r.speedup) << " | " << formatNumber("%.2fx", r.crowd_speedup) << " | "
         << formatNumber("%.0f", r.geometry_agents) << " / " << formatNumber("%.0f", r.impostor_agents)
         << (r.over_budget > 0.0 ? " (" + formatNumber("%.0f", r.over_budget) + " over the budget)" : std::string())
         << (r.coarser > 0.0 ? " (" + formatNumber("%.0f", r.coarser) + " coarser)" : std::string())
         << (r.coarsened > 0.0 ? " (" + formatNumber("%.0f", r.coarsened) + " coarsened for the budget)"
                               : std::string())
         << " | " << thousands(size_t(r.triangles)) << " | " << formatNumber("%.1f", r.psnr_mean) << " ("
         << formatNumber("%.1f", r.psnr_min) << ") | " << formatNumber("%.3f", r.bad_share_mean) << " | "
         << formatNumber("%.2f", r.popping_mean) << " / " << formatNumber("%.2f", r.popping_max) << " ("
         << formatNumber("%.2f", run.reference_popping_mean) << ") | " << formatNumber("%.0f", r.shadow_casters)
         << " / " << formatNumber("%.0f", r.receiver_bad_pixels) << " |\n";
  md << "\nIssue 45's goals: crowd-mixed at least 30 dB on the crowd's pixels, its crowd pass within 20 % of "
        "crowd-impostor's (each against the impostor mode of its own path; median crowd ms, and crowd GPU ms), its own "
        "CPU time at most 0.5 ms (median):\n";
  for (const CrowdRun& run : result.runs)
    for (const MixedAgainstImpostor& c : mixedAgainstImpostor(run))
      md << "- " << thousands(run.agents) << " agents, " << run.path << ", " << c.mixed << ": "
         << formatNumber("%.1f", c.psnr_mean) << " dB (min " << formatNumber("%.1f", c.psnr_min) << "), crowd pass "
         << formatNumber("%.2fx", c.crowd_ratio) << " " << c.impostor << "'s (GPU time "
         << formatNumber("%.2fx", c.crowd_gpu_ratio) << "): "
         << (c.psnr_met() && c.pass_met() ? "30 dB and the pass both met"
             : c.psnr_met()               ? "30 dB met, the pass not"
             : c.pass_met()               ? "the pass met, 30 dB not"
                                          : "neither 30 dB nor the pass met")
         << "; own CPU " << formatNumber("%.3f", c.own_cpu_ms) << " ms (" << (c.cpu_met() ? "met" : "not met")
         << ")\n";
  md << "\nThe CPU modes' agent states (poses and phases of every agent, eval::crowdAgentStates) are made before the "
        "crowd pass, outside its time:";
  for (const CrowdRun& run : result.runs)
    md << " " << formatNumber("%.2f", run.cpu_states_ms) << " ms (" << thousands(run.agents) << ", " << run.path << ")";
  md << ". The crowd-*-gpu modes simulate every agent inside it.\n";
  if (options.runtime.geometry_ms > 0.0) {
    md << "\ncrowd-mixed's skinned draws against the " << formatNumber("%.1f", options.runtime.geometry_ms)
       << " ms budget (the frames that drew skinned agents):\n";
    for (const CrowdRun& run : result.runs)
      for (const CrowdModeResult& r : run.modes)
        if (r.skinned_ms.count > 0)
          md << "- " << thousands(run.agents) << " agents, " << run.path << ", " << r.name << ": median "
             << formatNumber("%.2f", r.skinned_ms.median) << " ms, max " << formatNumber("%.2f", r.skinned_ms.max)
             << " ms; " << r.skinned_over << " of " << r.skinned_ms.count << " frames over\n";
  }
  return md.str();
}

// crowd.json and crowd.md in the output directory.
void writeCrowdReport(const CrowdBenchResult& result, const CrowdBenchOptions& options) {
  nlohmann::json j;
  j["renderer"] = result.renderer;
  j["gpu_time"] = result.gpu_time_queries ? "timestamp queries" : "cpu clock (software rasterizer)";
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
                           {"median_ms", r.wall.median}, {"p95_ms", r.wall.p95}, {"gpu_median_ms", r.gpu.median},
                           {"crowd_median_ms", r.crowd.median}, {"crowd_gpu_median_ms", r.crowd_gpu.median},
                           {"crowd_own_cpu_median_ms", r.crowd_cpu.median}, {"crowd_draw_calls_mean", r.draw_calls},
                           {"crowd_upload_bytes_mean", r.upload_bytes}, {"crowd_syncs_mean", r.syncs},
                           {"crowd_syncs_max", r.syncs_max}, {"cpu_states_ms", run.cpu_states_ms},
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
  for (const CrowdRun& run : result.runs)
    for (const MixedAgainstImpostor& c : mixedAgainstImpostor(run))
      j["mixed_against_impostor"].push_back({{"agents", run.agents}, {"path", run.path}, {"mixed", c.mixed},
                                             {"impostor", c.impostor}, {"psnr_db_mean", c.psnr_mean},
                                             {"psnr_db_min", c.psnr_min}, {"crowd_ratio", c.crowd_ratio},
                                             {"crowd_gpu_ratio", c.crowd_gpu_ratio}, {"psnr_met", c.psnr_met()},
                                             {"pass_met", c.pass_met()}, {"own_cpu_median_ms", c.own_cpu_ms},
                                             {"own_cpu_met", c.cpu_met()}});
  std::ofstream(fs::path(options.out_dir) / "crowd.json") << j.dump(2) << "\n";
  std::ofstream(fs::path(options.out_dir) / "crowd.md") << result.markdown;
}

}  // namespace farfield::eval
