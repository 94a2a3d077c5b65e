// Sharded bakes: a deterministic, balanced partition of the view space (the cells a bake works on) into N parts,
// each baked by its own process into its own database and joined by `farfield merge` (bake/merge.h).
//
// Balance: a cell's work grows with its length (PVS sample points every pvs.spacing metres, capture stations every
// station_spacing metres), so each cell gets that estimate as its weight and the cells are dealt out heaviest first
// to the lightest part (Graham's LPT list scheduling: the heaviest part weighs at most total / N + the heaviest
// unit), a street's two cells together. Ties break on the cell id and the part number, so every process computes the same partition from the same
// view space without talking to the others.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "farfield/extract/pipeline_options.h"
#include "farfield/scene/scene.h"
#include "farfield/urban/cells.h"

namespace farfield::bake {

// Part `index` of `count` (0 <= index < count), as `--shard K/N` gives it.
struct ShardSpec {
  uint32_t index = 0;
  uint32_t count = 1;
};
// Parses "K/N" (0 <= K < N, N >= 1). Throws farfield::Error naming `what` for anything else.
ShardSpec parseShard(const std::string& text, const std::string& what = "--shard");

// The estimated work of each cell (same order as `cells`): 1 + PVS sample points + capture stations.
std::vector<double> cellWeights(const urban::CellMap& map, const std::vector<uint32_t>& cells,
                                const extract::PipelineOptions& options);

// Splits `cells` (distinct ids) with their `weights` into `count` parts: every cell in exactly one part, each part
// ascending, the same result for the same input in any order. Cells with the same `groups` value (one per cell;
// empty = every cell alone) go to the same part, dealt out as one unit of their summed weight: the bake groups a
// street's two cells, which share their PVS sample points (urban/pvs.h reuses their views). Throws farfield::Error
// for count 0 or a size mismatch.
std::vector<std::vector<uint32_t>> partitionCells(const std::vector<uint32_t>& cells,
                                                  const std::vector<double>& weights, uint32_t count,
                                                  const std::vector<uint32_t>& groups = {});

// A digest of the scene a shard was baked from (object names, world bounds and footprints, triangle count): shards
// of different scenes differ (merge checks it), the same scene loaded by any process gives the same value.
uint32_t sceneDigest(const scene::Scene& scene);

}  // namespace farfield::bake
