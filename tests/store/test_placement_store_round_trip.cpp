// Placement database round trips: the index keeps every field bit for bit, loaded impostors equal the written ones
// and the writer refuses impostors that disagree with their plan. The layered impostors are made by hand (no GPU).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/store/placement_store.h"
#include "store/placement_store_fixture.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

using placement_test::Content;
using placement_test::expectError;
using placement_test::filesIn;
using placement_test::ImpostorInput;
using placement_test::kSceneObjects;
using placement_test::makeContent;
using placement_test::namedFiles;
using placement_test::PlanInputs;
using placement_test::randomInputs;
using placement_test::randomObjects;
using placement_test::randomViewSpace;
using placement_test::readBytes;
using placement_test::writeDatabase;

// ---- Bit-exact comparisons ---------------------------------------------------------------------------------------

bool same(float a, float b) { return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b); }
bool same(double a, double b) { return std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b); }
bool same(const Vec3& a, const Vec3& b) { return same(a.x, b.x) && same(a.y, b.y) && same(a.z, b.z); }
bool same(const Box3& a, const Box3& b) { return same(a.lo, b.lo) && same(a.hi, b.hi); }

void expectSameIndex(const PlacementIndex& got, const PlacementIndex& want) {
  EXPECT_EQ(got.version, kPlacementVersion);
  EXPECT_EQ(got.generation, want.generation);
  EXPECT_EQ(got.scene, want.scene);
  EXPECT_EQ(got.scene_objects, want.scene_objects);
  EXPECT_EQ(got.options, want.options);
  EXPECT_EQ(got.summary, want.summary);
  EXPECT_TRUE(same(got.view_space, want.view_space));
  ASSERT_EQ(got.nodes.size(), want.nodes.size());
  for (size_t k = 0; k < got.nodes.size(); ++k) {
    const StoredViewSpaceNode &a = got.nodes[k], &b = want.nodes[k];
    EXPECT_TRUE(same(a.box, b.box)) << "node " << k;
    EXPECT_EQ(a.children[0], b.children[0]) << "node " << k;
    EXPECT_EQ(a.children[1], b.children[1]) << "node " << k;
    EXPECT_EQ(a.cpv_first, b.cpv_first) << "node " << k;
    EXPECT_EQ(a.cpv_count, b.cpv_count) << "node " << k;
    EXPECT_EQ(a.has_visible, b.has_visible) << "node " << k;
    EXPECT_EQ(a.visible, b.visible) << "node " << k;
  }
  ASSERT_EQ(got.cpvs.size(), want.cpvs.size());
  for (size_t k = 0; k < got.cpvs.size(); ++k) {
    const StoredCpv &a = got.cpvs[k], &b = want.cpvs[k];
    EXPECT_TRUE(same(a.region, b.region)) << "cpv " << k;
    EXPECT_EQ(a.vdi.face, b.vdi.face) << "cpv " << k;
    EXPECT_TRUE(same(a.vdi.u0, b.vdi.u0) && same(a.vdi.u1, b.vdi.u1) && same(a.vdi.v0, b.vdi.v0) &&
                same(a.vdi.v1, b.vdi.v1))
        << "cpv " << k;
    EXPECT_TRUE(same(a.t_enc, b.t_enc)) << "cpv " << k;
    EXPECT_TRUE(same(a.t_after, b.t_after)) << "cpv " << k;
    EXPECT_EQ(a.impostors, b.impostors) << "cpv " << k;
  }
  ASSERT_EQ(got.impostors.size(), want.impostors.size());
  for (size_t k = 0; k < got.impostors.size(); ++k) {
    const StoredPlacedImpostor &a = got.impostors[k], &b = want.impostors[k];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.record, "impostor " + std::to_string(b.id));
    EXPECT_EQ(a.node, b.node);
    EXPECT_EQ(a.objects, b.objects);
    EXPECT_TRUE(same(a.box, b.box)) << a.record;
    EXPECT_TRUE(same(a.shaft.apex, b.shaft.apex)) << a.record;
    EXPECT_TRUE(same(a.shaft.axis, b.shaft.axis)) << a.record;
    EXPECT_TRUE(same(a.shaft.apex_angle, b.shaft.apex_angle)) << a.record;
    EXPECT_TRUE(same(a.shaft.min_distance, b.shaft.min_distance)) << a.record;
    EXPECT_TRUE(same(a.bound.pixels, b.bound.pixels)) << a.record;
    EXPECT_EQ(a.bound.width, b.bound.width);
    EXPECT_EQ(a.bound.height, b.bound.height);
    EXPECT_TRUE(same(a.bound.fov_y, b.bound.fov_y)) << a.record;
    EXPECT_TRUE(same(a.options.texel_pixels, b.options.texel_pixels)) << a.record;
    EXPECT_EQ(a.options.max_texture_size, b.options.max_texture_size);
    EXPECT_EQ(a.options.max_layers, b.options.max_layers);
    EXPECT_EQ(a.options.layer_count, b.options.layer_count);
    EXPECT_EQ(a.options.bound_cracks, b.options.bound_cracks);
    EXPECT_EQ(a.options.id_textures, b.options.id_textures);
    EXPECT_EQ(a.options.solid_slices, b.options.solid_slices);
    EXPECT_EQ(a.options.dilate_texels, b.options.dilate_texels);
    EXPECT_EQ(a.bytes, b.bytes);
    EXPECT_TRUE(same(a.capture_ms, b.capture_ms)) << a.record;
    ASSERT_EQ(a.layers.size(), b.layers.size()) << a.record;
    for (size_t l = 0; l < a.layers.size(); ++l) {
      const StoredImpostorLayer &x = a.layers[l], &y = b.layers[l];
      EXPECT_EQ(x.texture, y.texture);
      EXPECT_EQ(x.texture_check.crc32, y.texture_check.crc32);
      EXPECT_EQ(x.texture_check.bytes, y.texture_check.bytes);
      EXPECT_TRUE(x.texture_check.known);
      EXPECT_EQ(x.ids, y.ids);
      EXPECT_EQ(x.ids_check.crc32, y.ids_check.crc32);
      EXPECT_EQ(x.ids_check.bytes, y.ids_check.bytes);
      EXPECT_EQ(x.ids_check.known, !y.ids.empty());
      EXPECT_EQ(x.data_texels, y.data_texels);
      EXPECT_EQ(x.crop.x, y.crop.x);
      EXPECT_EQ(x.crop.y, y.crop.y);
      EXPECT_EQ(x.crop.width, y.crop.width);
      EXPECT_EQ(x.crop.height, y.crop.height);
      EXPECT_TRUE(same(x.render_ms, y.render_ms)) << a.record << " layer " << l;
    }
  }
}

TEST(PlacementStoreTest, IndexRoundTripKeepsEveryFieldBitForBit) {
  // Random records (file checks with every bit of the CRC in use; the index alone is read, so no files behind them).
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    const std::string dir = test::scratchDir("placement_round_trip").string();
    PlacementIndex index;
    index.generation = 1 + rng() % 1000000;
    index.scene = "scene \"" + std::to_string(seed) + "\" \xc3\xa9.glb";
    index.scene_objects = kSceneObjects;
    index.options = {{"t_max", std::uniform_real_distribution<double>(1, 100)(rng)}, {"nested", {1, 2.5, "x"}}};
    index.summary = {{"memory", rng()}, {"ratio", 1.0 / 3.0}};
    std::vector<uint32_t> ids;
    for (uint32_t id = 0; ids.size() < 6; id += 1 + rng() % 1000) ids.push_back(id);
    for (const uint32_t id : ids) {
      StoredPlacedImpostor imp;
      imp.id = id;
      imp.node = uint32_t(rng());
      imp.objects = randomObjects(rng);
      const PlanInputs in = randomInputs(rng, false);
      imp.box = in.box;
      imp.shaft = in.shaft;
      imp.bound = in.bound;
      imp.options = in.options;
      const impostor::LayeredPlan plan = impostor::planLayered(in.box, in.shaft, in.bound, in.options);
      for (size_t l = 0; l < plan.layers.size(); ++l) {
        StoredImpostorLayer s;
        s.texture = placedLayerFileName(index.generation, id, l, false);
        s.texture_check = FileCheck{(uint64_t(rng()) << 20) + rng(), uint32_t(rng()), true};
        if (in.options.id_textures) {
          s.ids = placedLayerFileName(index.generation, id, l, true);
          s.ids_check = FileCheck{uint64_t(rng()), uint32_t(rng()), true};
        }
        // A random rectangle of the captured image (cropLayered), holding the data texels.
        const int w = plan.layers[l].width, h = plan.layers[l].height;
        s.crop.x = int(rng() % uint32_t(w));
        s.crop.y = int(rng() % uint32_t(h));
        s.crop.width = 1 + int(rng() % uint32_t(w - s.crop.x));
        s.crop.height = 1 + int(rng() % uint32_t(h - s.crop.y));
        s.data_texels = rng() % (uint64_t(s.crop.width) * uint64_t(s.crop.height) + 1);
        s.render_ms = std::uniform_real_distribution<double>(0, 10)(rng);
        imp.layers.push_back(s);
      }
      imp.bytes = (uint64_t(rng()) << 32) | rng();
      imp.capture_ms = std::uniform_real_distribution<double>(0, 100)(rng);
      index.impostors.push_back(std::move(imp));
    }
    randomViewSpace(rng, index, 6, ids);
    ASSERT_GT(index.cpvs.size(), 0u);

    writePlacementIndex(dir, index);
    for (const StoredPlacedImpostor& imp : index.impostors) EXPECT_EQ(imp.record, "impostor " + std::to_string(imp.id));
    const PlacementIndex read = readPlacementIndex(dir);
    expectSameIndex(read, index);
    // And the text is the writer's form of what was read (nothing the reader drops).
    EXPECT_EQ(readBytes((fs::path(dir) / kPlacementIndexFile).string()), placementFileText(placementToJson(read)));
  }
}

TEST(PlacementStoreTest, LoadedImpostorsEqualTheWrittenOnes) {
  const std::string dir = test::scratchDir("placement_load").string();
  const Content c = makeContent(7, {0, 3, 4, 11});
  const PlacementIndex written = writeDatabase(dir, c);
  EXPECT_EQ(written.generation, 1u);
  EXPECT_EQ(filesIn(dir), namedFiles(written));
  const PlacementIndex index = readPlacementIndex(dir);
  expectSameIndex(index, written);
  bool with_ids = false, without_ids = false;
  for (const ImpostorInput& in : c.impostors) {
    const StoredPlacedImpostor* s = index.find(in.id);
    ASSERT_NE(s, nullptr);
    EXPECT_EQ(s->bytes, in.imp.plan.bytes());
    const impostor::LayeredImpostor got = loadPlacedImpostor(dir, *s);
    const impostor::LayeredImpostor& want = in.imp;
    // The re-derived plan is the capture's, bit for bit.
    ASSERT_EQ(got.plan.layers.size(), want.plan.layers.size());
    EXPECT_TRUE(same(got.plan.capture_eye, want.plan.capture_eye));
    EXPECT_TRUE(same(got.plan.right, want.plan.right) && same(got.plan.up, want.plan.up));
    EXPECT_TRUE(same(got.plan.spacing, want.plan.spacing));
    EXPECT_EQ(got.plan.bytes(), want.plan.bytes());
    for (size_t l = 0; l < got.plan.layers.size(); ++l) {
      const impostor::LayerPlan &a = got.plan.layers[l], &b = want.plan.layers[l];
      EXPECT_TRUE(same(a.z_lo, b.z_lo) && same(a.z_hi, b.z_hi) && same(a.depth, b.depth) && same(a.half_u, b.half_u) &&
                  same(a.half_v, b.half_v) && same(a.fov_y, b.fov_y));
      EXPECT_EQ(a.width, b.width);
      EXPECT_EQ(a.height, b.height);
    }
    EXPECT_TRUE(same(got.capture_ms, want.capture_ms));
    ASSERT_EQ(got.layers.size(), want.layers.size());
    for (size_t l = 0; l < got.layers.size(); ++l) {
      EXPECT_EQ(got.layers[l].color.width(), want.layers[l].color.width());
      EXPECT_EQ(got.layers[l].color.pixels(), want.layers[l].color.pixels()) << s->record << " layer " << l;
      EXPECT_EQ(got.layers[l].ids.width(), want.layers[l].ids.width());
      EXPECT_EQ(got.layers[l].ids.pixels(), want.layers[l].ids.pixels()) << s->record << " layer " << l;
      EXPECT_EQ(got.layers[l].data_texels, want.layers[l].data_texels);
      EXPECT_TRUE(same(got.layers[l].render_ms, want.layers[l].render_ms));
    }
    EXPECT_EQ(got.cpuBytes(), want.cpuBytes());
    (in.in.options.id_textures ? with_ids : without_ids) = true;
  }
  EXPECT_TRUE(with_ids && without_ids);
  uint64_t on_disk = 0;
  for (const std::string& f : filesIn(dir)) on_disk += fs::file_size(fs::path(dir) / f);
  EXPECT_EQ(placementBytes(dir, index), on_disk);
}

TEST(PlacementStoreTest, WriterRefusesImpostorsThatDisagreeWithTheirPlan) {
  const std::string dir = test::scratchDir("placement_writer_refuses").string();
  Content c = makeContent(3);
  ImpostorInput& in = c.impostors[0];  // id 2, with ids images
  ASSERT_TRUE(in.in.options.id_textures);
  const auto write = [&](const impostor::LayeredImpostor& imp, const PlanInputs& p) {
    writePlacedImpostor(dir, 1, in.id, in.node, in.objects, imp, p.box, p.shaft, p.bound, p.options);
  };
  EXPECT_NO_THROW(write(in.imp, in.in));
  impostor::LayeredImpostor bad = in.imp;
  bad.layers[0].color = image::ColorImage(bad.layers[0].color.width() + 1, bad.layers[0].color.height());
  expectError([&] { write(bad, in.in); }, {dir, "impostor 2", "layer 0", "colour image"}, "wrong colour size");
  bad = in.imp;
  bad.layers[0].ids = image::IdImage();
  expectError([&] { write(bad, in.in); }, {"impostor 2", "layer 0", "id image"}, "missing ids");
  bad = in.imp;
  bad.layers.pop_back();
  expectError([&] { write(bad, in.in); }, {"impostor 2", "layers"}, "a layer missing");
  PlanInputs other = in.in;
  other.options.layer_count += 1;
  expectError([&] { write(in.imp, other); }, {"impostor 2", "layers"}, "other plan inputs");
  other = in.in;
  other.shaft.min_distance = 0.1f;
  expectError([&] { write(in.imp, other); }, {"impostor 2", "no layered plan"}, "a shaft into the cluster");
  // Objects in any order (a BVH's) are stored ascending; repeats and 0 are refused.
  std::vector<uint32_t> shuffled = in.objects;
  shuffled.push_back(kSceneObjects + 7);
  std::reverse(shuffled.begin(), shuffled.end());
  std::vector<uint32_t> sorted = shuffled;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(writePlacedImpostor(dir, 1, in.id, in.node, shuffled, in.imp, in.in.box, in.in.shaft, in.in.bound,
                                in.in.options).objects,
            sorted);
  expectError([&] { writePlacedImpostor(dir, 1, in.id, in.node, {0, 3}, in.imp, in.in.box, in.in.shaft, in.in.bound,
                                        in.in.options); },
              {"impostor 2", "objects"}, "object 0");
  expectError([&] { writePlacedImpostor(dir, 1, in.id, in.node, {3, 5, 3}, in.imp, in.in.box, in.in.shaft, in.in.bound,
                                        in.in.options); },
              {"impostor 2", "objects"}, "repeated object");
  expectError([&] { writePlacedImpostor(dir, 0, in.id, in.node, in.objects, in.imp, in.in.box, in.in.shaft,
                                        in.in.bound, in.in.options); },
              {"impostor 2", "generation 0"}, "generation 0");
}

}  // namespace
}  // namespace farfield::store
