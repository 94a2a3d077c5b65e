// PVS by item-buffer sampling (Decoret 1999, section 5.3) and near/far segmentation (section 5.4): the PVS holds
// every object seen in random frames from points of the cell and leaves out objects enclosed or hidden by others.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/scene.h"
#include "farfield/urban/pvs.h"

namespace farfield::urban {
namespace {

Polygon2 rect(float x0, float y0, float x1, float y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

// A street along y = 0 from x = -40 to 40; around it a ground plane, a ring of 25 m walls enclosing a low box,
// a long 20 m wall south of the street with a box behind it, and scattered boxes in plain view.
struct TestCity {
  scene::Scene scene;
  uint32_t ground = 0, south = 0, north = 0, west = 0, east = 0, enclosed = 0, long_wall = 0, behind_wall = 0;
  std::vector<uint32_t> in_view;  // boxes visible from the street (by construction)

  uint32_t addBox(const char* name, float x0, float y0, float x1, float y1, float height) {
    scene::Object object;
    object.name = name;
    object.parts = {{scene.addMesh(scene::makeBox({x0, y0, 0.0f}, {x1, y1, height})), 0}};
    object.footprint = rect(x0, y0, x1, y1);
    return scene.addObject(object);
  }

  TestCity() {
    scene.addMaterial(scene::Material{});
    scene::Object g;
    g.name = "ground";
    g.parts = {{scene.addMesh(scene::makeGroundQuad({-200, -200}, {200, 200})), 0}};
    ground = scene.addObject(g);
    // The ring: west and east walls run the full depth, north and south walls fit between them, so the corners
    // close without coplanar outer faces.
    west = addBox("west wall", -12, 18, -11, 42, 25);
    east = addBox("east wall", 11, 18, 12, 42, 25);
    south = addBox("south wall", -11, 18, 11, 19, 25);
    north = addBox("north wall", -11, 41, 11, 42, 25);
    enclosed = addBox("enclosed box", -3, 27, 3, 33, 4);
    long_wall = addBox("long wall", -60, -50, 60, -49, 20);
    behind_wall = addBox("box behind the long wall", -5, -70, 5, -60, 5);
    in_view = {addBox("b1", 20, 10, 26, 16, 8),    addBox("b2", -30, 12, -24, 18, 6),
               addBox("b3", -8, -20, -2, -14, 5),  addBox("b4", 30, -30, 36, -24, 10),
               addBox("b5", 0, 60, 8, 66, 40),     addBox("b6", -60, 40, -50, 50, 12)};
  }
};

constexpr float kEye = 1.7f;
const Vec3 kP(-40.0f, 0.0f, kEye), kQ(40.0f, 0.0f, kEye);

class PvsTest : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

TEST(PvsSamplePoints, SpacingAndEndPoints) {
  const std::vector<Vec3> points = pvsSamplePoints({0, 0, 1}, {10, 0, 1}, 3.0f);
  ASSERT_EQ(points.size(), 5u);  // ceil(10 / 3) = 4 intervals of 2.5 m
  for (size_t i = 0; i < points.size(); ++i) EXPECT_NEAR(points[i].x, 2.5f * float(i), 1e-5f);
  EXPECT_EQ(points.back(), Vec3(10, 0, 1));
  EXPECT_EQ(pvsSamplePoints({1, 2, 3}, {1, 2, 3}, 1.0f).size(), 1u);
  EXPECT_EQ(pvsSamplePoints({0, 0, 0}, {1, 0, 0}, 5.0f).size(), 2u);
  EXPECT_THROW(pvsSamplePoints({0, 0, 0}, {1, 0, 0}, 0.0f), Error);
  EXPECT_THROW(pvsSamplePoints({0, 0, 0}, {std::nanf(""), 0, 0}, 1.0f), Error);
}

TEST(CubeFaces, CoverEveryDirection) {
  const Vec3 eye(3.0f, -2.0f, 1.5f);
  const std::vector<Camera> faces = cubeFaceCameras(eye, 64, 0.1f, 1000.0f);
  ASSERT_EQ(faces.size(), 6u);
  std::mt19937_64 rng(5);
  std::normal_distribution<float> n(0.0f, 1.0f);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 dir = glm::normalize(Vec3(n(rng), n(rng), n(rng)));
    int hits = 0;
    for (const Camera& camera : faces) {
      camera.validate();
      float w = 0.0f;
      const Vec3 px = camera.project(eye + dir * 10.0f, &w);
      hits += w > 0.0f && px.x >= 0.0f && px.x <= 64.0f && px.y >= 0.0f && px.y <= 64.0f;
    }
    EXPECT_GE(hits, 1) << "direction " << dir.x << ", " << dir.y << ", " << dir.z;
  }
}

TEST_F(PvsTest, ContainsEverythingSeenFromTheCellAndLeavesOutHiddenObjects) {
  const TestCity city;
  const gpu::GpuScene gpu_scene(city.scene);
  PvsOptions options;
  options.spacing = 1.0f;
  options.face_size = 128;
  PvsSampler sampler(gpu_scene, options);
  const Pvs pvs = sampler.sample(kP, kQ);
  EXPECT_EQ(pvs.sample_points, 81u);
  EXPECT_EQ(pvs.views, 81u * 6u);
  const std::set<uint32_t> in_pvs(pvs.ids.begin(), pvs.ids.end());
  EXPECT_TRUE(std::is_sorted(pvs.ids.begin(), pvs.ids.end()));
  EXPECT_EQ(in_pvs.size(), pvs.ids.size());

  // Hidden from every point of the street: the box inside the ring, the box behind the long wall.
  EXPECT_FALSE(in_pvs.count(city.enclosed));
  EXPECT_FALSE(in_pvs.count(city.behind_wall));
  for (uint32_t id : {city.ground, city.south, city.west, city.east}) EXPECT_TRUE(in_pvs.count(id)) << id;
  for (uint32_t id : city.in_view) EXPECT_TRUE(in_pvs.count(id)) << id;

  // Random frames from random points of the cell, random headings, pitches and fields of view: every id they show
  // must be in the PVS.
  gpu::Renderer renderer;
  gpu::RenderTarget target(64, 64);
  const std::vector<gpu::DrawItem> items = gpu_scene.drawItems();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> t(0.0f, 1.0f), yaw(0.0f, float(2.0 * kPi)), pitch(-0.45f, 0.45f),
      fov(0.8f, 1.4f);
  std::set<uint32_t> seen_all;
  for (int frame = 0; frame < 40; ++frame) {
    Camera camera;
    camera.eye = kP + (kQ - kP) * t(rng);
    const float heading = yaw(rng), up = pitch(rng);
    camera.at = camera.eye + Vec3(std::cos(heading) * std::cos(up), std::sin(heading) * std::cos(up), std::sin(up));
    camera.fov_y = fov(rng);
    camera.width = camera.height = 64;
    camera.near_plane = options.near_plane;
    renderer.render(camera, items, target, gpu::RenderMode::ItemBuffer);
    const image::IdImage ids = target.readIds();
    std::set<uint32_t> seen(ids.pixels().begin(), ids.pixels().end());
    seen.erase(0);
    for (uint32_t id : seen) EXPECT_TRUE(in_pvs.count(id)) << "frame " << frame << " sees object " << id;
    seen_all.insert(seen.begin(), seen.end());
  }
  // The frames are not trivially empty: they see most of the scene.
  EXPECT_GE(seen_all.size(), 8u);
}

TEST_F(PvsTest, SinglePointSeesLessThanTheWholeCell) {
  // From the west end, b5 (behind the ring) is hidden by the ring; from the east end it shows beside the ring.
  const TestCity city;
  const gpu::GpuScene gpu_scene(city.scene);
  PvsOptions options;
  options.face_size = 128;
  PvsSampler sampler(gpu_scene, options);
  std::vector<uint8_t> west_seen, east_seen;
  sampler.sampleViewpoint(Vec3(-5.0f, 0.0f, kEye), west_seen);
  sampler.sampleViewpoint(kQ, east_seen);
  const uint32_t b5 = city.in_view[4];
  EXPECT_TRUE(b5 >= west_seen.size() || !west_seen[b5]);
  ASSERT_LT(b5, east_seen.size());
  EXPECT_TRUE(east_seen[b5]);
}

TEST(PvsSamplePoints, AStreetsTwoDirectionsShareTheirPointsBitForBit) {
  std::mt19937 rng(1605);
  std::uniform_real_distribution<float> u(-3000.0f, 3000.0f), h(0.5f, 40.0f);
  for (int trial = 0; trial < 500; ++trial) {
    const Vec3 p(u(rng), u(rng), h(rng)), q(u(rng), u(rng), h(rng));
    const float spacing = 0.5f + float(trial % 9);
    std::vector<Vec3> forward = pvsSamplePoints(p, q, spacing), backward = pvsSamplePoints(q, p, spacing);
    std::reverse(backward.begin(), backward.end());
    ASSERT_EQ(forward.size(), backward.size());
    for (size_t k = 0; k < forward.size(); ++k)
      ASSERT_TRUE(forward[k] == backward[k]) << "trial " << trial << " point " << k;
    EXPECT_TRUE(forward.front() == p && forward.back() == q);
  }
}

TEST_F(PvsTest, ReusedViewpointsGiveThePvsOfFreshRenders) {
  const TestCity city;
  const gpu::GpuScene gpu_scene(city.scene);
  PvsOptions fresh_options;
  fresh_options.spacing = 4.0f;
  fresh_options.face_size = 64;
  fresh_options.reuse_viewpoints = false;
  PvsOptions reuse_options = fresh_options;
  reuse_options.reuse_viewpoints = true;
  PvsSampler reusing(gpu_scene, reuse_options);
  const Vec3 r = kQ + Vec3(0.0f, 30.0f, 0.0f);  // a street leaving the junction at kQ
  const std::vector<std::pair<Vec3, Vec3>> cells = {{kP, kQ}, {kQ, kP}, {kQ, r}, {kP, kQ}};
  for (size_t c = 0; c < cells.size(); ++c) {
    PvsSampler fresh(gpu_scene, fresh_options);  // no earlier cell
    const Pvs expected = fresh.sample(cells[c].first, cells[c].second);
    const Pvs got = reusing.sample(cells[c].first, cells[c].second);
    EXPECT_EQ(got.ids, expected.ids) << "cell " << c;
    EXPECT_EQ(got.sample_points, expected.sample_points);
    EXPECT_EQ(expected.views, expected.sample_points * 6);
    EXPECT_EQ(got.views + 6 * got.reused_points, got.sample_points * 6);
  }
  // The twin renders nothing; the street from the junction reuses the junction's point; the repeat renders nothing.
  EXPECT_EQ(reusing.sample(kQ, kP).reused_points, pvsSamplePoints(kQ, kP, 4.0f).size());
  EXPECT_EQ(reusing.sample(kQ, r + Vec3(0.0f, 9.0f, 0.0f)).reused_points, 1u);
}

TEST_F(PvsTest, BadOptionsThrow) {
  const TestCity city;
  const gpu::GpuScene gpu_scene(city.scene);
  PvsOptions options;
  options.face_size = 0;
  EXPECT_THROW(PvsSampler(gpu_scene, options), Error);
  options = {};
  options.near_plane = 0.0f;
  EXPECT_THROW(PvsSampler(gpu_scene, options), Error);
  options = {};
  options.spacing = -1.0f;
  PvsSampler sampler(gpu_scene, options);
  EXPECT_THROW(sampler.sample(kP, kQ), Error);
}

TEST(NearFar, ByDistanceToTheCellSegment) {
  const TestCity city;
  const CellSegment cell{{-40, 0}, {40, 0}};
  // Footprint distances to the street: b3 14 m (y = -14), south wall 18 m, long wall 49 m, b5 60 m; the ground has
  // no footprint, its bounds' rectangle contains the street (0 m).
  const uint32_t b3 = city.in_view[2], b5 = city.in_view[4];
  const std::vector<uint32_t> pvs = {city.ground, city.south, city.long_wall, b3, b5};
  NearFarSplit split = splitNearFar(city.scene, pvs, cell, 30.0f);
  EXPECT_EQ(split.near_ids, (std::vector<uint32_t>{city.ground, city.south, b3}));
  EXPECT_EQ(split.far_ids, (std::vector<uint32_t>{city.long_wall, b5}));
  split = splitNearFar(city.scene, pvs, cell, 49.5f);
  EXPECT_EQ(split.near_ids, (std::vector<uint32_t>{city.ground, city.south, city.long_wall, b3}));
  EXPECT_THROW(splitNearFar(city.scene, std::vector<uint32_t>{99u}, cell, 10.0f), Error);
  EXPECT_THROW(splitNearFar(city.scene, pvs, cell, -1.0f), Error);
}

TEST(NearFar, ByLocalModel) {
  const std::vector<uint32_t> pvs = {3, 8, 1, 12};
  const std::vector<uint32_t> local = {12, 5, 3};
  const NearFarSplit split = splitNearFar(pvs, local);
  EXPECT_EQ(split.near_ids, (std::vector<uint32_t>{3, 12}));
  EXPECT_EQ(split.far_ids, (std::vector<uint32_t>{8, 1}));
}

}  // namespace
}  // namespace farfield::urban
