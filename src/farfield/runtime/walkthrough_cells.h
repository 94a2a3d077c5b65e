// The cell walkthrough's loaded state (a cell's geometry and layers), shared by walkthrough.cpp (which owns it),
// walkthrough_cell_loads.cpp (which makes it resident) and walkthrough_dynamic.cpp (section 5.5's dynamic
// impostors). Internal to the runtime module.
#pragma once

#include <cstdint>
#include <memory>
#include <variant>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/extract/pipeline_runner.h"
#include "farfield/impostor/drawable.h"
#include "farfield/impostor/validity.h"
#include "farfield/runtime/dynamic_impostor.h"
#include "farfield/runtime/walkthrough.h"

namespace farfield::runtime {

// The cell layer a decision is about (the Placed alternatives have none and never reach the cell code).
inline uint32_t layerOf(const LayerDecision& decision) {
  return std::visit([](const auto& d) -> uint32_t {
    if constexpr (requires { d.layer; }) return d.layer;
    else return 0;
  }, decision);
}

struct Walkthrough::Layer {
  std::vector<uint32_t> objects;
  Box3 bounds;                                        // world bounds of its objects
  std::vector<std::unique_ptr<impostor::GpuImpostor>> views;
  std::vector<Vec3> view_eyes;                        // creation eyes of the views
  std::vector<uint32_t> view_station;                 // capture station of each view
  std::vector<impostor::ValidityRegion> validity;     // per station (none in version 2 databases)
  std::unique_ptr<DynamicImpostor> dynamic;
};

struct Walkthrough::Cell {
  std::vector<uint8_t> geometry_mask;  // per object id: always drawn as geometry with this cell
  std::vector<uint32_t> geometry;      // the same objects, ascending (a GPU-driven frame's list)
  std::vector<Layer> layers;           // MMI layers, or the single mesh as one layer (Smi)
  bool online = false;                 // stages run at load time
  uint64_t gpu_bytes = 0;              // of its impostors
};

// A cell being made resident: its layers are made at once (objects, bounds, validity), their views uploaded one at a
// time, all of them in the frame that enters the cell, or ahead of it in the time a host spares
// (Walkthrough::loadAhead), the rest in the frame that enters it.
struct Walkthrough::CellUpload {
  uint32_t half_edge = 0;
  std::unique_ptr<Cell> cell;
  const store::CellPipeline* record = nullptr;      // the index's record, or work.result (online)
  std::shared_ptr<store::CellViews> read;          // the decoded views (a stored cell)
  extract::CellWork work;                          // or the online stages' views
  bool single = false;                             // Smi: the single mesh as the one layer
  size_t layer = 0, view = 0;                      // the next view to upload
  size_t views_ahead = 0;                          // uploaded by Walkthrough::loadAhead
  size_t layerCount() const { return single ? 1 : record->layers.size(); }
  const store::StoredLayer& stored(size_t l) const { return single ? record->single : record->layers[l]; }
  bool done() const { return layer >= layerCount(); }
  impostor::DepthMeshImpostor& viewAt(size_t l, size_t v) {
    if (cell->online) return single ? work.single_views[v] : work.layer_views[l][v];
    return single ? read->single[v] : read->layers[l][v];
  }
  // The next view to upload that is not empty, null when none is left.
  impostor::DepthMeshImpostor* next() {
    for (size_t l = layer, v = view; l < layerCount(); ++l, v = 0)
      for (; v < stored(l).views.size(); ++v)
        if (!viewAt(l, v).empty()) return &viewAt(l, v);
    return nullptr;
  }
};

}  // namespace farfield::runtime
