// The cell walkthrough's cells made resident: read ahead on the reader's thread, uploaded view by view in the frame
// that enters a cell or before it (Walkthrough::loadAhead), evicted least recently used under the GPU budget.
#include <algorithm>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/runtime/prefetch.h"
#include "farfield/runtime/walkthrough.h"
#include "farfield/runtime/walkthrough_cells.h"

namespace farfield::runtime {

std::unique_ptr<Walkthrough::CellUpload> Walkthrough::startCell(const store::CellEntry& entry,
                                                                 std::shared_ptr<store::CellViews> read) {
  if (!entry.pipeline)
    throw Error(options_.database, "cell " + std::to_string(entry.half_edge) + " has no pipeline record");
  const Representation kind = options_.representation;
  auto upload = std::make_unique<CellUpload>();
  upload->half_edge = entry.half_edge;
  upload->record = &*entry.pipeline;
  upload->cell = std::make_unique<Cell>();
  Cell& cell = *upload->cell;
  if (!online_stages_.empty()) {
    Stopwatch timer;
    upload->work = runner_->resume(entry.half_edge, *entry.pipeline);
    runner_->runStages(online_stages_, upload->work);
    upload->record = &upload->work.result;
    stats_.online_ms_total += timer.milliseconds();
    ++stats_.online_runs;
    cell.online = true;
  }
  const store::CellPipeline& record = *upload->record;
  cell.geometry_mask.assign(scene_.objects.size() + 1, 0);
  const std::vector<uint32_t>& geometry = kind == Representation::Visible ? record.pvs : record.near;
  for (uint32_t id : geometry) cell.geometry_mask[id] = 1;
  for (uint32_t id = 1; id < uint32_t(cell.geometry_mask.size()); ++id)
    if (cell.geometry_mask[id]) cell.geometry.push_back(id);
  if (kind == Representation::Local || kind == Representation::Visible) {
    upload->layer = upload->layerCount();  // nothing to upload
    return upload;
  }

  upload->single = kind == Representation::Smi;
  if (!cell.online) upload->read = read ? std::move(read) : reader_->take(entry.half_edge, &plan_.report.read);
  for (size_t l = 0; l < upload->layerCount(); ++l) {
    const store::StoredLayer& stored = upload->stored(l);
    Layer layer;
    layer.objects = stored.objects;
    layer.validity = stored.validity;
    for (uint32_t id : layer.objects) layer.bounds.expand(scene_.objects[id - 1].world_bounds);
    cell.layers.push_back(std::move(layer));
  }
  return upload;
}

uint64_t Walkthrough::uploadNextView(CellUpload& upload, uint64_t room, bool* full) {
  while (!upload.done()) {
    const size_t l = upload.layer, v = upload.view;
    if (++upload.view >= upload.stored(l).views.size()) {
      ++upload.layer;
      upload.view = 0;
    }
    impostor::DepthMeshImpostor& imp = upload.viewAt(l, v);
    if (imp.empty()) continue;
    impostor::GpuImpostorOptions gpu_options;
    gpu_options.id_texture = options_.object_ids;  // per-pixel object ids in item buffers, one draw call per view
    Stopwatch timer;
    Layer& layer = upload.cell->layers[l];
    layer.views.push_back(std::make_unique<impostor::GpuImpostor>(imp, gpu_options));
    const double ms = timer.milliseconds();
    upload_rate_.add(ms, store::decodedBytes(imp));
    stats_.view_upload_ms_max = std::max(stats_.view_upload_ms_max, ms);
    const uint64_t bytes = layer.views.back()->gpuBytes();
    if (bytes > room) {  // given back, and next again
      layer.views.pop_back();
      upload.layer = l;
      upload.view = v;
      if (full) *full = true;
      return 0;
    }
    layer.view_eyes.push_back(imp.camera.eye);
    layer.view_station.push_back(upload.stored(l).views[v].station);
    imp = {};  // the decoded copy is no longer needed
    upload.cell->gpu_bytes += bytes;
    return bytes;
  }
  return 0;
}

Walkthrough::Cell& Walkthrough::cell(uint32_t half_edge, bool* loaded) {
  *loaded = false;
  const auto it = cells_.find(half_edge);
  if (it != cells_.end()) {
    order_.remove(half_edge);
    order_.push_front(half_edge);
    const auto ahead = std::find(uploaded_ahead_.begin(), uploaded_ahead_.end(), half_edge);
    if (ahead != uploaded_ahead_.end()) {  // its first entry: loadAhead did the load
      uploaded_ahead_.erase(ahead);
      *loaded = true;
      plan_.report.read = "uploaded";
      ++stats_.entered_uploaded;
    }
    return *it->second;
  }
  const store::CellEntry* entry = index_.find(half_edge);
  FF_CHECK(entry != nullptr);
  Stopwatch timer;
  std::unique_ptr<CellUpload> upload;
  if (uploading_ && uploading_->half_edge == half_edge) {
    upload = std::move(uploading_);
    resident_bytes_ -= upload->cell->gpu_bytes;  // counted while it was being uploaded; again below
    plan_.report.read = upload->views_ahead > 0 ? "partly" : "ready";  // read ahead, and some views uploaded ahead
    stats_.entered_partly += upload->views_ahead > 0 ? 1 : 0;
  } else {
    upload = startCell(*entry, nullptr);
  }
  while (!upload->done()) uploadNextView(*upload);
  const double ms = timer.milliseconds();
  plan_.report.load_ms = ms;
  *loaded = true;
  ++stats_.loads;
  stats_.load_ms_total += ms;
  stats_.load_ms_max = std::max(stats_.load_ms_max, ms);
  resident_bytes_ += upload->cell->gpu_bytes;
  order_.push_front(half_edge);
  Cell& out = *(cells_[half_edge] = std::move(upload->cell));
  evict(half_edge);
  return out;
}

// Least recently used cells leave the GPU until the resident bytes fit the budget; `keep` (the current cell) stays,
// and a cell being uploaded ahead is dropped before it.
void Walkthrough::evict(uint32_t keep) {
  if (resident_bytes_ > options_.gpu_budget_bytes && uploading_) {
    resident_bytes_ -= uploading_->cell->gpu_bytes;
    uploading_.reset();
    ++stats_.uploads_dropped;
  }
  while (resident_bytes_ > options_.gpu_budget_bytes && order_.size() > 1) {
    const uint32_t victim = order_.back() == keep ? *std::next(order_.rbegin()) : order_.back();
    const auto it = cells_.find(victim);
    resident_bytes_ -= it->second->gpu_bytes;
    cells_.erase(it);
    order_.remove(victim);
    uploaded_ahead_.erase(std::remove(uploaded_ahead_.begin(), uploaded_ahead_.end(), victim), uploaded_ahead_.end());
    ++stats_.evictions;
  }
}

// The cells the viewer may enter next, in the direction of motion (runtime/prefetch.h). Queued when the cell or the
// junction the viewer heads for changes; what was queued before and not started is dropped (the viewer went
// elsewhere). The motion is measured from where the eye was when it last changed by a metre or more.
void Walkthrough::queueCellsAhead(uint32_t half_edge, const Vec3& eye) {
  if (!reader_ || !options_.read_ahead) return;
  const Vec2 motion(eye.x - motion_from_.x, eye.y - motion_from_.y);
  if (glm::length(motion) >= 1.0f) motion_from_ = eye;
  const PrefetchChoice choice = prefetchCells(graph_, half_edge, motion, options_.prefetch_cells);
  if (half_edge == ahead_of_ && choice.exit_junction == ahead_junction_) return;
  ahead_of_ = half_edge;
  ahead_junction_ = choice.exit_junction;
  reader_->cancelQueued();
  cells_ahead_.clear();
  for (uint32_t next : choice.cells)
    if (!cells_.count(next)) {
      reader_->prefetch(next);
      cells_ahead_.push_back(next);
    }
  // A cell begun ahead that the viewer no longer heads for is finished all the same: its decoded views have left the
  // reader, and at a junction the cell lookup may come back to it a few frames later.
}

double Walkthrough::loadAhead(const Camera& camera, double budget_ms) {
  if (placed_) return loadPlacedAhead(camera, budget_ms);
  return loadCellsAhead(budget_ms);
}

double Walkthrough::loadCellsAhead(double budget_ms) {
  if (!reader_ || !options_.read_ahead || !(budget_ms > 0.0) || stats_.frames == 0) return 0.0;
  if (resident_bytes_ >= full_at_bytes_) return 0.0;
  full_at_bytes_ = ~uint64_t(0);
  Stopwatch timer;
  for (;;) {
    if (!uploading_) {
      for (uint32_t next : cells_ahead_) {
        if (cells_.count(next)) continue;
        if (std::shared_ptr<store::CellViews> ready = reader_->takeIfReady(next)) {
          const store::CellEntry* entry = index_.find(next);
          FF_CHECK(entry != nullptr);
          uploading_ = startCell(*entry, std::move(ready));
          break;
        }
      }
      if (!uploading_) break;  // nothing read yet
    }
    CellUpload& upload = *uploading_;
    const impostor::DepthMeshImpostor* next = upload.next();
    if (next && upload_rate_.known() &&
        upload_rate_.predictMs(store::decodedBytes(*next)) > budget_ms - timer.milliseconds())
      break;
    // Nothing is evicted for a load ahead: it stops where the next view does not fit the GPU budget, until
    // evictions or dropped uploads bring the resident bytes under what they were then.
    bool full = false;
    const uint64_t room = options_.gpu_budget_bytes > resident_bytes_ ? options_.gpu_budget_bytes - resident_bytes_ : 0;
    const uint64_t bytes = uploadNextView(upload, room, &full);
    if (full) {
      full_at_bytes_ = resident_bytes_;
      break;
    }
    resident_bytes_ += bytes;
    if (bytes > 0) {
      ++stats_.views_uploaded_ahead;
      ++upload.views_ahead;
    }
    if (upload.done()) {
      ++stats_.cells_uploaded_ahead;
      cells_[upload.half_edge] = std::move(upload.cell);
      order_.push_front(upload.half_edge);
      uploaded_ahead_.push_back(upload.half_edge);
      uploading_.reset();
    }
  }
  stats_.resident_bytes_max = std::max(stats_.resident_bytes_max, resident_bytes_);
  const double ms = timer.milliseconds();
  stats_.ahead_ms_total += ms;
  streaming_.addAheadMs(ms);
  return ms;
}

}  // namespace farfield::runtime
