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
    : dir_(std::move(dir)),
      index_(index),
      options_(options),
      reader_([this](uint32_t cell) { return readCellViews(dir_, index_, cell, options_.layers, options_.single); },
              [](const CellViews& views) { return views.bytes; }, options.budget_bytes) {}

void CellReader::prefetch(uint32_t half_edge) {
  const CellEntry* entry = index_.find(half_edge);
  if (entry && entry->pipeline) reader_.prefetch(half_edge);
}

}  // namespace farfield::store
