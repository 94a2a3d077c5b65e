// The paged reader of an impostor database (DESIGN.md, "store": a paged reader with a byte budget): a cell's layer
// views (meshes, textures, object ids) are read and checked on a background thread before the viewer needs them, so
// that entering a cell costs the GPU upload and not the disk and the PNG decoding (on the 400-block city's drive the
// read took 166 ms per cell on average, 240 ms at worst: every cell entry broke the frame budget).
//
// The runtime asks for the cells the viewer may enter next (prefetch) and takes the current one (take); the reading
// ahead, its byte budget of decoded bytes and its errors are store::BackgroundReader's (background_reader.h). The index
// and the directory must stay unchanged while the reader lives.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "farfield/impostor/impostor_mesh.h"
#include "farfield/store/background_reader.h"
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
  using Stats = BackgroundReaderStats;

  CellReader(std::string dir, const StoreIndex& index, Options options);

  // Queues a cell for reading ahead; does nothing for a cell that is waiting, queued, being read, or not in the
  // index. Never blocks on the disk.
  void prefetch(uint32_t half_edge);
  // The cell's views: waiting ones at once, one being read after its read, others read now on the calling thread.
  // Throws what the read threw. *how, when given: "ready", "waited" or "cold".
  std::shared_ptr<CellViews> take(uint32_t half_edge, const char** how = nullptr) {
    return reader_.take(half_edge, how);
  }
  // The cell's views if their background read has finished, else null: never waits and never reads.
  std::shared_ptr<CellViews> takeIfReady(uint32_t half_edge) { return reader_.takeIfReady(half_edge); }
  // Forgets queued (not yet started) prefetches: the viewer turned elsewhere.
  void cancelQueued() { reader_.cancelQueued(); }

  Stats stats() const { return reader_.stats(); }
  uint64_t heldBytes() const { return reader_.heldBytes(); }

 private:
  std::string dir_;
  const StoreIndex& index_;
  Options options_;
  BackgroundReader<CellViews> reader_;  // last: its thread reads with the members above
};

}  // namespace farfield::store
