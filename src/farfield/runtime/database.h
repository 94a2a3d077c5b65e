// Opening an impostor database for a walkthrough: its index (store/impostor_store.h, checked), street graph and cell
// locator, checked against the scene it is drawn with.
#pragma once

#include <string>

#include "farfield/scene/scene.h"
#include "farfield/store/impostor_store.h"
#include "farfield/urban/cells.h"
#include "farfield/urban/street_graph.h"

namespace farfield::runtime {

// An impostor store opened for a walkthrough: its index, street graph and cell locator. Checks that the store was
// baked for a scene with as many objects as `scene` and that its cells are half-edges of its graph; lookup_option
// ("" = the store's rule, else street or nearest) picks the cell lookup. Throws farfield::Error naming the file.
struct OpenStore {
  store::StoreIndex index;
  std::string index_file;
  urban::StreetGraph graph;
  urban::CellLocator locator;
};
OpenStore openStore(const std::string& dir, const scene::Scene& scene, const std::string& lookup_option);

}  // namespace farfield::runtime
