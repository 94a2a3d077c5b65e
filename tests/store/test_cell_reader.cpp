// The paged reader (store/cell_reader.h): cells read ahead on the background thread equal the cells read on the
// calling thread; a cell taken without a prefetch is read at once; the waiting bytes never exceed the budget (the
// oldest read is dropped and read again when taken), also under random prefetches and takes of cells of random
// sizes, some larger than the budget; a damaged file read ahead is reported by take(), naming the file.
#include "farfield/store/cell_reader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <chrono>
#include <random>
#include <thread>

#include "farfield/core/error.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

impostor::DepthMeshImpostor randomView(int size, uint32_t seed) {
  impostor::DepthMeshImpostor imp;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-50.0f, 50.0f), t(0.0f, 1.0f);
  for (int k = 0; k < 12; ++k) {
    imp.mesh.positions.emplace_back(u(rng), u(rng), u(rng));
    imp.mesh.uvs.emplace_back(t(rng), t(rng));
  }
  imp.mesh.indices = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
  imp.triangle_ids = {seed, seed + 1, seed + 2, seed + 3};
  auto texture = std::make_shared<image::ColorImage>(size, size, image::Rgba8(uint8_t(seed), 20, 30, 255));
  imp.texture = texture;
  auto ids = std::make_shared<image::IdImage>(size, size, seed);
  imp.ids = ids;
  imp.camera.width = imp.camera.height = size;
  imp.camera.eye = Vec3(float(seed), 0.0f, 1.7f);
  imp.camera.at = Vec3(float(seed), 10.0f, 1.7f);
  return imp;
}

// A database of `cells` cells, each with two layers of two views and a single mesh of one view, 16 x 16 texels.
StoreIndex writeDatabase(const std::string& dir, uint32_t cells) {
  StoreIndex index;
  for (uint32_t c = 0; c < cells; ++c) {
    CellEntry entry;
    entry.half_edge = c * 2;
    CellPipeline p;
    p.has_mmi = true;
    for (size_t l = 0; l < 2; ++l) {
      StoredLayer layer;
      for (size_t v = 0; v < 2; ++v)
        layer.views.push_back(writeLayerView(dir, layerFileStem(entry.half_edge, "mmi", l, v),
                                             randomView(16, c * 100 + uint32_t(l * 10 + v))));
      p.layers.push_back(layer);
    }
    p.single.views.push_back(writeLayerView(dir, layerFileStem(entry.half_edge, "smi", 0, 0), randomView(16, c * 100 + 99)));
    entry.pipeline = p;
    index.cells.push_back(entry);
  }
  return index;
}

// A take() of a cell still queued reads it on the calling thread: wait for the background reads to be deterministic.
void waitForReads(const CellReader& reader, size_t n) {
  for (int i = 0; i < 5000 && reader.stats().read_ahead < n; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ASSERT_EQ(reader.stats().read_ahead, n);
}

void expectSameViews(const CellViews& a, const CellViews& b) {
  EXPECT_EQ(a.half_edge, b.half_edge);
  EXPECT_EQ(a.bytes, b.bytes);
  ASSERT_EQ(a.layers.size(), b.layers.size());
  for (size_t l = 0; l < a.layers.size(); ++l) {
    ASSERT_EQ(a.layers[l].size(), b.layers[l].size());
    for (size_t v = 0; v < a.layers[l].size(); ++v) {
      EXPECT_EQ(a.layers[l][v].mesh.positions, b.layers[l][v].mesh.positions);
      EXPECT_EQ(a.layers[l][v].texture->pixels(), b.layers[l][v].texture->pixels());
      EXPECT_EQ(a.layers[l][v].ids->pixels(), b.layers[l][v].ids->pixels());
    }
  }
  EXPECT_EQ(a.single.size(), b.single.size());
}

TEST(CellReaderTest, DecodedBytesByHand) {
  const impostor::DepthMeshImpostor v = randomView(16, 3);
  // 12 positions (12 B) + 12 uvs (8 B) + 12 indices (4 B) + 4 triangle ids (4 B) + 16 x 16 texels x (4 + 4) B.
  EXPECT_EQ(decodedBytes(v), uint64_t(12 * 12 + 12 * 8 + 12 * 4 + 4 * 4 + 256 * 8));
  EXPECT_EQ(decodedBytes(impostor::DepthMeshImpostor{}), 0u);
}

TEST(CellReaderTest, ReadAheadEqualsReadNow) {
  const std::string dir = test::scratchDir("cell_reader_same").string();
  const StoreIndex index = writeDatabase(dir, 3);
  CellReader reader(dir, index, {});
  reader.prefetch(0);
  reader.prefetch(2);
  reader.prefetch(77);  // not in the database: ignored
  waitForReads(reader, 2);
  const char* how = nullptr;
  const std::shared_ptr<CellViews> first = reader.take(0, &how);
  EXPECT_EQ(std::string(how), "ready");
  expectSameViews(*first, readCellViews(dir, index, 0, true, false));
  EXPECT_TRUE(first->single.empty());  // layers only, as asked
  reader.take(2, &how);
  EXPECT_EQ(std::string(how), "ready");
  reader.take(4, &how);  // never prefetched
  EXPECT_EQ(std::string(how), "cold");
  const CellReader::Stats s = reader.stats();
  EXPECT_EQ(s.prefetch_requests, 2u);
  EXPECT_EQ(s.taken_cold, 1u);
  EXPECT_EQ(s.taken_ready, 2u);
  EXPECT_EQ(reader.heldBytes(), 0u);
  EXPECT_THROW(reader.take(77), Error);
}

TEST(CellReaderTest, WaitingBytesStayUnderTheBudget) {
  const std::string dir = test::scratchDir("cell_reader_budget").string();
  const StoreIndex index = writeDatabase(dir, 4);
  const uint64_t cell_bytes = readCellViews(dir, index, 0, true, true).bytes;
  CellReader::Options options;
  options.single = true;
  options.budget_bytes = cell_bytes * 3 / 2;  // room for one cell
  CellReader reader(dir, index, options);
  for (uint32_t c = 0; c < 4; ++c) reader.prefetch(c * 2);
  waitForReads(reader, 4);
  const CellReader::Stats s = reader.stats();
  ASSERT_EQ(s.read_ahead, 4u);
  EXPECT_EQ(s.dropped, 3u);
  EXPECT_LE(s.held_bytes_max, options.budget_bytes);  // room is made before a read is kept
  EXPECT_LE(reader.heldBytes(), options.budget_bytes);
  const char* how = nullptr;
  expectSameViews(*reader.take(6, &how), readCellViews(dir, index, 6, true, true));  // the newest stayed
  EXPECT_EQ(std::string(how), "ready");
  expectSameViews(*reader.take(0, &how), readCellViews(dir, index, 0, true, true));  // dropped: read again
  EXPECT_EQ(std::string(how), "cold");
}

TEST(CellReaderTest, TheBudgetHoldsAtEveryMomentUnderRandomPrefetchesAndTakes) {
  const std::string dir = test::scratchDir("cell_reader_random_budget").string();
  // Cells of 1 to 6 views of 8 to 48 texels: sizes spread over a factor of about 200.
  StoreIndex index;
  std::mt19937 rng(1604);
  for (uint32_t c = 0; c < 14; ++c) {
    CellEntry entry;
    entry.half_edge = c;
    CellPipeline p;
    p.has_mmi = true;
    StoredLayer layer;
    const int views = 1 + int(rng() % 6), size = 8 + 8 * int(rng() % 6);
    for (int v = 0; v < views; ++v)
      layer.views.push_back(writeLayerView(dir, layerFileStem(c, "mmi", 0, size_t(v)), randomView(size, c * 10 + uint32_t(v))));
    p.layers.push_back(layer);
    entry.pipeline = p;
    index.cells.push_back(entry);
  }
  std::vector<uint64_t> bytes;
  for (uint32_t c = 0; c < 14; ++c) bytes.push_back(readCellViews(dir, index, c, true, false).bytes);
  const uint64_t largest = *std::max_element(bytes.begin(), bytes.end());
  for (const double share : {0.3, 0.8, 1.5, 3.0}) {
    CellReader::Options options;
    options.budget_bytes = uint64_t(double(largest) * share);
    CellReader reader(dir, index, options);
    uint64_t watched_max = 0;
    for (int step = 0; step < 60; ++step) {
      const uint32_t c = uint32_t(rng() % 14);
      if (rng() % 3 == 0) {
        const auto views = reader.take(c);
        EXPECT_EQ(views->bytes, bytes[c]);
        EXPECT_EQ(views->half_edge, c);
      } else {
        reader.prefetch(c);
      }
      watched_max = std::max(watched_max, reader.heldBytes());
      if (step % 10 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(3));
    }
    for (int i = 0; i < 200 && reader.stats().read_ahead < reader.stats().prefetch_requests; ++i) {
      watched_max = std::max(watched_max, reader.heldBytes());
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    const CellReader::Stats s = reader.stats();
    EXPECT_LE(s.held_bytes_max, options.budget_bytes) << "budget " << share << " x the largest cell";
    EXPECT_LE(watched_max, options.budget_bytes);
    if (share < 1.0) {
      EXPECT_GT(s.too_large, 0u);
    }
  }
}

TEST(CellReaderTest, DamagedFileReadAheadIsReportedByTake) {
  const std::string dir = test::scratchDir("cell_reader_damage").string();
  const StoreIndex index = writeDatabase(dir, 2);
  const std::string texture = (fs::path(dir) / index.cells[1].pipeline->layers[1].views[0].texture).string();
  {
    std::fstream f(texture, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(40);
    f.put(char(0x5a));
  }
  CellReader reader(dir, index, {});
  reader.prefetch(2);
  try {
    reader.take(2);
    ADD_FAILURE() << "a damaged texture must be an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(texture), std::string::npos) << e.what();
  }
  // The reader still works for the other cell.
  EXPECT_EQ(reader.take(0)->layers.size(), 2u);
}

}  // namespace
}  // namespace farfield::store
