// Prefetch in the direction of motion (runtime/prefetch.h, Sillion et al. 1997, section 5.1): on a hand-made
// junction the cells are ranked by their agreement with the motion, computed here from the junction positions; and
// a walkthrough along a straight street chain of a baked city, prefetching one cell only, finds every cell it enters
// after the first already read ("ready": loaded before the viewer entered it), while without read-ahead every entry
// stalls (the test can fail both ways); under a memory budget that holds one cell and not three, the resident
// impostors and the cells read ahead stay within it at every frame while each entry evicts. With the time a host
// spares after each frame given to Walkthrough::loadAhead, every cell after the first is entered uploaded (the frame
// loads nothing) and the frames draw what they drew without it; with no time to spare for a view, nothing is uploaded
// ahead; with a GPU budget a byte short of the first two cells, the second is entered partly uploaded, and the budget
// holds at every frame.
#include "farfield/runtime/prefetch.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <cmath>
#include <set>
#include <thread>

#include "farfield/bake/pipeline.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/runtime/walkthrough.h"
#include "support/test_support.h"

namespace farfield::runtime {
namespace {

// A junction J1 at (100, 0) with streets to the west (J0), east (J2), north (J3) and south (J4).
struct Cross {
  urban::StreetGraph graph = urban::StreetGraph::build({{0, 0}, {100, 0}, {200, 0}, {100, 100}, {100, -100}},
                                                       {{0, 1}, {1, 2}, {1, 3}, {1, 4}});
  // The half-edge from junction a to b.
  uint32_t edge(uint32_t a, uint32_t b) const {
    for (uint32_t e : graph.outgoing(a))
      if (graph.destination(e) == b) return e;
    ADD_FAILURE() << "no street " << a << " -> " << b;
    return 0;
  }
};

TEST(PrefetchTest, CellsAreRankedByTheirAgreementWithTheMotion) {
  const Cross x;
  const uint32_t east = x.edge(0, 1);
  // Along the cell (east): the junction ahead is J1; straight on first, the way back last.
  PrefetchChoice c = prefetchCells(x.graph, east, Vec2(1.0f, 0.0f), 0);
  EXPECT_EQ(c.exit_junction, 1u);
  ASSERT_EQ(c.cells.size(), 7u);  // every cell touching J1 but this one
  EXPECT_EQ(c.cells[0], x.edge(1, 2));
  EXPECT_EQ(std::set<uint32_t>(c.cells.begin() + 5, c.cells.end()), (std::set<uint32_t>{x.edge(1, 0), x.edge(2, 1)}));
  // Veering north: north before south. The motion's ranking against a brute-force one from the positions: the
  // streets leaving J1 and those towards it.
  const Vec2 motion(1.0f, 0.6f);
  c = prefetchCells(x.graph, east, motion, 0);
  std::vector<std::pair<float, uint32_t>> expected;
  for (uint32_t j : {0u, 2u, 3u, 4u}) {
    const Vec2 d = glm::normalize(x.graph.position(j) - x.graph.position(1));
    expected.emplace_back(-glm::dot(d, glm::normalize(motion)), x.edge(1, j));
    if (j != 0) expected.emplace_back(glm::dot(d, glm::normalize(motion)), x.edge(j, 1));
  }
  std::sort(expected.begin(), expected.end());
  ASSERT_EQ(c.cells.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) EXPECT_EQ(c.cells[k], expected[k].second) << k;
  EXPECT_EQ(c.cells[1], x.edge(1, 3));  // turning north
  EXPECT_EQ(c.cells[2], x.edge(4, 1));  // northbound, towards J1: where a turning viewer is found for a few frames
  // At most two.
  EXPECT_EQ(prefetchCells(x.graph, east, motion, 2).cells.size(), 2u);
  // Backwards (west) in the eastbound cell: the junction behind, whose only street is this one: its twin.
  c = prefetchCells(x.graph, east, Vec2(-1.0f, 0.0f), 0);
  EXPECT_EQ(c.exit_junction, 0u);
  EXPECT_EQ(c.cells, std::vector<uint32_t>{x.edge(1, 0)});
  // Standing still: as if moving along the cell.
  EXPECT_EQ(prefetchCells(x.graph, east, Vec2(0.0f), 1).cells, std::vector<uint32_t>{x.edge(1, 2)});
}

// A chain of cells going as straight as the street graph allows from `start`: each the best-aligned street leaving
// the previous one's end.
std::vector<uint32_t> straightChain(const urban::StreetGraph& g, uint32_t start, size_t length) {
  std::vector<uint32_t> chain{start};
  while (chain.size() < length) {
    const uint32_t e = chain.back();
    uint32_t best = urban::kNone;
    float best_dot = 0.9f;  // at most about 25 degrees off
    for (uint32_t n : g.outgoing(g.destination(e)))
      if (n != urban::StreetGraph::twin(e) && glm::dot(g.direction(n), g.direction(e)) > best_dot) {
        best_dot = glm::dot(g.direction(n), g.direction(e));
        best = n;
      }
    if (best == urban::kNone) break;
    chain.push_back(best);
  }
  return chain;
}

TEST(PrefetchWalkTest, OnAStraightPathTheNextCellIsLoadedBeforeTheViewerEntersIt) {
  gpu::sharedHeadlessContext();
  gen::CityOptions o;
  o.blocks = 16;
  o.detail = 0;
  o.seed = 19;
  const gen::City city = gen::generateCity(o);
  const urban::CellMap cells(city.streets, city.scene);
  const urban::StreetGraph& g = city.streets;
  std::vector<uint32_t> chain;
  for (uint32_t e = 0; e < g.halfEdgeCount() && chain.size() < 3; ++e) {
    std::vector<uint32_t> c = straightChain(g, e, 3);
    bool usable = c.size() == 3;
    for (uint32_t id : c) usable = usable && !cells.degenerate(id) && g.length(id) > 20.0f;
    if (usable) chain = c;
  }
  ASSERT_EQ(chain.size(), 3u) << "no straight chain of three cells in this city";
  // The camera along the chain's centrelines at eye height, looking ahead, 2 m apart.
  gen::CameraPath path;
  for (uint32_t e : chain) {
    const Vec2 a = g.originPosition(e), b = g.destinationPosition(e);
    const int steps = int(glm::length(b - a) / 2.0f);
    for (int s = 1; s < steps; ++s) {
      const Vec2 p = a + (b - a) * (float(s) / float(steps));
      gen::PathFrame f;
      f.eye = Vec3(p, 1.7f);
      f.at = f.eye + Vec3(g.direction(e), 0.0f);
      path.frames.push_back(f);
    }
  }
  extract::PipelineOptions options;
  options.base.resolution = 64;
  options.base.progress = false;
  options.pvs.spacing = 15.0f;
  options.pvs.face_size = 32;
  options.grid_cells = 10;
  options.station_spacing = 0.0f;
  const std::string store = test::scratchDir("prefetch_store").string();
  bake::bakePipeline(gpu::sharedHeadlessContext(), city.scene, cells, chain,
                     extract::parsePipeline("pvs,near-far,mmi"), options, store);

  const gpu::GpuScene gpu_scene(city.scene);
  const scene::Bvh bvh(city.scene);
  gpu::Renderer renderer;
  std::vector<uint64_t> resident_at_entry;  // with read-ahead and a budget that never binds
  for (const bool read_ahead : {true, false}) {
    WalkthroughOptions w;
    w.database = store;
    w.read_ahead = read_ahead;
    w.prefetch_cells = 1;  // the straight continuation only: the direction of motion must pick it
    w.memory_budget_bytes = uint64_t(64) << 20;
    Walkthrough walkthrough(city.scene, gpu_scene, bvh, renderer, w);
    std::vector<std::string> entries;
    std::vector<uint32_t> entered;
    for (size_t f = 0; f < path.frames.size(); ++f) {
      const FramePlan& plan = walkthrough.plan(path.camera(f, 64, 36));
      if (plan.report.loaded) {
        entries.push_back(plan.report.read);
        entered.push_back(plan.report.cell);
        if (read_ahead) resident_at_entry.push_back(plan.report.resident_bytes);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));  // a frame's time: the reader thread runs
    }
    ASSERT_EQ(entered, chain) << "the path should enter the chain's cells in order";
    const auto stats = walkthrough.statistics();
    if (read_ahead) {
      EXPECT_EQ(entries, (std::vector<std::string>{"cold", "ready", "ready"}));
      EXPECT_EQ(stats.at("stall_frames"), 1.0);  // the first cell only
    } else {
      EXPECT_EQ(entries, (std::vector<std::string>{"cold", "cold", "cold"}));
      EXPECT_EQ(stats.at("stall_frames"), 3.0);
    }
    EXPECT_EQ(stats.at("frames_over_memory_budget"), 0.0);
  }

  // A budget that binds: its GPU share (3/4) holds the largest cell and a tenth more, not the three cells, so each
  // entry evicts. At no frame may the resident impostors and the cells read ahead exceed it, and every cell must
  // still be entered in order.
  ASSERT_EQ(resident_at_entry.size(), 3u);
  std::vector<uint64_t> cell_bytes{resident_at_entry[0]};
  for (size_t k = 1; k < 3; ++k) cell_bytes.push_back(resident_at_entry[k] - resident_at_entry[k - 1]);
  const uint64_t largest = *std::max_element(cell_bytes.begin(), cell_bytes.end());
  const uint64_t budget = largest * 4 / 3 * 11 / 10;
  ASSERT_GT(resident_at_entry[2], budget * 3 / 4) << "the three cells fit the GPU share: the budget would not bind";
  WalkthroughOptions w;
  w.database = store;
  w.prefetch_cells = 1;
  w.memory_budget_bytes = budget;
  Walkthrough walkthrough(city.scene, gpu_scene, bvh, renderer, w);
  std::vector<uint32_t> entered;
  uint64_t held_max = 0;
  for (size_t f = 0; f < path.frames.size(); ++f) {
    const FramePlan& plan = walkthrough.plan(path.camera(f, 64, 36));
    if (plan.report.loaded) entered.push_back(plan.report.cell);
    const uint64_t held = plan.report.resident_bytes + plan.report.read_ahead_bytes;
    EXPECT_LE(held, budget) << "frame " << f;
    EXPECT_FALSE(plan.report.over_gpu_budget) << "frame " << f;
    held_max = std::max(held_max, held);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_EQ(entered, chain);
  EXPECT_GE(held_max, largest);  // the largest cell was resident
  EXPECT_EQ(walkthrough.statistics().at("frames_over_memory_budget"), 0.0);

  // Uploads ahead, in the time a host spares after each frame.
  struct Walked {
    std::vector<std::string> entries;
    std::vector<double> entry_load_ms;
    std::vector<uint64_t> impostor_triangles;  // per frame
    std::vector<size_t> items;                 // per frame
    std::map<std::string, double> stats;
    uint64_t resident_max = 0;
  };
  const auto walk = [&](double spare_ms, uint64_t gpu_budget) {
    WalkthroughOptions o;
    o.database = store;
    o.prefetch_cells = 1;
    o.gpu_budget_bytes = gpu_budget;
    Walkthrough walker(city.scene, gpu_scene, bvh, renderer, o);
    Walked out;
    for (size_t f = 0; f < path.frames.size(); ++f) {
      const Camera camera = path.camera(f, 64, 36);
      const FramePlan& plan = walker.plan(camera);
      if (plan.report.loaded) {
        out.entries.push_back(plan.report.read);
        out.entry_load_ms.push_back(plan.report.load_ms);
      }
      out.impostor_triangles.push_back(plan.report.impostor_triangles);
      out.items.push_back(plan.items.size());
      out.resident_max = std::max(out.resident_max, plan.report.resident_bytes);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      if (spare_ms > 0.0) walker.loadAhead(camera, spare_ms);
    }
    out.stats = walker.statistics();
    return out;
  };
  const uint64_t unbound = uint64_t(1) << 40;
  const Walked in_frame = walk(0.0, unbound);
  const Walked ahead = walk(1000.0, unbound);
  EXPECT_EQ(in_frame.entries, (std::vector<std::string>{"cold", "ready", "ready"}));
  EXPECT_EQ(ahead.entries, (std::vector<std::string>{"cold", "uploaded", "uploaded"}));
  ASSERT_EQ(ahead.entry_load_ms.size(), 3u);
  EXPECT_EQ(ahead.entry_load_ms[1], 0.0);
  EXPECT_EQ(ahead.entry_load_ms[2], 0.0);
  EXPECT_GT(in_frame.entry_load_ms[1] + in_frame.entry_load_ms[2], 0.0);
  EXPECT_EQ(ahead.stats.at("cells_uploaded_ahead"), 2.0);
  EXPECT_EQ(ahead.stats.at("cell_loads"), 1.0);  // in a frame: the first cell only
  EXPECT_GT(ahead.stats.at("views_uploaded_ahead"), 0.0);
  EXPECT_EQ(ahead.impostor_triangles, in_frame.impostor_triangles);  // the same impostors drawn in every frame
  EXPECT_EQ(ahead.items, in_frame.items);
  const Walked little = walk(1e-9, unbound);  // the upload rate is known from the first cell's: nothing fits
  EXPECT_EQ(little.entries, in_frame.entries);
  EXPECT_EQ(little.stats.at("views_uploaded_ahead"), 0.0);
  const uint64_t half = cell_bytes[0] + cell_bytes[1] - 1;  // not both cells: the second's last view waits
  const Walked partly = walk(1000.0, half);
  ASSERT_EQ(partly.entries.size(), 3u);
  EXPECT_EQ(partly.entries[1], "partly");
  EXPECT_GT(partly.stats.at("views_uploaded_ahead"), 0.0);
  EXPECT_LE(partly.stats.at("resident_bytes_max"), double(std::max(half, largest)));
  EXPECT_LE(partly.resident_max, std::max(half, largest));
  EXPECT_EQ(partly.impostor_triangles, in_frame.impostor_triangles);
}

}  // namespace
}  // namespace farfield::runtime
