// The cell walkthrough's loaded state (a cell's geometry and layers), shared by walkthrough.cpp (which owns it) and
// walkthrough_dynamic.cpp (section 5.5's dynamic impostors). Internal to the runtime module.
#pragma once

#include <cstdint>
#include <memory>
#include <variant>
#include <vector>

#include "farfield/core/bounds.h"
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

}  // namespace farfield::runtime
