// The extractor pipeline (Decoret et al. 1999, sections 4-5): PVS sampling, near/far segmentation, the single mesh
// (also Sillion et al. 1997's cell impostor), layering by visibility events and one meshed impostor per layer, baked
// in parallel (GL stages and captures on the calling thread, meshes and files on worker threads: bake/gl_workers.h).
#include "farfield/bake/pipeline.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <initializer_list>
#include <limits>
#include <type_traits>
#include <filesystem>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "farfield/bake/gl_workers.h"
#include "farfield/core/error.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/impostor/depth_mesh.h"
#include "farfield/impostor/grid_mesh.h"

namespace fs = std::filesystem;

namespace farfield::bake {

using namespace extract;

// ---------------------------------------------------------------------------------------------------------------
// Storage (section 5.1)

nlohmann::json storageReport(const store::StoreIndex& index, const std::string& dir, const PipelineOptions& options,
                             size_t city_cells) {
  size_t cells = 0, layers = 0, layer_views = 0, single_views = 0;
  uint64_t texture_bytes = 0, mesh_bytes = 0, raw_texture_bytes = 0, id_bytes = 0;
  auto file_bytes = [&](const std::string& name) -> uint64_t {
    if (name.empty()) return 0;
    std::error_code ec;
    const uintmax_t n = fs::file_size(fs::path(dir) / name, ec);
    return ec ? 0 : uint64_t(n);
  };
  auto count_view = [&](const store::StoredView& v) {
    texture_bytes += file_bytes(v.texture);
    mesh_bytes += file_bytes(v.mesh);
    id_bytes += file_bytes(v.ids);
    if (!v.texture.empty()) raw_texture_bytes += uint64_t(v.camera.width) * uint64_t(v.camera.height) * 4;
  };
  for (const store::CellEntry& c : index.cells) {
    if (!c.pipeline || !(c.pipeline->has_mmi || c.pipeline->has_single)) continue;
    ++cells;
    layers += c.pipeline->layers.size();
    for (const store::StoredLayer& l : c.pipeline->layers)
      for (const store::StoredView& v : l.views) {
        ++layer_views;
        count_view(v);
      }
    for (const store::StoredView& v : c.pipeline->single.views) {
      ++single_views;
      count_view(v);
    }
  }
  const int views = options.views == LayerViews::Six ? 6 : 1;
  const double image = double(options.base.resolution) * double(options.base.resolution) * 3.0;  // RGB, as the paper
  const double grid = double(options.grid_cells) * double(options.grid_cells) * 3.0 * 4.0;      // float xyz
  const double mean_layers = cells ? double(layers) / double(cells) : 0.0;
  nlohmann::json j;
  j["cells"] = cells;
  j["layers"] = layers;
  j["mean_layers"] = mean_layers;
  j["views_per_layer"] = views;
  j["image_bytes_each"] = image;
  j["mesh_bytes_each"] = grid;
  j["estimate_bytes_measured_layers"] = double(layer_views) * (image + grid);
  j["estimate_bytes_3_layers"] = double(cells) * 3.0 * double(views) * (image + grid);
  j["estimate_bytes_paper_city"] = 572.0 * 18.0 * (256.0 * 256.0 * 3.0 + 10800.0);  // section 5.1's own numbers
  j["written_texture_bytes"] = texture_bytes;
  j["written_mesh_bytes"] = mesh_bytes;
  j["written_bytes"] = texture_bytes + mesh_bytes;
  j["written_id_bytes"] = id_bytes;  // per-texel object ids: for measurement (item buffers), not for the picture
  j["uncompressed_texture_bytes"] = raw_texture_bytes;
  j["single_mesh_views"] = single_views;
  if (city_cells > 0 && cells > 0) {
    j["city_cells"] = city_cells;
    j["estimate_bytes_city"] = double(city_cells) * mean_layers * double(views) * (image + grid);
    j["projected_written_bytes_city"] = double(city_cells) * double(texture_bytes + mesh_bytes) / double(cells);
  }
  return j;
}

// ---------------------------------------------------------------------------------------------------------------
// The bake

namespace {

struct PipelineJob {
  CellWork work;
  store::CellEntry entry;
};

}  // namespace

PipelineReport bakePipeline(gpu::Context& context, const scene::Scene& scene, const urban::CellMap& cells,
                            std::vector<uint32_t> half_edges, const PipelineSpec& spec,
                            const PipelineOptions& options, const std::string& out_dir) {
  validatePipelineOptions(options);
  if (spec.stages.empty()) throw Error("--pipeline", "no stages given");
  if (options.base.workers < 0) throw Error("--workers", "must be 0 (automatic) or more");
  if (cells.objectCount() != scene.objects.size())
    throw Error("bake", "the cell map was made for " + std::to_string(cells.objectCount()) +
                            " objects but the scene has " + std::to_string(scene.objects.size()));
  Stopwatch wall;
  PipelineReport report;
  report.store_dir = out_dir;
  CellSelection selection = selectCells(cells, std::move(half_edges));
  const std::vector<uint32_t> todo = std::move(selection.todo);
  report.skipped_degenerate = std::move(selection.skipped_degenerate);
  report.requested = selection.requested;
  {
    std::error_code ec;
    fs::create_directories(fs::path(out_dir) / "cells", ec);
    if (ec) throw Error(out_dir, "cannot create the store directory: " + ec.message());
  }
  // A new generation of files next to those of the store being replaced (which stays readable until the new index
  // is in place: store/impostor_store.h).
  store::StoreIndex index;
  index.generation = store::nextGeneration(out_dir);
  const uint64_t generation = index.generation;
  store::writeStreets(out_dir, index, cells.graph().toJson().dump() + "\n");

  const std::vector<std::string> baked = spec.baked();
  const bool bake_images = std::find(baked.begin(), baked.end(), kStageMmi) != baked.end() ||
                           std::find(baked.begin(), baked.end(), kStageSingle) != baked.end();
  const size_t workers = workerCount(options.base.workers);
  report.workers = workers;

  std::mutex results_mutex;
  std::vector<store::CellEntry> entries;
  std::vector<PipelineCellReport> records;
  context.makeCurrent();
  gpu::GpuScene gpu_scene(scene);
  PipelineRunner runner(scene, gpu_scene, cells, options);  // outlives the workers, which build meshes with it
  const auto produce = [&](const std::function<bool(std::shared_ptr<PipelineJob>)>& push) {
    for (uint32_t cell : todo) {
      auto job = std::make_shared<PipelineJob>();
      job->work = runner.start(cell);
      for (const std::string& stage : baked) runner.runStage(stage, job->work);
      store::CellEntry& e = job->entry;
      e.half_edge = cell;
      e.camera = job->work.street_camera;
      e.local_objects = cells.localObjects(cell);
      e.distant_objects = cells.distantObjects(cell).size();
      e.render_ms = job->work.capture_ms;
      if (!push(std::move(job))) return;
    }
  };
  const auto consume = [&](PipelineJob& job) {
    CellWork& w = job.work;
    if (bake_images) {
      runner.buildMeshes(w);
      // The construction is timed per cell: each view gets an equal share.
      size_t views = w.single_views.size();
      for (const auto& layer : w.layer_views) views += layer.size();
      const double build_share = views ? w.build_ms / double(views) : 0.0;
      const auto write = [&](store::StoredView& record, const impostor::DepthMeshImpostor& view, const char* kind,
                             size_t layer, size_t index) {
        const store::StoredView written =
            store::writeLayerView(out_dir, store::layerFileStem(w.cell, kind, layer, index, generation), view);
        record.texture = written.texture;
        record.texture_check = written.texture_check;
        record.mesh = written.mesh;
        record.mesh_check = written.mesh_check;
        record.ids = written.ids;
        record.ids_check = written.ids_check;
        record.build_ms = build_share;
      };
      for (size_t l = 0; l < w.layer_views.size(); ++l)
        for (size_t v = 0; v < w.layer_views[l].size(); ++v)
          write(w.result.layers[l].views[v], w.layer_views[l][v], "mmi", l, v);
      for (size_t v = 0; v < w.single_views.size(); ++v) write(w.result.single.views[v], w.single_views[v], "smi", 0, v);
    }
    PipelineCellReport r;
    r.half_edge = w.cell;
    r.pvs = w.result.pvs.size();
    r.near = w.result.near.size();
    r.far = w.result.far.size();
    r.layers = w.result.layers.size();
    for (const store::StoredLayer& l : w.result.layers)
      for (const store::StoredView& v : l.views) r.layer_triangles += v.triangles;
    for (const store::StoredView& v : w.result.single.views) r.single_triangles += v.triangles;
    r.pvs_ms = w.result.pvs_ms;
    r.weights_ms = w.result.weights_ms;
    r.capture_ms = w.capture_ms;
    r.build_ms = w.build_ms;
    job.entry.pipeline = std::move(w.result);
    w.layer_views.clear();
    w.single_views.clear();
    std::lock_guard<std::mutex> lock(results_mutex);
    records.push_back(r);
    entries.push_back(std::move(job.entry));
  };
  produceAndConsume<PipelineJob>(workers, options.base.queue_capacity,
                                 options.base.progress ? "bake pipeline" : "", todo.size(), produce, consume);
  const double threshold = runner.threshold();

  std::sort(entries.begin(), entries.end(),
            [](const store::CellEntry& a, const store::CellEntry& b) { return a.half_edge < b.half_edge; });
  std::sort(records.begin(), records.end(),
            [](const PipelineCellReport& a, const PipelineCellReport& b) { return a.half_edge < b.half_edge; });

  index.scene = options.base.scene_label;
  index.scene_objects = scene.objects.size();
  index.local_model = urban::localModelName(cells.options().local);
  index.cell_lookup = urban::cellLookupName(cells.options().lookup);
  index.pipeline = spec.stages;
  index.online = spec.online();
  index.options = {{"pipeline", pipelineOptionsToJson(options)}, {"block_margin", cells.options().block_margin}};
  index.cells = std::move(entries);
  index.storage = storageReport(index, out_dir, options, cells.cellCount());
  store::writeIndex(out_dir, index);

  report.cells = std::move(records);
  report.threshold_rad = threshold;
  report.storage = index.storage;
  report.wall_s = wall.seconds();
  return report;
}

}  // namespace farfield::bake
