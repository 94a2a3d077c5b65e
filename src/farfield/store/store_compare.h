// Comparing two impostor databases record by record: what a merged sharded bake, a resumed bake and an
// uninterrupted single-process bake must agree on (the same cells, PVS, splits, layers, views, cameras, validity
// regions, and files of the same size and CRC-32), leaving out what may differ between runs of the same bake:
// timings, the generation number (in "generation" and in the data file names) and the index checksum.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "farfield/store/impostor_store.h"

namespace farfield::store {

// The index as records (indexToJson without timings, "generation", generation prefixes of file names, "checksum";
// `with_shard` false also drops "shard").
nlohmann::json comparableRecords(const StoreIndex& index, bool with_shard = true);
// The first place where `a` and `b` differ ("cells[3].pipeline.mmi.layers[0].views[1].mesh_crc32: 12 vs 13",
// "cells: 5 vs 6 elements"), "" when they are equal.
std::string firstDifference(const nlohmann::json& a, const nlohmann::json& b, const std::string& at = "");

}  // namespace farfield::store
