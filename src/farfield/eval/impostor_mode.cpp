// Local model + cell impostor per frame (Sillion et al. 1997, section 3: "always draw the combination of the
// impostors of the current cell and its local model, to obtain a view of the entire model").
//
// Why registerImpostorModes() instead of a static RegisterMode object: the eval library is static and nothing in an
// executable refers to this file's symbols except through the registry, so the linker would drop the object file
// together with its static initialiser and the modes would silently be missing. A function the executable calls
// pulls the file in for certain.
#include "farfield/eval/impostor_mode.h"

#include "farfield/eval/mode_options.h"

#include <algorithm>
#include <filesystem>
#include <functional>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/eval/mmi_mode.h"

namespace fs = std::filesystem;

namespace farfield::eval {

namespace {
constexpr size_t kDefaultCache = 16;
}

void registerImpostorModes() {
  registerMode("depth-mesh",
                     "local model (blocks touching the street) + the cell's textured depth-mesh impostor "
                     "(Sillion 1997); --impostors DIR",
                     [](const ModeContext& c) { return std::make_unique<ImpostorMode>("depth-mesh", c); });
  registerMode("grid-mesh",
                     "local model + the cell's regular-grid mesh impostor (baseline); --impostors DIR",
                     [](const ModeContext& c) { return std::make_unique<ImpostorMode>("grid-mesh", c); });
  registerMmiModes();
}

// ---------------------------------------------------------------------------------------------------------------
// ImpostorCache

ImpostorCache::ImpostorCache(size_t capacity, Loader loader)
    : capacity_(std::max<size_t>(1, capacity)), loader_(std::move(loader)) {}

const impostor::GpuImpostor& ImpostorCache::get(uint32_t cell) {
  auto it = map_.find(cell);
  if (it != map_.end()) {
    order_.splice(order_.begin(), order_, it->second.position);
    return *it->second.impostor;
  }
  Stopwatch timer;
  std::unique_ptr<impostor::GpuImpostor> loaded = loader_(cell);
  const double ms = timer.milliseconds();
  ++loads_;
  load_ms_total_ += ms;
  load_ms_max_ = std::max(load_ms_max_, ms);
  while (map_.size() >= capacity_) {
    map_.erase(order_.back());
    order_.pop_back();
    ++evictions_;
  }
  order_.push_front(cell);
  Slot& slot = map_[cell];
  slot.position = order_.begin();
  slot.impostor = std::move(loaded);
  return *slot.impostor;
}

size_t ImpostorCache::gpuBytes() const {
  size_t bytes = 0;
  for (const auto& [cell, slot] : map_) bytes += slot.impostor->gpuBytes();
  return bytes;
}

// ---------------------------------------------------------------------------------------------------------------
// ImpostorMode

ImpostorMode::ImpostorMode(std::string technique, const ModeContext& context)
    : technique_(std::move(technique)) {
  std::string key = technique_;
  std::replace(key.begin(), key.end(), '-', '_');
  dir_ = context.option(key + "_dir", context.option("impostor_dir"));
  if (dir_.empty())
    throw Error("mode '" + technique_ + "'", "needs an impostor store: farfield bench --impostors DIR (or "
                                             "--mode-option impostor_dir=DIR), baked with farfield bake");
  cache_capacity_ = countOption(context, "impostor_cache", kDefaultCache);
  projective_ = switchOption(context, "impostor_projective", true);
  lookup_option_ = context.option("cell_lookup");
  if (!lookup_option_.empty()) urban::parseCellLookup(lookup_option_, "--mode-option cell_lookup");
}

ImpostorMode::~ImpostorMode() = default;

void ImpostorMode::prepare(const ModeContext& context) {
  scene_ = context.scene;
  gpu_scene_ = context.gpu_scene;
  bvh_ = context.bvh;
  runtime::OpenStore opened = runtime::openStore(dir_, *scene_, lookup_option_);
  index_ = std::move(opened.index);
  graph_ = std::move(opened.graph);
  locator_ = std::move(opened.locator);
  const std::string& index_file = opened.index_file;
  if (!index_.hasTechnique(technique_)) {
    std::string have;
    for (const std::string& t : index_.techniques) have += (have.empty() ? "" : ", ") + t;
    throw Error(index_file, "holds no " + technique_ + " impostors (it has: " + have +
                                "); bake with --technique " + technique_ + " or both");
  }

  impostor_id_ = uint32_t(scene_->objects.size() + 1);
  object_triangles_.assign(scene_->objects.size() + 1, 0);
  for (const scene::Object& o : scene_->objects)
    for (const scene::Part& p : o.parts) object_triangles_[o.id] += scene_->meshes[p.mesh].triangleCount();
  local_mask_.assign(scene_->objects.size() + 1, 0);

  impostor::GpuImpostorOptions gpu_options;
  gpu_options.projective_texture = projective_;
  cache_ = std::make_unique<ImpostorCache>(cache_capacity_, [this, gpu_options](uint32_t cell) {
    const store::CellEntry* entry = index_.find(cell);
    FF_CHECK(entry != nullptr);
    return std::make_unique<impostor::GpuImpostor>(store::loadImpostor(dir_, *entry, technique_), gpu_options);
  });
}

void ImpostorMode::frame(FrameContext& frame) {
  const Camera& camera = frame.camera();
  const Vec3 view = camera.at - camera.eye;
  const uint32_t cell = locator_.lookup(graph_, camera.eye, view);
  ++frames_;
  if (cell != current_cell_) {
    // New cell: rebuild the local-model mask.
    if (current_entry_)
      for (uint32_t id : current_entry_->local_objects) local_mask_[id] = 0;
    current_cell_ = cell;
    current_entry_ = cell == urban::kNone ? nullptr : index_.find(cell);
    if (current_entry_)
      for (uint32_t id : current_entry_->local_objects) local_mask_[id] = 1;
    ++cell_changes_;
  }
  if (cell != urban::kNone) ++visited_[cell];

  ids_.clear();
  const Frustum frustum = Frustum::fromMatrix(camera.viewProjection());
  bvh_->queryFrustum(frustum, ids_);
  if (current_entry_) {
    ids_.erase(std::remove_if(ids_.begin(), ids_.end(), [&](uint32_t id) { return !local_mask_[id]; }),
               ids_.end());
  } else {
    ++fallback_frames_;  // not baked: every object in the frustum, as the culled mode
  }
  std::sort(ids_.begin(), ids_.end());
  // GpuScene::appendDrawItems takes an empty list as "all objects": nothing visible must draw nothing.
  if (!ids_.empty()) gpu_scene_->appendDrawItems(ids_, frame.items(), camera);
  for (uint32_t id : ids_) local_triangles_sum_ += double(object_triangles_[id]);
  local_objects_sum_ += double(ids_.size());

  if (current_entry_) {
    const impostor::GpuImpostor& imp = cache_->get(cell);
    imp.appendDrawItems(frame.items(), impostor_id_);
    impostor_triangles_sum_ += double(imp.triangleCount());
    peak_gpu_bytes_ = std::max(peak_gpu_bytes_, cache_->gpuBytes());
  }
}

std::map<std::string, double> ImpostorMode::info() const {
  std::map<std::string, double> out;
  const double n = frames_ ? double(frames_) : 1.0;
  out["frames"] = double(frames_);
  out["impostor_loads"] = cache_ ? double(cache_->loads()) : 0.0;
  out["impostor_load_ms_max"] = cache_ ? cache_->loadMsMax() : 0.0;
  out["impostor_load_ms_mean"] = cache_ && cache_->loads() ? cache_->loadMsTotal() / double(cache_->loads()) : 0.0;
  out["cache_capacity"] = double(cache_capacity_);
  out["cache_evictions"] = cache_ ? double(cache_->evictions()) : 0.0;
  out["fallback_frames"] = double(fallback_frames_);
  out["cells_visited"] = double(visited_.size());
  out["cell_changes"] = double(cell_changes_);
  out["baked_cells"] = double(index_.cells.size());
  const size_t impostor_frames = frames_ - fallback_frames_;
  out["mean_impostor_triangles"] = impostor_frames ? impostor_triangles_sum_ / double(impostor_frames) : 0.0;
  out["mean_geometry_triangles"] = local_triangles_sum_ / n;
  out["mean_geometry_objects"] = local_objects_sum_ / n;
  out["peak_cache_gpu_bytes"] = double(peak_gpu_bytes_);
  return out;
}

}  // namespace farfield::eval
