#include "farfield/eval/envmap_baseline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "farfield/bake/place.h"
#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "support/small_placement.h"
#include "support/test_support.h"

namespace farfield::eval {
namespace {

struct Fixture {
  gen::City city = test::smallPlacementCity();
  gpu::CostProfile profile = test::handProfile();
  bake::PlaceOptions place = test::smallPlaceOptions(city.scene);
  store::PlacementIndex index;
  ErrorBound bound;
  Lens lens;
  Fixture() {
    const std::string dir = test::scratchDir("envmap_baseline").string() + "/placed";
    bake::placeImpostors(gpu::sharedHeadlessContext(), city.scene, profile, place, dir);
    index = store::readPlacementIndex(dir);
    bound = ErrorBound{place.error_px, place.width, place.height, degToRad(double(place.fov_deg))};
    lens.fov_y = float(degToRad(double(place.fov_deg)));
    lens.aspect = 1.0f;
    lens.near_plane = place.near_plane;
    lens.far_plane = place.far_plane;
  }
  EnvMapBaselineReport run(const EnvMapBaselineOptions& o) const {
    return runEnvMapBaseline(gpu::sharedHeadlessContext(), city.scene, profile, index, bound, lens, place.t_max_ms, o);
  }
  double radius() const {
    for (const store::StoredViewSpaceNode& n : index.nodes)
      if (n.children[0] == -1 && n.cpv_count > 0) return 0.5 * double(glm::length(n.box.extent()));
    return 0.0;
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

EnvMapBaselineOptions quiet(std::vector<double> distances) {
  EnvMapBaselineOptions o;
  o.far_distances = std::move(distances);
  o.progress = false;
  o.envmap.texel_pixels = 2.0;
  o.envmap.max_texture_size = 128;
  return o;
}

TEST(EnvMapBaseline, EachProblemCellTakesTheLargestDistanceThatKeepsTmax) {
  const Fixture& f = fixture();
  size_t problem = 0;
  for (const store::StoredViewSpaceNode& n : f.index.nodes) problem += n.children[0] == -1 && n.cpv_count > 0;
  ASSERT_GT(problem, 0u) << "the small placement must have problem cells";
  const double r = f.radius();
  const std::vector<double> distances = {1.2 * r, 2.0 * r, 4.0 * r, 8.0 * r};
  const EnvMapBaselineReport all = f.run(quiet(distances));
  EXPECT_EQ(all.problem_cells, problem);
  ASSERT_EQ(all.cells.size(), problem);
  EXPECT_DOUBLE_EQ(all.bytes_estimate, all.bytes_captured);
  EXPECT_GT(all.bytes_captured, 0.0);
  EXPECT_GT(all.placement_bytes, 0.0);
  EXPECT_LE(all.placement_bytes, all.placement_total_bytes);
  // Not vacuous: some cell needs a nearer far field than the largest (the loop below then checks the larger ones).
  EXPECT_TRUE(std::any_of(all.cells.begin(), all.cells.end(),
                          [&](const EnvMapCell& c) { return c.solved && c.far_distance < distances.back(); }));
  // Each cell against runs with one distance only: its own distance keeps t_max with the same bytes, every larger one
  // does not (or it would have been taken).
  for (size_t i = 0; i < all.cells.size(); ++i) {
    const EnvMapCell& c = all.cells[i];
    if (!c.solved) continue;
    EXPECT_LE(c.t_est_max_ms, f.place.t_max_ms);
    const EnvMapBaselineReport same = f.run(quiet({c.far_distance}));
    EXPECT_EQ(same.cells[i].bytes, c.bytes);
    EXPECT_TRUE(same.cells[i].solved);
    for (double d : distances) {
      if (d <= c.far_distance) continue;
      const EnvMapBaselineReport larger = f.run(quiet({d}));
      EXPECT_FALSE(larger.cells[i].solved) << "cell " << i << " could have taken " << d << " m";
      EXPECT_LE(larger.cells[i].bytes, c.bytes);  // a larger far field: fewer layers and objects
    }
  }
  // The largest distance alone draws the most geometry and stores the least.
  const EnvMapBaselineReport largest = f.run(quiet({distances.back()}));
  EXPECT_LE(largest.bytes_captured, all.bytes_captured);
  EXPECT_GE(largest.unsolved, all.unsolved);
}

TEST(EnvMapBaseline, ASampleEstimatesTheTotalFromItsMean) {
  const Fixture& f = fixture();
  EnvMapBaselineOptions o = quiet({2.0 * f.radius(), 4.0 * f.radius()});
  const EnvMapBaselineReport all = f.run(o);
  if (all.cells.size() < 2) GTEST_SKIP() << "needs two problem cells";
  o.sample = 1;
  const EnvMapBaselineReport one = f.run(o);
  ASSERT_EQ(one.cells.size(), 1u);
  EXPECT_DOUBLE_EQ(one.bytes_estimate, double(one.cells[0].bytes) * double(all.cells.size()));
  EXPECT_EQ(one.all_cells, all.cells.size());
}

TEST(EnvMapBaseline, BadInputIsAnError) {
  const Fixture& f = fixture();
  EXPECT_THROW(f.run(quiet({})), Error);
  EXPECT_THROW(f.run(quiet({-5.0})), Error);
  EXPECT_THROW(f.run(quiet({0.5 * f.radius()})), Error);  // no distance beyond the cells' half-diagonal
  const gen::City other = [] {
    gen::CityOptions o;
    o.blocks = 10;
    o.detail = 0;
    o.seed = 9;
    return gen::generateCity(o);
  }();
  EXPECT_THROW(runEnvMapBaseline(gpu::sharedHeadlessContext(), other.scene, f.profile, f.index, f.bound, f.lens,
                                 f.place.t_max_ms, quiet({100.0})),
               Error);
}

}  // namespace
}  // namespace farfield::eval
