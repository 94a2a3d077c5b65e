// What `farfield bake` prints: the pipeline it runs, then per-cell statistics, storage against the paper's
// estimate (Decoret et al. 1999, section 5.1), shards and resumption, and the wall time.
#include "bake_report.h"

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <vector>

namespace farfield::app {
namespace {

struct Summary {
  double mean = 0.0, median = 0.0, max = 0.0, total = 0.0;
};
Summary summarize(std::vector<double> v) {
  Summary s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.total = std::accumulate(v.begin(), v.end(), 0.0);
  s.mean = s.total / double(v.size());
  s.median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  s.max = v.back();
  return s;
}

std::string megabytes(double bytes) {
  char buf[32];
  if (bytes >= 1e9)
    std::snprintf(buf, sizeof(buf), "%.2f GB", bytes / 1e9);
  else if (bytes >= 1e6)
    std::snprintf(buf, sizeof(buf), "%.1f MB", bytes / 1e6);
  else
    std::snprintf(buf, sizeof(buf), "%.1f kB", bytes / 1e3);
  return buf;
}

}  // namespace

void printPipelineSetup(const extract::PipelineSpec& spec, const extract::PipelineOptions& options) {
  std::string baked, online;
  for (const std::string& s : spec.baked()) baked += (baked.empty() ? "" : ",") + s;
  for (const std::string& s : spec.online()) online += (online.empty() ? "" : ",") + s;
  std::printf("pipeline:      baked [%s], online [%s]\n", baked.c_str(), online.empty() ? "" : online.c_str());
  std::printf("layers:        error %.1f px in %dx%d frames at %.0f deg, %s mesh (%d x %d grid), %s view(s), "
              "%dx%d images\n",
              options.error_px, options.frame_width, options.frame_height, double(options.frame_fov_deg),
              extract::layerMeshName(options.mesh), options.grid_cells,
              options.grid_cells, extract::layerViewsName(options.views), options.base.resolution,
              options.base.resolution);
}

void printPipelineReport(const bake::PipelineReport& report, size_t scene_objects, bool list, bool resume,
                         const std::string& out_dir) {
  if (report.shard)
    std::printf("shard:         %u/%u: %zu of the %zu cells of the view space\n", report.shard->index,
                report.shard->count, report.cells.size(), report.view_space);
  if (report.already_complete) {
    std::printf("resume:        %s already holds this bake, complete (%zu cells): nothing to do\n",
                out_dir.c_str(), report.cells.size());
    return;
  }
  if (resume)
    std::printf("resume:        %zu cells kept from the journal, %zu baked now (%zu rejected, %zu torn journal "
                "line)\n",
                report.resumed, report.cells.size() - report.resumed, report.resume_rejected,
                report.torn_journal_lines);
  std::printf("threshold:     T = %.4f rad\n", report.threshold_rad);
  std::printf("cells:         %zu requested, %zu baked, %zu skipped (too short)\n", report.requested,
              report.cells.size(), report.skipped_degenerate.size());
  if (list) {
    std::printf("\n%8s %6s %6s %6s %6s %10s %10s %9s %9s %9s %9s\n", "cell", "pvs", "near", "far", "layers",
                "mmi tris", "smi tris", "pvs ms", "layer ms", "capt ms", "build ms");
    for (const bake::PipelineCellReport& c : report.cells)
      std::printf("%8u %6zu %6zu %6zu %6zu %10zu %10zu %9.0f %9.1f %9.0f %9.0f\n", c.half_edge, c.pvs, c.near,
                  c.far, c.layers, c.layer_triangles, c.single_triangles, c.pvs_ms, c.weights_ms, c.capture_ms,
                  c.build_ms);
  }
  if (!report.cells.empty()) {
    std::vector<double> pvs, near, far, layers, mmi_tris, smi_tris, pvs_ms, weights_ms, capture_ms, build_ms;
    for (const bake::PipelineCellReport& c : report.cells) {
      pvs.push_back(double(c.pvs));
      near.push_back(double(c.near));
      far.push_back(double(c.far));
      layers.push_back(double(c.layers));
      mmi_tris.push_back(double(c.layer_triangles));
      smi_tris.push_back(double(c.single_triangles));
      pvs_ms.push_back(c.pvs_ms);
      weights_ms.push_back(c.weights_ms);
      capture_ms.push_back(c.capture_ms);
      build_ms.push_back(c.build_ms);
    }
    std::printf("\nper cell            %10s %10s %10s   (scene: %zu objects)\n", "mean", "median", "max",
                scene_objects);
    const auto row = [](const char* label, const Summary& s) {
      std::printf("%-19s %10.1f %10.1f %10.1f\n", label, s.mean, s.median, s.max);
    };
    row("PVS objects", summarize(pvs));
    row("near objects", summarize(near));
    row("far objects", summarize(far));
    row("layers", summarize(layers));
    row("MMI triangles", summarize(mmi_tris));
    row("SMI triangles", summarize(smi_tris));
    row("PVS ms", summarize(pvs_ms));
    row("layering ms", summarize(weights_ms));
    row("capture ms", summarize(capture_ms));
    row("mesh build ms", summarize(build_ms));
  }
  const nlohmann::json& st = report.storage;
  if (st.value("cells", 0) > 0) {
    std::printf("\nstorage (section 5.1): %zu cells, %.2f layers per cell, %d view(s) per layer\n",
                st["cells"].get<size_t>(), st["mean_layers"].get<double>(), st["views_per_layer"].get<int>());
    std::printf("  paper's estimate with our layer count: %s (%s per image, %s per mesh)\n",
                megabytes(st["estimate_bytes_measured_layers"].get<double>()).c_str(),
                megabytes(st["image_bytes_each"].get<double>()).c_str(),
                megabytes(st["mesh_bytes_each"].get<double>()).c_str());
    std::printf("  paper's worst case (3 layers):         %s\n",
                megabytes(st["estimate_bytes_3_layers"].get<double>()).c_str());
    std::printf("  written (PNG textures + meshes):       %s (textures %s, meshes %s; SMI included)\n",
                megabytes(st["written_bytes"].get<double>()).c_str(),
                megabytes(st["written_texture_bytes"].get<double>()).c_str(),
                megabytes(st["written_mesh_bytes"].get<double>()).c_str());
    std::printf("  plus per-texel object ids (for measurement): %s\n",
                megabytes(st.value("written_id_bytes", 0.0)).c_str());
    if (st.contains("city_cells"))
      std::printf("  whole city (%zu cells): estimate %s, written at this rate %s\n", st["city_cells"].get<size_t>(),
                  megabytes(st["estimate_bytes_city"].get<double>()).c_str(),
                  megabytes(st["projected_written_bytes_city"].get<double>()).c_str());
  }
  std::printf("\nwall:          %.1f s for %zu cells (%.2f s per cell)\n", report.wall_s, report.cells.size(),
              report.cells.empty() ? 0.0 : report.wall_s / double(report.cells.size()));
  std::printf("wrote %s/index.json\n", out_dir.c_str());
}

}  // namespace farfield::app
