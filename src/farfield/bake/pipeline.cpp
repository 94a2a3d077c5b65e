// The extractor pipeline (Decoret et al. 1999, sections 4-5): PVS sampling, near/far segmentation, the single mesh
// (also Sillion et al. 1997's cell impostor), layering by visibility events and one meshed impostor per layer, baked
// in parallel (GL stages and captures on the calling thread, meshes and files on worker threads: bake/gl_workers.h).
#include "farfield/bake/pipeline.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <initializer_list>
#include <map>
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
#include "farfield/store/bake_journal.h"
#include "farfield/store/store_compare.h"

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

// A cell's report row from its record (a cell resumed from the journal).
PipelineCellReport reportOf(const store::CellEntry& e) {
  PipelineCellReport r;
  r.half_edge = e.half_edge;
  if (!e.pipeline) return r;
  const store::CellPipeline& p = *e.pipeline;
  r.pvs = p.pvs.size();
  r.near = p.near.size();
  r.far = p.far.size();
  r.layers = p.layers.size();
  for (const store::StoredLayer& l : p.layers)
    for (const store::StoredView& v : l.views) r.layer_triangles += v.triangles;
  for (const store::StoredView& v : p.single.views) r.single_triangles += v.triangles;
  r.pvs_ms = p.pvs_ms;
  r.weights_ms = p.weights_ms;
  r.capture_ms = e.render_ms;
  for (const store::StoredLayer* l : {&p.single})
    for (const store::StoredView& v : l->views) r.build_ms += v.build_ms;
  for (const store::StoredLayer& l : p.layers)
    for (const store::StoredView& v : l.views) r.build_ms += v.build_ms;
  return r;
}

// A cell's record as the index writes it (its "cells" element), for the journal.
nlohmann::json cellRecord(const store::StoreIndex& header, const store::CellEntry& entry) {
  store::StoreIndex one = header;
  one.shard.reset();  // the record alone, not checked against the part
  one.cells = {entry};
  return store::indexToJson(one)["cells"][0];
}

// What identifies a bake for --resume: the index without its cells and storage, and the cells to bake.
nlohmann::json bakeFingerprint(const store::StoreIndex& header, std::vector<uint32_t> todo) {
  nlohmann::json j = store::indexToJson(header);
  j.erase("cells");
  j.erase("storage");
  std::sort(todo.begin(), todo.end());
  return {{"index", std::move(j)}, {"todo", todo}};
}

// Every file a cell's record names, with its check (a resumed cell must still have all of them, intact).
bool cellFilesIntact(const std::string& dir, const store::CellEntry& e) {
  if (!e.pipeline) return false;
  std::vector<const store::StoredLayer*> layers{&e.pipeline->single};
  for (const store::StoredLayer& l : e.pipeline->layers) layers.push_back(&l);
  try {
    for (const store::StoredLayer* l : layers)
      for (const store::StoredView& v : l->views)
        for (const auto& [name, check] : {std::pair{v.texture, v.texture_check}, std::pair{v.mesh, v.mesh_check},
                                          std::pair{v.ids, v.ids_check}})
          if (!name.empty()) store::readCheckedFile((fs::path(dir) / name).string(), check, "");
  } catch (const Error&) {
    return false;
  }
  return true;
}

// The finished database of this same bake in `dir`, if that is what it holds (--resume after the end).
bool finishedAlready(const std::string& dir, store::StoreIndex header, const std::vector<uint32_t>& todo,
                     const std::string& streets_text) {
  std::error_code ec;
  if (!fs::is_regular_file(fs::path(dir) / store::kIndexFile, ec)) return false;
  store::StoreIndex existing;
  try {
    existing = store::readIndex(dir);
  } catch (const Error&) {
    return false;
  }
  header.generation = existing.generation;
  header.streets = store::streetsFileName(existing.generation);
  header.streets_check = store::fileCheck(streets_text);
  std::vector<uint32_t> have;
  for (const store::CellEntry& e : existing.cells) have.push_back(e.half_edge);
  std::vector<uint32_t> want = todo;
  std::sort(want.begin(), want.end());
  return have == want && bakeFingerprint(existing, {}) == bakeFingerprint(header, {});
}

}  // namespace

PipelineReport bakePipeline(gpu::Context& context, const scene::Scene& scene, const urban::CellMap& cells,
                            std::vector<uint32_t> half_edges, const PipelineSpec& spec,
                            const PipelineOptions& options, const std::string& out_dir, const BakeControl& control) {
  validatePipelineOptions(options);
  if (spec.stages.empty()) throw Error("--pipeline", "no stages given");
  if (options.base.workers < 0) throw Error("--workers", "must be 0 (automatic) or more");
  if (cells.objectCount() != scene.objects.size())
    throw Error("bake", "the cell map was made for " + std::to_string(cells.objectCount()) +
                            " objects but the scene has " + std::to_string(scene.objects.size()));
  Stopwatch wall;
  PipelineReport report;
  report.store_dir = out_dir;
  report.shard = control.shard;
  CellSelection selection = selectCells(cells, std::move(half_edges));
  std::vector<uint32_t> todo = std::move(selection.todo);
  report.skipped_degenerate = std::move(selection.skipped_degenerate);
  report.requested = selection.requested;
  report.view_space = todo.size();
  {
    std::error_code ec;
    fs::create_directories(fs::path(out_dir) / "cells", ec);
    if (ec) throw Error(out_dir, "cannot create the store directory: " + ec.message());
  }
  // The index's header, known before any cell is baked (the journal's fingerprint).
  store::StoreIndex index;
  index.scene = options.base.scene_label;
  index.scene_objects = scene.objects.size();
  index.local_model = urban::localModelName(cells.options().local);
  index.cell_lookup = urban::cellLookupName(cells.options().lookup);
  index.pipeline = spec.stages;
  index.online = spec.online();
  index.options = {{"pipeline", pipelineOptionsToJson(options)}, {"block_margin", cells.options().block_margin}};
  if (control.shard) {
    store::ShardRecord shard;
    shard.index = control.shard->index;
    shard.count = control.shard->count;
    shard.scene_crc32 = sceneDigest(scene);
    shard.view_space = todo;
    std::sort(shard.view_space.begin(), shard.view_space.end());
    std::vector<uint32_t> streets;  // a street's two cells in one shard: they share their PVS views
    for (uint32_t c : todo) streets.push_back(c / 2);
    shard.cells = partitionCells(todo, cellWeights(cells, todo, options), shard.count, streets)[shard.index];
    todo = shard.cells;
    index.shard = std::move(shard);
  }
  const std::string streets_text = cells.graph().toJson().dump() + "\n";

  // Resume: the journal's generation and finished cells; otherwise a new generation of files next to those of the
  // store being replaced (which stays readable until the new index is in place: store/impostor_store.h).
  std::vector<store::CellEntry> entries;
  std::vector<nlohmann::json> journal_cells;
  std::optional<store::JournalContents> journal;
  if (control.resume) journal = store::readJournal(out_dir);
  const std::string journal_file = (fs::path(out_dir) / store::kJournalFile).string();
  if (journal) {
    const nlohmann::json& g = journal->header.contains("index") ? journal->header["index"].value("generation", nlohmann::json())
                                                                 : nlohmann::json();
    if (!g.is_number_unsigned() || g.get<uint64_t>() == 0)
      throw Error(journal_file, "line 1: the header has no generation: start the bake without --resume");
    index.generation = g.get<uint64_t>();
  } else {
    if (control.resume && finishedAlready(out_dir, index, todo, streets_text)) {
      store::StoreIndex done = store::readIndex(out_dir);
      for (const store::CellEntry& e : done.cells) report.cells.push_back(reportOf(e));
      report.already_complete = true;
      report.resumed = done.cells.size();
      report.storage = done.storage;
      report.wall_s = wall.seconds();
      return report;
    }
    index.generation = store::nextGeneration(out_dir);
  }
  const uint64_t generation = index.generation;
  store::writeStreets(out_dir, index, streets_text);
  const nlohmann::json fingerprint = bakeFingerprint(index, todo);
  if (journal) {
    if (journal->header != fingerprint)
      throw Error(journal_file, "the bake in progress is another bake (" +
                                    store::firstDifference(journal->header, fingerprint) +
                                    "): run it with its own arguments, or without --resume to start again");
    report.torn_journal_lines = journal->torn_lines;
    // The journal's records, validated as an index holds them; a cell recorded twice keeps its last record.
    std::map<uint32_t, nlohmann::json> by_cell;
    for (const nlohmann::json& c : journal->cells)
      if (c.is_object() && c.contains("half_edge") && c["half_edge"].is_number_unsigned())
        by_cell[c["half_edge"].get<uint32_t>()] = c;
    nlohmann::json j = store::indexToJson(index);
    j["cells"] = nlohmann::json::array();
    for (auto& [cell, record] : by_cell) j["cells"].push_back(record);
    store::StoreIndex recorded = store::indexFromJson(j, journal_file);
    for (store::CellEntry& e : recorded.cells) {
      if (!std::binary_search(fingerprint["todo"].begin(), fingerprint["todo"].end(), nlohmann::json(e.half_edge)) ||
          !cellFilesIntact(out_dir, e)) {
        ++report.resume_rejected;
        continue;
      }
      journal_cells.push_back(by_cell[e.half_edge]);
      entries.push_back(std::move(e));
    }
    report.resumed = entries.size();
    std::set<uint32_t> finished;
    for (const store::CellEntry& e : entries) finished.insert(e.half_edge);
    std::erase_if(todo, [&](uint32_t c) { return finished.count(c) > 0; });
  }
  store::JournalWriter journal_writer(out_dir, fingerprint, journal_cells);

  const std::vector<std::string> baked = spec.baked();
  const bool bake_images = std::find(baked.begin(), baked.end(), kStageMmi) != baked.end() ||
                           std::find(baked.begin(), baked.end(), kStageSingle) != baked.end();
  const size_t workers = workerCount(options.base.workers);
  report.workers = workers;

  std::mutex results_mutex;
  std::vector<PipelineCellReport> records;
  for (const store::CellEntry& e : entries) records.push_back(reportOf(e));
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
    // The cell is finished once its files are durable and the journal names them.
    store::syncCellFiles(out_dir);
    journal_writer.append(cellRecord(index, job.entry));
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

  index.cells = std::move(entries);
  index.storage = storageReport(index, out_dir, options, cells.cellCount());
  store::writeIndex(out_dir, index);
  store::removeJournal(out_dir);

  report.cells = std::move(records);
  report.threshold_rad = threshold;
  report.storage = index.storage;
  report.wall_s = wall.seconds();
  return report;
}

}  // namespace farfield::bake
