// What an impostor database offers the viewer: the modes it can draw (full and culled always; a pipeline store from
// `farfield bake --pipeline` the representations its stages support, by the rules runtime::Walkthrough checks; a
// placement database from `farfield place` the placed mode, and governed: placed under the frame governor, which keeps
// the viewer's t_max by coarsening frames and says which bound each kept), and what the street map draws (the store's
// street graph, the placement's conservative problem views).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "farfield/store/placement_store.h"

namespace farfield::view {

enum class DatabaseKind { None, Pipeline, Placement };

struct DatabaseModes {
  DatabaseKind kind = DatabaseKind::None;
  std::vector<std::string> modes;  // "full", "culled", then the database's representations (best last; governed after
                                   // placed)
  std::string streets_file;        // Pipeline: the store's street graph file
  std::shared_ptr<const store::PlacementIndex> placement;  // Placement: the index (CPV regions for the map)
};

// dir "" = no database. Reads and checks the index (store::readIndex, store::readPlacementIndex). Throws
// farfield::Error naming the directory or the file: a missing directory, one holding neither index, a damaged
// index, a store without pipeline data.
DatabaseModes databaseModes(const std::string& dir);

// The mode a viewer opens with: the database's best representation (mmi, placed: governed relaxes the bound, so it
// is chosen, not the default), else full.
std::string defaultMode(const DatabaseModes& modes);

}  // namespace farfield::view
