// Parallel bake of cell impostors (Sillion et al. 1997, sections 4.1-4.2): one capture per cell on the GL thread,
// the constructions and files on worker threads (bake/gl_workers.h).
#include "farfield/bake/bake.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <set>
#include <thread>

#include "farfield/bake/gl_workers.h"
#include "farfield/extract/ground_height.h"
#include "farfield/core/error.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/renderer.h"
#include "farfield/store/impostor_store.h"

namespace farfield::bake {

using extract::BakeOptions;
using extract::kDepthMesh;
using extract::kGridMesh;


namespace {


struct Job {
  CellBake record;
  store::CellEntry entry;
  impostor::ImpostorCapture capture;
};

}  // namespace


CellSelection selectCells(const urban::CellMap& cells, std::vector<uint32_t> half_edges) {
  if (half_edges.empty())
    for (uint32_t e = 0; e < cells.cellCount(); ++e) half_edges.push_back(e);
  CellSelection out;
  std::set<uint32_t> seen;
  for (uint32_t e : half_edges) {
    if (e >= cells.cellCount())
      throw Error("cell " + std::to_string(e), "no such half-edge (the street graph has " +
                                                   std::to_string(cells.cellCount()) + ")");
    if (!seen.insert(e).second) continue;
    (cells.degenerate(e) ? out.skipped_degenerate : out.todo).push_back(e);
  }
  out.requested = seen.size();
  return out;
}

std::vector<uint32_t> cellsOnPath(const urban::CellMap& cells, const gen::CameraPath& path) {
  std::vector<uint32_t> order;
  std::set<uint32_t> seen;
  for (const gen::PathFrame& f : path.frames) {
    const uint32_t cell = cells.lookup(f.eye, f.at - f.eye);
    if (cell != urban::kNone && seen.insert(cell).second) order.push_back(cell);
  }
  return order;
}

BakeReport bakeCells(gpu::Context& context, const scene::Scene& scene, const urban::CellMap& cells,
                     std::vector<uint32_t> half_edges, const BakeOptions& options, const std::string& out_dir) {
  extract::validateBakeOptions(options);
  if (cells.objectCount() != scene.objects.size())
    throw Error("bake", "the cell map was made for " + std::to_string(cells.objectCount()) +
                            " objects but the scene has " + std::to_string(scene.objects.size()));
  Stopwatch wall;
  BakeReport report;
  report.store_dir = out_dir;

  // The cells: requested order without repeats; degenerate ones reported and skipped.
  CellSelection selection = selectCells(cells, std::move(half_edges));
  const std::vector<uint32_t> todo = std::move(selection.todo);
  report.skipped_degenerate = std::move(selection.skipped_degenerate);
  report.requested = selection.requested;

  const extract::GroundHeight ground_height(scene, cells.assignment().shared);
  const auto ground = [&](float x, float y) { return ground_height.at(x, y, 0.0f); };

  store::StoreIndex index;
  index.techniques = options.techniques;
  index.scene = options.scene_label;
  index.scene_objects = scene.objects.size();
  index.local_model = urban::localModelName(cells.options().local);
  index.cell_lookup = urban::cellLookupName(cells.options().lookup);
  index.options = {{"resolution", options.resolution},
                   {"fov_deg", options.fov_deg},
                   {"eye_height", options.eye_height},
                   {"near", options.near_plane},
                   {"far", options.far_plane},
                   {"block_margin", cells.options().block_margin},
                   {"detect_seen_from_below", options.capture.detect_seen_from_below},
                   {"depth_mesh",
                    {{"grid_spacing_px", options.depth_mesh.grid_spacing_px},
                     {"contour_tolerance_px", options.depth_mesh.contour.tolerance_px},
                     {"contour_dilation_px", options.depth_mesh.contour_dilation_px}}},
                   {"grid_mesh", {{"grid_spacing_px", options.grid_mesh.grid_spacing_px}}}};
  {
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec) throw Error(out_dir, "cannot create the store directory: " + ec.message());
  }
  // A new generation of files next to those of the store being replaced (which stays readable until the new index
  // is in place: store/impostor_store.h).
  index.generation = store::nextGeneration(out_dir);
  const uint64_t generation = index.generation;
  store::writeStreets(out_dir, index, cells.graph().toJson().dump() + "\n");

  const size_t workers = workerCount(options.workers);
  report.workers = workers;

  std::mutex results_mutex;
  std::vector<CellBake> records;
  std::vector<store::CellEntry> entries;
  context.makeCurrent();
  gpu::GpuScene gpu_scene(scene);
  gpu::Renderer renderer;
  const auto produce = [&](const std::function<bool(std::shared_ptr<Job>)>& push) {
    for (uint32_t cell : todo) {
      auto job = std::make_shared<Job>();
      const Camera camera = cellCamera(cells, cell, options, ground);
      const std::vector<uint32_t> distant = cells.distantObjects(cell);
      job->capture = impostor::captureView(renderer, gpu_scene, distant, camera, options.capture);
      job->record.half_edge = cell;
      job->record.render_ms = job->capture.render_ms;
      job->record.data_pixels = job->capture.data_pixels;
      job->record.distant_objects = distant.size();
      job->entry.half_edge = cell;
      job->entry.camera = camera;
      job->entry.local_objects = cells.localObjects(cell);
      job->record.local_objects = job->entry.local_objects.size();
      job->entry.distant_objects = distant.size();
      job->entry.data_pixels = job->capture.data_pixels;
      job->entry.render_ms = job->capture.render_ms;
      if (!push(std::move(job))) return;
    }
  };
  const auto consume = [&](Job& job) {
    std::map<std::string, impostor::DepthMeshImpostor> built;
    for (const std::string& technique : options.techniques) {
      Stopwatch t;
      if (technique == kDepthMesh) {
        impostor::DepthMeshOptions o = options.depth_mesh;
        o.resolution = options.resolution;
        o.fov_y = job.capture.camera.fov_y;
        built[technique] = impostor::buildDepthMesh(job.capture, o);
      } else {
        built[technique] = impostor::buildGridMesh(job.capture, options.grid_mesh);
      }
      job.record.build_ms[technique] = t.milliseconds();
      job.record.triangles[technique] = built[technique].mesh.triangleCount();
    }
    Stopwatch t;
    std::map<std::string, const impostor::DepthMeshImpostor*> pointers;
    for (const auto& [technique, imp] : built) pointers[technique] = &imp;
    store::writeCell(out_dir, job.entry, pointers, generation);
    for (auto& [technique, stored] : job.entry.impostors) stored.build_ms = job.record.build_ms[technique];
    job.record.write_ms = t.milliseconds();
    std::lock_guard<std::mutex> lock(results_mutex);
    records.push_back(job.record);
    entries.push_back(std::move(job.entry));
  };
  produceAndConsume<Job>(workers, options.queue_capacity, options.progress ? "bake" : "", todo.size(), produce,
                         consume);

  std::sort(records.begin(), records.end(), [](const CellBake& a, const CellBake& b) {
    return a.half_edge < b.half_edge;
  });
  std::sort(entries.begin(), entries.end(), [](const store::CellEntry& a, const store::CellEntry& b) {
    return a.half_edge < b.half_edge;
  });
  index.cells = std::move(entries);
  store::writeIndex(out_dir, index);
  report.cells = std::move(records);
  report.wall_s = wall.seconds();
  return report;
}

}  // namespace farfield::bake
