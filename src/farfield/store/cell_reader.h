// The paged reader of an impostor database (DESIGN.md, "store": a paged reader with a byte budget): a cell's layer
// views (meshes, textures, object ids) are read and checked on a background thread before the viewer needs them, so
// that entering a cell costs the GPU upload and not the disk and the PNG decoding (on the 400-block city's drive the
// read took 166 ms per cell on average, 240 ms at worst: every cell entry broke the frame budget).
//
// The runtime asks for the cells the viewer may enter next (prefetch) and takes the current one (take). Prefetched
// cells wait in memory under a byte budget of decoded bytes that holds at every moment: before a finished read is
// kept, the oldest waiting reads are dropped until it fits, and a cell larger than the whole budget is not kept (the
// bytes of the one read in progress are counted when it finishes). A cell taken before it was prefetched, or
// dropped, is read on the calling thread. Errors of a background read (a damaged file) are raised by take(), with
// the message loadLayerView gives (file and record), never lost and never thrown on the reader thread.
//
// Thread safety: prefetch() and take() may be called from one thread (the render thread) while the reader runs; the
// index and the directory must stay unchanged while the reader lives.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "farfield/impostor/impostor_mesh.h"
#include "farfield/store/impostor_store.h"

namespace farfield::store {

// Decoded views of one cell, as the index orders them.
struct CellViews {
  uint32_t half_edge = 0;
  std::vector<std::vector<impostor::DepthMeshImpostor>> layers;  // per layer of CellPipeline::layers, per view
  std::vector<impostor::DepthMeshImpostor> single;              // the single mesh's views
  uint64_t bytes = 0;                                           // decoded bytes held (meshes, textures, ids)
  double read_ms = 0.0;                                         // wall time of the read and checks
};

// Bytes a decoded view holds in memory (positions, uvs, normals, indices, triangle ids, texture, id image).
uint64_t decodedBytes(const impostor::DepthMeshImpostor& view);

// Reads a cell's pipeline views now, on the calling thread. `layers` / `single` choose what is read (a walkthrough
// drawing the single mesh needs no layer). Throws farfield::Error naming the file and record for a damaged file, and
// the cell for a cell the index does not hold or that has no pipeline record.
CellViews readCellViews(const std::string& dir, const StoreIndex& index, uint32_t half_edge, bool layers, bool single);

class CellReader {
 public:
  struct Options {
    bool layers = true;                 // read the MMI layers' views
    bool single = false;                // read the single mesh's views
    uint64_t budget_bytes = 256u << 20; // decoded bytes of prefetched cells waiting to be taken
  };
  struct Stats {
    size_t prefetch_requests = 0;  // cells queued
    size_t read_ahead = 0;         // cells read by the background thread
    size_t taken_ready = 0;        // taken after their read had finished
    size_t taken_waited = 0;       // taken while being read (the caller waited for the rest)
    size_t taken_cold = 0;         // taken without a prefetch (read on the calling thread)
    size_t dropped = 0;            // prefetched cells dropped for the budget
    size_t too_large = 0;          // of them, cells larger than the whole budget (never kept)
    uint64_t held_bytes_max = 0;   // largest decoded bytes waiting at once
    double wait_ms_total = 0.0;    // time take() waited for a background read
  };

  CellReader(std::string dir, const StoreIndex& index, Options options);
  ~CellReader();  // stops the thread after its current read
  CellReader(const CellReader&) = delete;
  CellReader& operator=(const CellReader&) = delete;

  // Queues a cell for reading ahead; does nothing for a cell that is waiting, queued, being read, or not in the
  // index. Never blocks on the disk.
  void prefetch(uint32_t half_edge);
  // The cell's views: waiting ones at once, one being read after its read, others read now on the calling thread.
  // Throws what the read threw. *how, when given: "ready", "waited" or "cold".
  std::shared_ptr<CellViews> take(uint32_t half_edge, const char** how = nullptr);
  // Forgets queued (not yet started) prefetches: the viewer turned elsewhere.
  void cancelQueued();

  Stats stats() const;
  uint64_t heldBytes() const;

 private:
  struct Slot {
    std::shared_ptr<CellViews> views;
    std::exception_ptr error;
    bool done = false;
    uint64_t order = 0;  // when it finished, for dropping the oldest
  };
  void run();
  void makeRoom(uint64_t incoming);  // with mutex_ held

  std::string dir_;
  const StoreIndex& index_;
  Options options_;
  mutable std::mutex mutex_;
  std::condition_variable wake_, finished_;
  std::deque<uint32_t> queue_;
  std::map<uint32_t, Slot> slots_;  // queued (not in slots_), in flight (done = false) or waiting (done = true)
  uint64_t held_ = 0;
  uint64_t finished_count_ = 0;
  bool stop_ = false;
  Stats stats_;
  std::thread thread_;
};

}  // namespace farfield::store
