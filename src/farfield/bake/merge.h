// Joining the shards of a sharded bake (`farfield bake --shard K/N`, bake/shard.h) into one impostor database.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace farfield::bake {

struct MergeReport {
  size_t shards = 0;
  size_t cells = 0;
  size_t files = 0;          // data files of the merged database
  size_t linked = 0;         // of them hard-linked to the shard's file (the rest copied)
  uint64_t bytes = 0;        // bytes of the data files
  double wall_s = 0.0;
};

// Checks that `shard_dirs` are the N shards of one bake (each a database with a "shard" record: the same scene digest,
// street graph, options, pipeline, view space and N; each part 0..N-1 exactly once; each shard holding exactly the
// cells of its part, so that every cell of the view space is present once) and writes them as one whole database in
// `out_dir` (a new generation, atomically: store/impostor_store.h), each data file checked (size, CRC-32) and
// hard-linked where the file system allows, else copied. Throws farfield::Error naming the shard directory and the
// problem: not a shard, an unfinished shard (a journal and no index: resume it), a missing or repeated part, a
// missing or repeated cell, shards of different scenes or options.
MergeReport mergeShards(const std::vector<std::string>& shard_dirs, const std::string& out_dir);

}  // namespace farfield::bake
