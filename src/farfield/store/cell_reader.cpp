#include "farfield/store/cell_reader.h"

#include <algorithm>
#include <utility>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"

namespace farfield::store {

uint64_t decodedBytes(const impostor::DepthMeshImpostor& view) {
  const scene::Mesh& m = view.mesh;
  uint64_t bytes = m.positions.size() * sizeof(Vec3) + m.normals.size() * sizeof(Vec3) + m.uvs.size() * sizeof(Vec2) +
                   m.indices.size() * sizeof(uint32_t) + view.triangle_ids.size() * sizeof(uint32_t);
  if (view.texture) bytes += uint64_t(view.texture->width()) * uint64_t(view.texture->height()) * 4;
  if (view.ids) bytes += uint64_t(view.ids->width()) * uint64_t(view.ids->height()) * sizeof(uint32_t);
  return bytes;
}

CellViews readCellViews(const std::string& dir, const StoreIndex& index, uint32_t half_edge, bool layers,
                        bool single) {
  const CellEntry* entry = index.find(half_edge);
  if (!entry) throw Error(dir, "cell " + std::to_string(half_edge) + " is not in the database");
  if (!entry->pipeline) throw Error(dir, "cell " + std::to_string(half_edge) + " has no pipeline record");
  Stopwatch timer;
  CellViews out;
  out.half_edge = half_edge;
  const CellPipeline& p = *entry->pipeline;
  if (layers) {
    out.layers.resize(p.layers.size());
    for (size_t l = 0; l < p.layers.size(); ++l)
      for (const StoredView& v : p.layers[l].views) {
        out.layers[l].push_back(loadLayerView(dir, v));
        out.bytes += decodedBytes(out.layers[l].back());
      }
  }
  if (single)
    for (const StoredView& v : p.single.views) {
      out.single.push_back(loadLayerView(dir, v));
      out.bytes += decodedBytes(out.single.back());
    }
  out.read_ms = timer.milliseconds();
  return out;
}

CellReader::CellReader(std::string dir, const StoreIndex& index, Options options)
    : dir_(std::move(dir)), index_(index), options_(options) {
  thread_ = std::thread([this] { run(); });
}

CellReader::~CellReader() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void CellReader::prefetch(uint32_t half_edge) {
  const CellEntry* entry = index_.find(half_edge);
  if (!entry || !entry->pipeline) return;
  {
    std::lock_guard lock(mutex_);
    if (slots_.count(half_edge) || std::find(queue_.begin(), queue_.end(), half_edge) != queue_.end()) return;
    queue_.push_back(half_edge);
    ++stats_.prefetch_requests;
  }
  wake_.notify_one();
}

void CellReader::cancelQueued() {
  std::lock_guard lock(mutex_);
  queue_.clear();
}

void CellReader::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
    if (stop_) return;
    const uint32_t cell = queue_.front();
    queue_.pop_front();
    slots_[cell];  // in flight
    lock.unlock();
    std::shared_ptr<CellViews> views;
    std::exception_ptr error;
    try {
      views = std::make_shared<CellViews>(readCellViews(dir_, index_, cell, options_.layers, options_.single));
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    ++stats_.read_ahead;
    // Room first, so that the waiting bytes stay under the budget at every moment: older reads are dropped, and a
    // cell larger than the whole budget is not kept (take() reads it again).
    const uint64_t bytes = views ? views->bytes : 0;
    if (bytes > options_.budget_bytes) {
      slots_.erase(cell);
      ++stats_.dropped;
      ++stats_.too_large;
      finished_.notify_all();
      continue;
    }
    makeRoom(bytes);
    Slot& slot = slots_[cell];
    slot.views = std::move(views);
    slot.error = error;
    slot.done = true;
    slot.order = ++finished_count_;
    held_ += bytes;
    stats_.held_bytes_max = std::max(stats_.held_bytes_max, held_);
    finished_.notify_all();
  }
}

// Drops the oldest finished reads until `incoming` more bytes fit the budget (a failed read holds no bytes and stays,
// so that take() can report it).
void CellReader::makeRoom(uint64_t incoming) {
  while (held_ + incoming > options_.budget_bytes) {
    auto oldest = slots_.end();
    for (auto it = slots_.begin(); it != slots_.end(); ++it)
      if (it->second.done && it->second.views && (oldest == slots_.end() || it->second.order < oldest->second.order))
        oldest = it;
    if (oldest == slots_.end()) return;
    held_ -= oldest->second.views->bytes;
    slots_.erase(oldest);
    ++stats_.dropped;
  }
}

std::shared_ptr<CellViews> CellReader::take(uint32_t half_edge, const char** how) {
  std::unique_lock lock(mutex_);
  auto it = slots_.find(half_edge);
  if (it != slots_.end()) {
    const char* kind = "ready";
    if (!it->second.done) {
      kind = "waited";
      Stopwatch wait;
      finished_.wait(lock, [&] { return slots_.count(half_edge) == 0 || slots_[half_edge].done; });
      stats_.wait_ms_total += wait.milliseconds();
      it = slots_.find(half_edge);
    }
    if (it != slots_.end()) {
      Slot slot = std::move(it->second);
      slots_.erase(it);
      if (slot.views) held_ -= slot.views->bytes;
      ++(kind[0] == 'r' ? stats_.taken_ready : stats_.taken_waited);
      if (how) *how = kind;
      if (slot.error) std::rethrow_exception(slot.error);
      return slot.views;
    }
    // Finished and dropped for the budget while we waited: read it again below.
  }
  queue_.erase(std::remove(queue_.begin(), queue_.end(), half_edge), queue_.end());
  ++stats_.taken_cold;
  lock.unlock();
  if (how) *how = "cold";
  return std::make_shared<CellViews>(readCellViews(dir_, index_, half_edge, options_.layers, options_.single));
}

CellReader::Stats CellReader::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

uint64_t CellReader::heldBytes() const {
  std::lock_guard lock(mutex_);
  return held_;
}

}  // namespace farfield::store
