// Sharded bakes (bake/shard.h, bake/merge.h): the partition covers every cell exactly once and stays balanced for
// many N (checked by counting, against Graham's bound); a merged N-shard bake holds the same records as a
// single-process bake of the same cells; merge refuses a missing, repeated or foreign shard.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <numeric>
#include <random>
#include <set>

#include "farfield/bake/merge.h"
#include "farfield/bake/pipeline.h"
#include "farfield/bake/shard.h"
#include "farfield/core/error.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/store/impostor_store.h"
#include "farfield/store/store_compare.h"
#include "farfield/urban/cells.h"
#include "support/expect_error.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::bake {
namespace {

using test::expectErrorMentions;

TEST(ShardPartitionTest, CoversEveryCellExactlyOnceAndStaysBalancedForManyN) {
  std::mt19937 rng(1601);
  for (int trial = 0; trial < 20; ++trial) {
    const size_t n_cells = std::uniform_int_distribution<size_t>(0, 400)(rng);
    std::vector<uint32_t> cells;
    for (uint32_t id = 0; cells.size() < n_cells; ++id)
      if (rng() % 3 != 0) cells.push_back(id * 2 + 1);  // sparse ids
    std::shuffle(cells.begin(), cells.end(), rng);
    std::vector<double> weights;
    for (size_t k = 0; k < cells.size(); ++k) weights.push_back(std::uniform_real_distribution<double>(1.0, 40.0)(rng));
    const double total = std::accumulate(weights.begin(), weights.end(), 0.0);
    const double heaviest = weights.empty() ? 0.0 : *std::max_element(weights.begin(), weights.end());
    std::map<uint32_t, double> weight_of;
    for (size_t k = 0; k < cells.size(); ++k) weight_of[cells[k]] = weights[k];
    for (uint32_t n : {1u, 2u, 3u, 4u, 5u, 7u, 8u, 16u, 31u, 64u, 500u}) {
      const auto parts = partitionCells(cells, weights, n);
      ASSERT_EQ(parts.size(), n);
      std::map<uint32_t, int> seen;
      for (const auto& part : parts) {
        EXPECT_TRUE(std::is_sorted(part.begin(), part.end()));
        double load = 0.0;
        for (uint32_t c : part) {
          ++seen[c];
          load += weight_of.at(c);
        }
        EXPECT_LE(load, total / double(n) + heaviest + 1e-9) << "n = " << n;  // Graham's bound for list scheduling
      }
      ASSERT_EQ(seen.size(), cells.size()) << "n = " << n;
      for (const auto& [c, times] : seen) EXPECT_EQ(times, 1) << "cell " << c << ", n = " << n;
      // Deterministic: the same partition from the cells in another order.
      std::vector<size_t> order(cells.size());
      std::iota(order.begin(), order.end(), size_t(0));
      std::shuffle(order.begin(), order.end(), rng);
      std::vector<uint32_t> c2;
      std::vector<double> w2;
      for (size_t k : order) {
        c2.push_back(cells[k]);
        w2.push_back(weights[k]);
      }
      EXPECT_EQ(partitionCells(c2, w2, n), parts) << "n = " << n;
    }
  }
}

TEST(ShardPartitionTest, GroupedCellsShareAPartAndEveryCellIsPlacedOnce) {
  std::mt19937 rng(1606);
  std::vector<uint32_t> cells, groups;
  std::vector<double> weights;
  for (uint32_t e = 0; e < 300; ++e)
    if (rng() % 4 != 0) {
      cells.push_back(e);
      groups.push_back(e / 2);  // a street's two cells
      weights.push_back(std::uniform_real_distribution<double>(1.0, 30.0)(rng));
    }
  double total = 0.0, heaviest_unit = 0.0;
  std::map<uint32_t, double> unit_weight;
  for (size_t k = 0; k < cells.size(); ++k) unit_weight[groups[k]] += weights[k];
  for (const auto& [g, w] : unit_weight) {
    total += w;
    heaviest_unit = std::max(heaviest_unit, w);
  }
  for (uint32_t n : {1u, 2u, 3u, 8u, 13u, 64u}) {
    const auto parts = partitionCells(cells, weights, n, groups);
    std::map<uint32_t, std::set<size_t>> parts_of_group;
    std::map<uint32_t, int> seen;
    for (size_t p = 0; p < parts.size(); ++p) {
      double load = 0.0;
      for (uint32_t c : parts[p]) {
        ++seen[c];
        parts_of_group[c / 2].insert(p);
        load += weights[size_t(std::find(cells.begin(), cells.end(), c) - cells.begin())];
      }
      EXPECT_LE(load, total / double(n) + heaviest_unit + 1e-9);
    }
    EXPECT_EQ(seen.size(), cells.size());
    for (const auto& [c, times] : seen) EXPECT_EQ(times, 1);
    for (const auto& [g, in] : parts_of_group) EXPECT_EQ(in.size(), 1u) << "street " << g << ", n = " << n;
  }
  EXPECT_THROW(partitionCells({1, 2}, {1.0, 1.0}, 2, {0}), Error);
}

TEST(ShardPartitionTest, ParsesKOfNAndRejectsTheRest) {
  const ShardSpec s = parseShard("3/8");
  EXPECT_EQ(s.index, 3u);
  EXPECT_EQ(s.count, 8u);
  for (const char* bad : {"", "3", "8/8", "-1/4", "1/0", "a/4", "1/4x", "1//4", "/4"})
    expectErrorMentions([&] { parseShard(bad); }, {"--shard", "K/N"});
  EXPECT_THROW(partitionCells({1, 2}, {1.0}, 2), Error);
  EXPECT_THROW(partitionCells({1, 2}, {1.0, 1.0}, 0), Error);
}

struct ShardCity {
  gen::City city;
  std::unique_ptr<urban::CellMap> cells;
  std::vector<uint32_t> view_space;
  extract::PipelineOptions options;
};

const ShardCity& shardCity() {
  static const ShardCity* c = [] {
    auto* s = new ShardCity;
    gen::CityOptions o;
    o.blocks = 10;
    o.detail = 0;
    o.seed = 16;
    o.objects = gen::ObjectGrouping::Buildings;
    s->city = gen::generateCity(o);
    s->cells = std::make_unique<urban::CellMap>(s->city.streets, s->city.scene);
    for (uint32_t e = 0; e < s->cells->cellCount() && s->view_space.size() < 5; e += 3)
      if (!s->cells->degenerate(e)) s->view_space.push_back(e);
    s->options.base.resolution = 64;
    s->options.base.progress = false;
    s->options.pvs.spacing = 12.0f;
    s->options.pvs.face_size = 48;
    s->options.frame_width = 256;
    s->options.frame_height = 256;
    s->options.grid_cells = 12;
    s->options.station_spacing = 20.0f;
    return s;
  }();
  return *c;
}

PipelineReport bake(const std::string& dir, const BakeControl& control = {}, extract::PipelineOptions options = shardCity().options) {
  const ShardCity& c = shardCity();
  return bakePipeline(gpu::sharedHeadlessContext(), c.city.scene, *c.cells, c.view_space,
                      extract::parsePipeline("pvs,near-far,single,mmi"), options, dir, control);
}

TEST(ShardedBakeTest, MergedShardsHoldTheRecordsOfASingleProcessBakeAndMergeChecksTheParts) {
  const std::string single = test::scratchDir("shard_single").string();
  bake(single);
  const store::StoreIndex whole = store::readIndex(single);
  ASSERT_EQ(whole.cells.size(), shardCity().view_space.size());
  EXPECT_FALSE(whole.shard);

  std::vector<std::string> dirs;
  for (uint32_t k = 0; k < 3; ++k) {
    dirs.push_back(test::scratchDir("shard_" + std::to_string(k)).string());
    const PipelineReport r = bake(dirs.back(), BakeControl{ShardSpec{k, 3}, false});
    EXPECT_EQ(r.view_space, shardCity().view_space.size());
    const store::StoreIndex part = store::readIndex(dirs.back());
    ASSERT_TRUE(part.shard);
    EXPECT_EQ(part.shard->index, k);
    EXPECT_EQ(part.cells.size(), part.shard->cells.size());
  }
  const std::string merged = test::scratchDir("shard_merged").string();
  const MergeReport m = mergeShards({dirs[2], dirs[0], dirs[1]}, merged);  // any order
  EXPECT_EQ(m.cells, shardCity().view_space.size());
  const store::StoreIndex joined = store::readIndex(merged);
  EXPECT_FALSE(joined.shard);
  EXPECT_EQ(store::firstDifference(store::comparableRecords(whole), store::comparableRecords(joined)), "");
  // Every file the merged index names is there and intact (its own generation's names).
  for (const store::CellEntry& e : joined.cells)
    for (const store::StoredLayer& l : e.pipeline->layers)
      for (const store::StoredView& v : l.views) EXPECT_NO_THROW(store::loadLayerView(merged, v));

  const std::string out = test::scratchDir("shard_bad_merge").string();
  expectErrorMentions([&] { mergeShards({dirs[0], dirs[1]}, out); }, {"shard 2/3", "missing"});
  expectErrorMentions([&] { mergeShards({dirs[0], dirs[1], dirs[1]}, out); }, {dirs[1], "given twice"});
  expectErrorMentions([&] { mergeShards({dirs[0], dirs[1], dirs[2], single}, out); }, {single, "not a shard"});
  // A shard of the same part with other options, and one of another partition (N = 2).
  extract::PipelineOptions other = shardCity().options;
  other.grid_cells = 10;
  const std::string foreign = test::scratchDir("shard_foreign").string();
  bake(foreign, BakeControl{ShardSpec{2, 3}, false}, other);
  expectErrorMentions([&] { mergeShards({dirs[0], dirs[1], foreign}, out); }, {foreign, "grid_cells"});
  const std::string half = test::scratchDir("shard_half").string();
  bake(half, BakeControl{ShardSpec{1, 2}, false});
  expectErrorMentions([&] { mergeShards({dirs[0], half, dirs[2]}, out); }, {half, "a shard of 2"});
  // A shard that lost a cell of its part.
  store::StoreIndex damaged = store::readIndex(dirs[0]);
  ASSERT_FALSE(damaged.cells.empty());
  const uint32_t lost = damaged.cells.back().half_edge;
  damaged.cells.pop_back();
  const std::string short_dir = test::scratchDir("shard_short").string();
  fs::copy(dirs[0], short_dir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  store::writeIndex(short_dir, damaged);
  expectErrorMentions([&] { mergeShards({short_dir, dirs[1], dirs[2]}, out); },
                      {short_dir, "cell " + std::to_string(lost), "missing"});
  EXPECT_FALSE(fs::exists(fs::path(out) / store::kIndexFile));
}

}  // namespace
}  // namespace farfield::bake
