// Placement database: the index round trip keeps every field bit for bit, loaded impostors equal the written ones,
// every truncation and byte flip of every file and every kind of damage to the index gives a farfield::Error naming
// the file and the record or element, a write failing at any file operation leaves the previous database, and the
// CPV lookup agrees with a brute-force scan. The layered impostors are made by hand (no GPU).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <set>
#include <tuple>

#include "farfield/core/error.h"
#include "farfield/image/png_io.h"
#include "farfield/store/placement_store.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

constexpr size_t kSceneObjects = 40;

std::string readBytes(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
void writeBytes(const std::string& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

// Every regular file under dir, relative to it.
std::set<std::string> filesIn(const std::string& dir) {
  std::set<std::string> out;
  for (const auto& f : fs::recursive_directory_iterator(dir))
    if (f.is_regular_file()) out.insert(fs::relative(f.path(), dir).generic_string());
  return out;
}

std::set<std::string> namedFiles(const PlacementIndex& index) {
  std::set<std::string> out{kPlacementIndexFile};
  for (const StoredPlacedImpostor& imp : index.impostors)
    for (const StoredImpostorLayer& l : imp.layers) {
      out.insert(l.texture);
      if (!l.ids.empty()) out.insert(l.ids);
    }
  return out;
}

// ---- Random plan inputs and hand-made layered impostors -----------------------------------------------------------

struct PlanInputs {
  Box3 box;
  Shaft shaft;
  ErrorBound bound;
  impostor::LayeredOptions options;
};

// Inputs planLayered accepts, with no round numbers (an inexact float anywhere shows). `small`: a few layers of at
// most 12 x 12 texels, for impostors with images.
PlanInputs randomInputs(std::mt19937& rng, bool small) {
  const auto u = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  const auto i = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  PlanInputs in;
  const Vec3 c(float(u(-500, 500)), float(u(-500, 500)), float(u(0, 50)));
  const Vec3 half(float(u(0.5, 10)), float(u(0.5, 10)), float(u(0.5, 10)));
  in.box = Box3::fromPoints(c - half, c + half);
  Vec3 axis(0.0f);
  while (glm::length(axis) < 0.1f) axis = Vec3(float(u(-2, 2)), float(u(-2, 2)), float(u(-0.5, 0.5)));
  in.shaft.apex = c;
  in.shaft.axis = axis;  // not unit: planLayered normalises it, the store keeps it as given
  in.shaft.apex_angle = float(u(0.1, 1.6));
  in.shaft.min_distance = glm::length(half) * float(u(4, 12));
  in.bound.pixels = u(0.5, 4);
  in.bound.width = i(320, 1280);
  in.bound.height = i(200, 720);
  in.bound.fov_y = u(0.6, 1.4);
  in.options.texel_pixels = u(1, 3);
  in.options.bound_cracks = rng() % 2 == 0;
  in.options.id_textures = rng() % 2 == 0;
  in.options.solid_slices = rng() % 2 == 0;
  in.options.dilate_texels = i(0, 16);
  if (small) {
    in.options.max_texture_size = i(4, 12);
    in.options.max_layers = i(1, 64);
    in.options.layer_count = i(1, 3);
  } else {
    in.options.max_texture_size = i(16, 1024);
    in.options.max_layers = i(1, 64);
    in.options.layer_count = rng() % 2 == 0 ? 0 : i(1, 8);
  }
  return in;
}

impostor::LayeredImpostor makeImpostor(const PlanInputs& in, std::mt19937& rng) {
  impostor::LayeredImpostor imp;
  imp.plan = impostor::planLayered(in.box, in.shaft, in.bound, in.options);
  for (const impostor::LayerPlan& p : imp.plan.layers) {
    impostor::Layer layer;
    layer.color = image::ColorImage(p.width, p.height);
    for (image::Rgba8& c : layer.color.pixels()) {
      const bool covered = rng() % 3 != 0;
      c = image::Rgba8(uint8_t(rng()), uint8_t(rng()), uint8_t(rng()), covered ? 255 : 0);
      layer.data_texels += covered ? 1 : 0;
    }
    if (in.options.id_textures) {
      layer.ids = image::IdImage(p.width, p.height);
      for (uint32_t& id : layer.ids.pixels()) id = rng() % 4 == 0 ? 0u : uint32_t(rng());  // all four bytes in use
    }
    layer.render_ms = std::uniform_real_distribution<double>(0.01, 5.0)(rng);
    imp.layers.push_back(std::move(layer));
  }
  imp.capture_ms = std::uniform_real_distribution<double>(0.1, 50.0)(rng);
  return imp;
}

std::vector<uint32_t> randomObjects(std::mt19937& rng) {
  std::set<uint32_t> s;
  const size_t n = 1 + rng() % 6;
  while (s.size() < n) s.insert(1 + uint32_t(rng() % kSceneObjects));
  return {s.begin(), s.end()};
}

// ---- Random view spaces: a regular BSP like placement/view_space.h's ---------------------------------------------

Vdi randomVdi(std::mt19937& rng, int level, uint32_t cell) {
  const int n = 1 << level;
  const float w = 2.0f / float(n);
  Vdi v;
  v.face = int(cell % 6);
  const uint32_t k = cell / 6;
  const int iu = int(k % uint32_t(n)), iv = int(k / uint32_t(n));
  v.u0 = -1.0f + w * float(iu);
  v.u1 = iu + 1 == n ? 1.0f : -1.0f + w * float(iu + 1);
  v.v0 = -1.0f + w * float(iv);
  v.v1 = iv + 1 == n ? 1.0f : -1.0f + w * float(iv + 1);
  (void)rng;
  return v;
}

// Splits `node` at the middle of its longest axis down to `depth` (randomly stopping early), leaves get 0..5 CPVs
// with distinct VDIs of one quadtree level; CPVs are numbered in depth-first order, lower child first.
void buildBsp(std::mt19937& rng, PlacementIndex& index, int node, int depth, const std::vector<uint32_t>& ids) {
  index.nodes[size_t(node)].cpv_first = uint32_t(index.cpvs.size());
  const Box3 box = index.nodes[size_t(node)].box;
  if (depth > 0 && (node == 0 || rng() % 4 != 0)) {
    const int axis = box.longestAxis();
    const float mid = 0.5f * (box.lo[axis] + box.hi[axis]);
    Box3 lower = box, upper = box;
    lower.hi[axis] = mid;
    upper.lo[axis] = mid;
    for (int k = 0; k < 2; ++k) {
      StoredViewSpaceNode child;
      child.box = k == 0 ? lower : upper;
      index.nodes[size_t(node)].children[k] = int(index.nodes.size());
      index.nodes.push_back(child);
    }
    buildBsp(rng, index, index.nodes[size_t(node)].children[0], depth - 1, ids);
    buildBsp(rng, index, index.nodes[size_t(node)].children[1], depth - 1, ids);
  } else {
    // A leaf: sometimes its visible set.
    if (rng() % 2 == 0) {
      StoredViewSpaceNode& leaf = index.nodes[size_t(node)];
      leaf.has_visible = true;
      std::set<uint32_t> seen;
      for (uint32_t id = 1; id <= index.scene_objects; ++id)
        if (rng() % 2 == 0) seen.insert(id);
      leaf.visible.assign(seen.begin(), seen.end());
    }
    const int level = int(rng() % 3);
    const uint32_t cells = 6u << (2 * level);
    std::set<uint32_t> chosen;
    const size_t count = rng() % 6;
    while (chosen.size() < std::min<size_t>(count, cells)) chosen.insert(uint32_t(rng() % cells));
    for (const uint32_t cell : chosen) {
      StoredCpv cpv;
      cpv.region = box;
      cpv.vdi = randomVdi(rng, level, cell);
      cpv.t_enc = std::uniform_real_distribution<double>(10.0, 40.0)(rng);
      cpv.t_after = cpv.t_enc * std::uniform_real_distribution<double>(0.2, 1.0)(rng);
      std::set<uint32_t> drawn;
      for (const uint32_t id : ids)
        if (rng() % 3 == 0) drawn.insert(id);
      cpv.impostors.assign(drawn.begin(), drawn.end());
      index.cpvs.push_back(std::move(cpv));
    }
  }
  index.nodes[size_t(node)].cpv_count = uint32_t(index.cpvs.size()) - index.nodes[size_t(node)].cpv_first;
}

void randomViewSpace(std::mt19937& rng, PlacementIndex& index, int depth, const std::vector<uint32_t>& ids) {
  const auto u = [&](double lo, double hi) { return float(std::uniform_real_distribution<double>(lo, hi)(rng)); };
  const Vec3 lo(u(-300, -100), u(-300, -100), u(0.5, 2));
  index.view_space = Box3::fromPoints(lo, lo + Vec3(u(100, 400), u(100, 400), u(5, 40)));
  index.nodes = {StoredViewSpaceNode{index.view_space, {-1, -1}, 0, 0, false, {}}};
  index.cpvs.clear();
  buildBsp(rng, index, 0, depth, ids);
}

// ---- Databases -------------------------------------------------------------------------------------------------

struct ImpostorInput {
  uint32_t id = 0;
  uint32_t node = 0;
  std::vector<uint32_t> objects;
  PlanInputs in;
  impostor::LayeredImpostor imp;
};

struct Content {
  PlacementIndex index;  // without impostors: writeDatabase fills them
  std::vector<ImpostorInput> impostors;
};

// A database with impostors of ids `ids` (images of a few texels; even positions with ids images, odd without) and a
// view space split `depth` times at most.
Content makeContent(uint32_t seed, const std::vector<uint32_t>& ids = {2, 5, 9}, int depth = 4) {
  std::mt19937 rng(seed);
  Content c;
  for (size_t k = 0; k < ids.size(); ++k) {
    ImpostorInput in;
    in.id = ids[k];
    in.node = uint32_t(rng() % 500);
    in.objects = randomObjects(rng);
    in.in = randomInputs(rng, true);
    in.in.options.id_textures = k % 2 == 0;
    in.imp = makeImpostor(in.in, rng);
    c.impostors.push_back(std::move(in));
  }
  c.index.scene = "city-" + std::to_string(seed) + ".glb";
  c.index.scene_objects = kSceneObjects;
  c.index.options = {{"t_max", 16.6 + seed}, {"lens", {{"fov_y", 1.0471975}}}, {"note", "opaque to the store"}};
  c.index.summary = {{"cpvs", 5}, {"memory", 1234567 + seed}, {"unsolved", nlohmann::json::array()}};
  randomViewSpace(rng, c.index, depth, ids);
  return c;
}

PlacementIndex writeDatabase(const std::string& dir, const Content& c) {
  PlacementIndex index = c.index;
  index.generation = nextPlacementGeneration(dir);
  for (const ImpostorInput& in : c.impostors)
    index.impostors.push_back(writePlacedImpostor(dir, index.generation, in.id, in.node, in.objects, in.imp,
                                                  in.in.box, in.in.shaft, in.in.bound, in.in.options));
  writePlacementIndex(dir, index);
  return index;
}

// What a database holds, without its generation and file names (they change with every rewrite): the index's content
// and every loaded image.
std::string storedContent(const std::string& dir) {
  const PlacementIndex index = readPlacementIndex(dir);
  nlohmann::json j = placementToJson(index);
  j.erase("generation");
  for (nlohmann::json& imp : j["impostors"])
    for (nlohmann::json& l : imp["layers"]) {
      l.erase("texture");
      l.erase("ids");
    }
  std::string out = j.dump();
  for (const StoredPlacedImpostor& s : index.impostors) {
    const impostor::LayeredImpostor imp = loadPlacedImpostor(dir, s);
    for (const impostor::Layer& l : imp.layers) {
      out.append(reinterpret_cast<const char*>(l.color.data()), 4 * l.color.pixelCount());
      out.append(reinterpret_cast<const char*>(l.ids.data()), 4 * l.ids.pixelCount());
    }
  }
  return out;
}

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

// Runs fn and expects a farfield::Error whose message holds every one of `parts`.
void expectError(const std::function<void()>& fn, const std::vector<std::string>& parts, const std::string& what) {
  try {
    fn();
    ADD_FAILURE() << what << ": no error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    for (const std::string& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << what << ": \"" << p << "\" not in: " << msg;
  }
}

// ---- Tests -------------------------------------------------------------------------------------------------------

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

TEST(PlacementStoreTest, LookupCpvAgreesWithABruteForceScan) {
  size_t views = 0, found = 0, ties = 0;
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    std::mt19937 rng(seed);
    PlacementIndex index;
    randomViewSpace(rng, index, 1 + int(seed % 7), {});
    const auto u = [&](double lo, double hi) { return float(std::uniform_real_distribution<double>(lo, hi)(rng)); };
    const Box3& vs = index.view_space;
    const Vec3 margin = 0.1f * vs.extent();
    for (int k = 0; k < 3000; ++k) {
      Vec3 eye(u(vs.lo.x - margin.x, vs.hi.x + margin.x), u(vs.lo.y - margin.y, vs.hi.y + margin.y),
               u(vs.lo.z - margin.z, vs.hi.z + margin.z));
      // Some eyes exactly on a split plane (on two regions: the BSP takes the lower child).
      bool on_plane = false;
      if (k % 5 == 0 && index.nodes.size() > 1) {
        const StoredViewSpaceNode& lower = index.nodes[1 + rng() % (index.nodes.size() - 1)];
        const int axis = int(rng() % 3);
        eye[axis] = rng() % 2 ? lower.box.lo[axis] : lower.box.hi[axis];
        on_plane = true;
      }
      Vec3 dir(u(-1, 1), u(-1, 1), u(-1, 1));
      if (k % 7 == 0) dir[int(rng() % 3)] = 0.0f;  // on a cube edge between faces
      if (glm::length(dir) < 1e-3f) continue;
      // Brute force: every CPV whose region holds the eye and whose VDI holds the direction.
      std::vector<uint32_t> holding;
      bool on_boundary = on_plane;
      for (uint32_t c = 0; c < index.cpvs.size(); ++c) {
        if (!index.cpvs[c].region.contains(eye) || !index.cpvs[c].vdi.contains(dir)) continue;
        holding.push_back(c);
        for (int a = 0; a < 3; ++a)
          on_boundary |= eye[a] == index.cpvs[c].region.lo[a] || eye[a] == index.cpvs[c].region.hi[a];
      }
      const std::optional<uint32_t> got = lookupCpv(index, eye, dir);
      ++views;
      // The leaf holding the eye: a leaf whose box holds it (brute force over the nodes), none outside the space.
      const std::optional<uint32_t> leaf = lookupLeaf(index, eye);
      bool in_some_leaf = false;
      for (const StoredViewSpaceNode& n : index.nodes) in_some_leaf |= n.children[0] < 0 && n.box.contains(eye);
      EXPECT_EQ(leaf.has_value(), in_some_leaf) << "seed " << seed << " view " << k;
      if (leaf) {
        EXPECT_LT(index.nodes[*leaf].children[0], 0);
        EXPECT_TRUE(index.nodes[*leaf].box.contains(eye));
      }
      if (holding.empty()) {
        EXPECT_FALSE(got.has_value()) << "seed " << seed << " view " << k << ": found " << *got;
        continue;
      }
      if (on_boundary) {
        // On a face shared by two regions: any CPV holding the view (or none, when the lower region has no CPV
        // for this direction) is right.
        ++ties;
        if (got) {
          EXPECT_NE(std::find(holding.begin(), holding.end(), *got), holding.end()) << "seed " << seed;
        }
        continue;
      }
      ASSERT_TRUE(got.has_value()) << "seed " << seed << " view " << k << ": brute force finds cpv " << holding[0];
      EXPECT_EQ(*got, holding[0]) << "seed " << seed << " view " << k;
      ++found;
    }
  }
  EXPECT_GT(found, 5000u);
  EXPECT_GT(ties, 1000u);
  EXPECT_GT(views - found - ties, 5000u);  // views in no CPV
  PlacementIndex empty;
  EXPECT_FALSE(lookupCpv(empty, Vec3(0.0f), Vec3(1.0f, 0.0f, 0.0f)).has_value());
}

TEST(PlacementStoreIntegrityTest, EveryTruncationAndByteFlipOfEveryFileIsAnErrorNamingFileAndRecord) {
  const std::string dir = test::scratchDir("placement_damage").string();
  const Content c = makeContent(11, {2, 5, 9}, 1);  // a small index: each of its bytes is damaged in turn
  writeDatabase(dir, c);
  const PlacementIndex index = readPlacementIndex(dir);
  struct Target {
    std::string name;    // relative to dir
    std::string record;  // what the message must name besides the file
    std::function<void()> load;
  };
  std::vector<Target> targets{{kPlacementIndexFile, "", [&] { readPlacementIndex(dir); }}};
  for (const StoredPlacedImpostor& s : index.impostors)
    for (size_t l = 0; l < s.layers.size(); ++l) {
      const std::string at = s.record + " layer " + std::to_string(l);
      const auto load = [&dir, &s] { loadPlacedImpostor(dir, s); };
      targets.push_back({s.layers[l].texture, at + " texture", load});
      if (!s.layers[l].ids.empty()) targets.push_back({s.layers[l].ids, at + " ids", load});
    }
  std::set<std::string> covered;
  for (const Target& t : targets) covered.insert(t.name);
  EXPECT_EQ(covered, namedFiles(index));

  size_t cases = 0;
  for (const Target& t : targets) {
    const std::string file = (fs::path(dir) / t.name).string();
    const std::string good = readBytes(file);
    const size_t n = good.size();
    ASSERT_GT(n, 2u) << t.name;
    const bool index_file = t.name == kPlacementIndexFile;
    const auto expect_found = [&](const std::string& bytes, const std::string& what, const std::string& how) {
      writeBytes(file, bytes);
      std::vector<std::string> parts{file, what};
      if (!t.record.empty()) parts.push_back(t.record);
      expectError(t.load, parts, t.name + ": " + how);
      ++cases;
    };
    for (size_t keep = 0; keep < n; ++keep)
      expect_found(good.substr(0, keep),
                   index_file ? "" : "truncated: " + std::to_string(keep) + " of " + std::to_string(n) + " bytes",
                   "truncation to " + std::to_string(keep) + " bytes");
    // A flip of every byte of the layer files, and of a thousand spread over the index (its checksum and text form
    // catch any: the index's own test below flips every digit).
    std::mt19937 rng{uint32_t(n)};
    const size_t step = std::max<size_t>(1, n / 1000);
    for (size_t at = 0; at < n; at += index_file ? step : 1) {
      std::string bad = good;
      bad[at] = char(uint8_t(bad[at]) ^ uint8_t(1u << (rng() % 8)));
      expect_found(bad, index_file ? "" : "checksum mismatch", "flip of byte " + std::to_string(at));
    }
    expect_found(good + "\n", index_file ? "" : "too long", "one byte appended");
    writeBytes(file, good);
    EXPECT_NO_THROW(t.load()) << t.name;
  }
  EXPECT_GT(cases, 10000u);
  EXPECT_EQ(storedContent(dir), [&] {
    const std::string other = test::scratchDir("placement_damage_fresh").string();
    writeDatabase(other, c);
    return storedContent(other);
  }());
  // A missing file names itself and the record.
  const StoredPlacedImpostor& s = index.impostors[0];
  fs::remove(fs::path(dir) / s.layers[0].texture);
  expectError([&] { loadPlacedImpostor(dir, s); }, {s.layers[0].texture, s.record + " layer 0 texture", "cannot open"},
              "missing texture");
  expectError([&] { placementBytes(dir, index); }, {s.layers[0].texture}, "missing texture (bytes)");
}

TEST(PlacementStoreIntegrityTest, DigitChangesInTheIndexAreCaughtByItsChecksum) {
  // A digit changed for another leaves valid JSON of the same layout: only the checksum can see it.
  const std::string dir = test::scratchDir("placement_digits").string();
  writeDatabase(dir, makeContent(13, {2, 5, 9}, 1));
  const std::string file = (fs::path(dir) / kPlacementIndexFile).string();
  const std::string good = readBytes(file);
  size_t digits = 0;
  for (size_t at = 0; at < good.size(); ++at) {
    if (good[at] < '0' || good[at] > '8') continue;
    std::string bad = good;
    ++bad[at];
    writeBytes(file, bad);
    try {
      readPlacementIndex(dir);
      ADD_FAILURE() << "digit at " << at << " changed without an error";
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(file), std::string::npos) << msg;
      // (A digit of "checksum" itself may push it past 32 bits, which its own check names.)
      EXPECT_TRUE(msg.find("checksum mismatch") != std::string::npos ||
                  msg.find("\"checksum\" must be a CRC-32") != std::string::npos ||
                  msg.find("text the placement writer") != std::string::npos ||
                  msg.find("not valid JSON") != std::string::npos)
          << msg;
    }
    ++digits;
  }
  EXPECT_GT(digits, 1000u);
  writeBytes(file, good);
  EXPECT_NO_THROW(readPlacementIndex(dir));
}

TEST(PlacementStoreIntegrityTest, ImagesOfTheWrongSizeAreRefusedNamingFileAndRecord) {
  // A layer file replaced by a valid PNG of another size, with the index's check updated: only the plan can tell.
  const std::string dir = test::scratchDir("placement_wrong_size").string();
  writeDatabase(dir, makeContent(5));
  PlacementIndex index = readPlacementIndex(dir);
  StoredPlacedImpostor& s = index.impostors[0];
  ASSERT_FALSE(s.layers[0].ids.empty());
  for (const bool ids : {false, true}) {
    std::string& name = ids ? s.layers[0].ids : s.layers[0].texture;
    FileCheck& check = ids ? s.layers[0].ids_check : s.layers[0].texture_check;
    const std::string file = (fs::path(dir) / name).string();
    const std::string good = readBytes(file);
    const FileCheck good_check = check;
    const std::string scratch = file + ".other.png";
    image::writePng(scratch, image::ColorImage(13, 1));  // wider than any layer (max_texture_size <= 12)
    writeBytes(file, readBytes(scratch));
    fs::remove(scratch);
    check = fileCheck(readBytes(file));
    expectError([&] { loadPlacedImpostor(dir, s); },
                {file, s.record + " layer 0 " + (ids ? "ids" : "texture"), "13x1 but the plan needs"}, name);
    writeBytes(file, good);
    check = good_check;
    EXPECT_NO_THROW(loadPlacedImpostor(dir, s));
  }
}

TEST(PlacementStoreIntegrityTest, DamagedIndexGivesErrorsNamingTheElement) {
  const std::string dir = test::scratchDir("placement_bad_index").string();
  // A fixed view space: node 0 splits into 1 (leaf: CPVs 0, 1) and 2, which splits into 3 (leaf: CPV 2) and 4
  // (leaf: CPVs 3, 4). Impostors 2, 5 and 9.
  Content c = makeContent(9);
  PlacementIndex& v = c.index;
  v.view_space = Box3::fromPoints(Vec3(0.0f), Vec3(100.0f, 50.0f, 10.0f));
  const Box3 left = Box3::fromPoints(Vec3(0.0f), Vec3(50.0f, 50.0f, 10.0f));
  const Box3 right = Box3::fromPoints(Vec3(50.0f, 0.0f, 0.0f), Vec3(100.0f, 50.0f, 10.0f));
  const Box3 right_lo = Box3::fromPoints(Vec3(50.0f, 0.0f, 0.0f), Vec3(100.0f, 25.0f, 10.0f));
  const Box3 right_hi = Box3::fromPoints(Vec3(50.0f, 25.0f, 0.0f), Vec3(100.0f, 50.0f, 10.0f));
  v.nodes = {{v.view_space, {1, 2}, 0, 5, false, {}}, {left, {-1, -1}, 0, 2, false, {}},
             {right, {3, 4}, 2, 3, false, {}}, {right_lo, {-1, -1}, 2, 1, false, {}},
             {right_hi, {-1, -1}, 3, 2, false, {}}};
  const auto cpv = [](const Box3& region, int face, std::vector<uint32_t> imps) {
    return StoredCpv{region, Vdi::fullFace(face), 20.5, 12.25, std::move(imps)};
  };
  v.cpvs = {cpv(left, 0, {2, 5}), cpv(left, 1, {9}), cpv(right_lo, 2, {}), cpv(right_hi, 3, {2, 5, 9}),
            cpv(right_hi, 4, {5})};
  writeDatabase(dir, c);
  const std::string file = (fs::path(dir) / kPlacementIndexFile).string();
  const std::string good_text = readBytes(file);
  const nlohmann::json good = nlohmann::json::parse(good_text);
  ASSERT_NO_THROW(readPlacementIndex(dir));
  ASSERT_TRUE(good["impostors"][0]["options"]["id_textures"].get<bool>());
  ASSERT_FALSE(good["impostors"][1]["options"]["id_textures"].get<bool>());

  using Edit = std::function<void(nlohmann::json&)>;
  const std::vector<std::tuple<std::string, Edit, std::vector<std::string>>> cases{
      {"unknown top-level member", [](nlohmann::json& j) { j["extra"] = 1; }, {"top level", "unknown member \"extra\""}},
      {"missing cpvs", [](nlohmann::json& j) { j.erase("cpvs"); }, {"top level", "missing \"cpvs\""}},
      {"wrong format", [](nlohmann::json& j) { j["format"] = "farfield-impostor-store"; }, {"\"format\""}},
      {"newer version", [](nlohmann::json& j) { j["version"] = 4; }, {"unsupported version 4"}},
      {"older version (layers not cropped)", [](nlohmann::json& j) { j["version"] = 1; }, {"unsupported version 1"}},
      {"older version (texels per impostor)", [](nlohmann::json& j) { j["version"] = 2; }, {"unsupported version 2"}},
      {"generation 0", [](nlohmann::json& j) { j["generation"] = 0; }, {"\"generation\"", ">= 1"}},
      {"scene_objects a string", [](nlohmann::json& j) { j["scene_objects"] = "many"; },
       {"\"scene_objects\" must be a non-negative integer"}},
      {"view space as an array", [](nlohmann::json& j) { j["view_space"] = {1, 2}; }, {"view_space", "expected an object"}},
      {"unknown impostor member", [](nlohmann::json& j) { j["impostors"][1]["color"] = 1; },
       {"impostors[1]", "unknown member \"color\""}},
      {"object id 0", [](nlohmann::json& j) { j["impostors"][1]["objects"][0] = 0; },
       {"impostors[1]", "\"objects\" holds an id outside 1..40"}},
      {"object id past the scene", [](nlohmann::json& j) { j["impostors"][2]["objects"].push_back(41); },
       {"impostors[2]", "outside 1..40"}},
      {"objects not ascending", [](nlohmann::json& j) { j["impostors"][0]["objects"] = {7, 3}; },
       {"impostors[0]", "ascending"}},
      {"no objects", [](nlohmann::json& j) { j["impostors"][0]["objects"] = nlohmann::json::array(); },
       {"impostors[0]", "\"objects\" is empty"}},
      {"impostor ids not ascending", [](nlohmann::json& j) { j["impostors"][1]["id"] = 2; },
       {"impostors[1].id", "sorted by id"}},
      {"negative id", [](nlohmann::json& j) { j["impostors"][0]["id"] = -2; }, {"impostors[0]", "\"id\""}},
      {"cpv names a missing impostor", [](nlohmann::json& j) { j["cpvs"][3]["impostors"][1] = 6; },
       {"cpvs[3].impostors[1]", "names impostor 6, which the index does not hold"}},
      {"cpv impostors repeated", [](nlohmann::json& j) { j["cpvs"][3]["impostors"][1] = 2; },
       {"cpvs[3].impostors[1]", "ascending without repeats"}},
      {"cpv impostor id negative", [](nlohmann::json& j) { j["cpvs"][0]["impostors"][0] = -1; },
       {"cpvs[0].impostors[0]", "must be an impostor id"}},
      {"cpv impostor id a string", [](nlohmann::json& j) { j["cpvs"][4]["impostors"][0] = "5"; },
       {"cpvs[4].impostors[0]"}},
      {"vdi face 6", [](nlohmann::json& j) { j["cpvs"][2]["vdi"]["face"] = 6; },
       {"cpvs[2].vdi", "\"face\" must be an integer in 0..5"}},
      {"vdi u0 > u1", [](nlohmann::json& j) { j["cpvs"][2]["vdi"]["u0"] = 1.0; },
       {"cpvs[2].vdi", "-1 <= u0 < u1 <= 1"}},
      {"vdi v outside the face", [](nlohmann::json& j) { j["cpvs"][2]["vdi"]["v1"] = 1.5; },
       {"cpvs[2].vdi", "-1 <= v0 < v1 <= 1"}},
      {"vdi not a number", [](nlohmann::json& j) { j["cpvs"][1]["vdi"]["u0"] = "left"; },
       {"cpvs[1].vdi", "\"u0\" must be a number"}},
      {"unknown vdi member", [](nlohmann::json& j) { j["cpvs"][1]["vdi"]["level"] = 3; },
       {"cpvs[1].vdi", "unknown member \"level\""}},
      {"negative time", [](nlohmann::json& j) { j["cpvs"][0]["t_enc"] = -1.0; }, {"cpvs[0]", "\"t_enc\" must be >= 0"}},
      {"time a string", [](nlohmann::json& j) { j["cpvs"][0]["t_after"] = "fast"; },
       {"cpvs[0]", "\"t_after\" must be a number"}},
      {"empty region", [](nlohmann::json& j) { j["cpvs"][0]["region"]["lo"][0] = 60.0; },
       {"cpvs[0].region", "is empty"}},
      {"region outside its leaf", [](nlohmann::json& j) { j["cpvs"][2]["region"]["hi"][1] = 30.0; },
       {"cpvs[2].region", "outside the box of nodes[3]"}},
      {"a node its own child", [](nlohmann::json& j) { j["nodes"][0]["children"] = {0, 2}; },
       {"nodes[0].children", "both nodes after it"}},
      {"a child past the nodes", [](nlohmann::json& j) { j["nodes"][2]["children"][1] = 99; },
       {"nodes[2].children[1]", "node index"}},
      {"one child", [](nlohmann::json& j) { j["nodes"][2]["children"][1] = -1; }, {"nodes[2].children"}},
      {"three children", [](nlohmann::json& j) { j["nodes"][2]["children"].push_back(4); },
       {"nodes[2].children", "[lower, upper]"}},
      {"the same child twice", [](nlohmann::json& j) { j["nodes"][2]["children"] = {4, 4}; },
       {"nodes[2].children", "twice"}},
      {"a shared child", [](nlohmann::json& j) { j["nodes"][1]["children"] = {3, 4}; },
       {"nodes[3]", "a child of both nodes[1] and nodes[2]"}},
      {"a node no one's child",
       [](nlohmann::json& j) {
         j["nodes"].push_back(j["nodes"][3]);
         j["nodes"][5]["cpv_count"] = 0;
       },
       {"nodes[5]", "no node's child"}},
      {"no nodes", [](nlohmann::json& j) { j["nodes"] = nlohmann::json::array(); }, {"\"nodes\"", "is empty"}},
      {"cpv range outside the list", [](nlohmann::json& j) { j["nodes"][4]["cpv_count"] = 7; },
       {"nodes[4]", "leave the 5 CPVs"}},
      {"root misses a cpv", [](nlohmann::json& j) { j["nodes"][0]["cpv_count"] = 4; },
       {"nodes[0]", "must hold every CPV"}},
      {"children do not split the range", [](nlohmann::json& j) { j["nodes"][3]["cpv_first"] = 3; },
       {"nodes[2]", "children's CPV ranges"}},
      {"a child box leaving its parent", [](nlohmann::json& j) { j["nodes"][3]["box"]["lo"][0] = 40.0; },
       {"nodes[3]", "leaves the box of its parent nodes[2]"}},
      {"root box not the view space", [](nlohmann::json& j) { j["view_space"]["hi"][2] = 11.0; },
       {"nodes[0]", "\"view_space\""}},
      {"cpv_first negative", [](nlohmann::json& j) { j["nodes"][1]["cpv_first"] = -1; },
       {"nodes[1]", "\"cpv_first\""}},
      {"a layer missing",
       [](nlohmann::json& j) { j["impostors"][1]["layers"].erase(j["impostors"][1]["layers"].size() - 1); },
       {"impostors[1].layers", "the plan of its box, shaft, bound and options has"}},
      {"ids without id textures",
       [](nlohmann::json& j) { j["impostors"][0]["options"]["id_textures"] = false; },
       {"impostors[0].layers[0]", "no id_textures"}},
      {"id textures without ids", [](nlohmann::json& j) { j["impostors"][1]["options"]["id_textures"] = true; },
       {"impostors[1].layers[0]", "\"ids\" is empty"}},
      {"an ids check without a file", [](nlohmann::json& j) { j["impostors"][1]["layers"][0]["ids_crc32"] = 5; },
       {"impostors[1].layers[0]", "without an ids file"}},
      {"a texture without its check", [](nlohmann::json& j) { j["impostors"][0]["layers"][0].erase("texture_crc32"); },
       {"impostors[0].layers[0]", "missing \"texture_crc32\""}},
      {"a CRC over 32 bits", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["ids_crc32"] = 1ull << 32; },
       {"impostors[0].layers[0]", "CRC-32"}},
      {"a file outside the database", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["texture"] = "../x.png"; },
       {"impostors[0].layers[0]", "\"..\""}},
      {"an absolute file", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["texture"] = "/tmp/x.png"; },
       {"impostors[0].layers[0]", "relative"}},
      {"an empty texture name", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["texture"] = ""; },
       {"impostors[0].layers[0]", "\"texture\" is empty"}},
      {"more data texels than texels", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["data_texels"] = 100000; },
       {"impostors[0].layers[0]", "exceeds"}},
      {"a crop outside its image", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["crop"] = {0, 0, 100000, 1}; },
       {"impostors[0].layers", "layer 0", "crop 100000x1"}},
      {"a crop of three numbers", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["crop"] = {0, 0, 1}; },
       {"impostors[0].layers[0]", "\"crop\" must be"}},
      {"a missing crop", [](nlohmann::json& j) { j["impostors"][0]["layers"][0].erase("crop"); },
       {"impostors[0].layers[0]", "crop"}},
      {"unknown layer member", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["mesh"] = "x"; },
       {"impostors[0].layers[0]", "unknown member \"mesh\""}},
      {"a shaft into the cluster", [](nlohmann::json& j) { j["impostors"][2]["shaft"]["min_distance"] = 0.5; },
       {"impostors[2]", "give no layered plan", "does not clear the cluster"}},
      {"a zero axis", [](nlohmann::json& j) { j["impostors"][2]["shaft"]["axis"] = {0, 0, 0}; },
       {"impostors[2]", "give no layered plan"}},
      {"a shaft without its apex", [](nlohmann::json& j) { j["impostors"][2]["shaft"].erase("apex"); },
       {"impostors[2].shaft", "missing \"apex\""}},
      {"max_texture_size 0", [](nlohmann::json& j) { j["impostors"][0]["options"]["max_texture_size"] = 0; },
       {"impostors[0].options", "\"max_texture_size\" must be an integer in 1..16384"}},
      {"an option missing", [](nlohmann::json& j) { j["impostors"][0]["options"].erase("solid_slices"); },
       {"impostors[0].options", "missing \"solid_slices\""}},
      {"an unknown option", [](nlohmann::json& j) { j["impostors"][0]["options"]["mip_maps"] = true; },
       {"impostors[0].options", "unknown member \"mip_maps\""}},
      {"a flag as a number", [](nlohmann::json& j) { j["impostors"][0]["options"]["bound_cracks"] = 0; },
       {"impostors[0].options", "\"bound_cracks\" must be true or false"}},
      {"a fractional frame width", [](nlohmann::json& j) { j["impostors"][0]["bound"]["width"] = 640.5; },
       {"impostors[0].bound", "\"width\" must be an integer"}},
      {"a bound of 0 pixels", [](nlohmann::json& j) { j["impostors"][0]["bound"]["pixels"] = 0.0; },
       {"impostors[0]", "give no layered plan"}},
      {"an empty cluster box", [](nlohmann::json& j) { j["impostors"][1]["box"]["hi"][2] = -1e9; },
       {"impostors[1].box", "is empty"}},
      {"negative capture time", [](nlohmann::json& j) { j["impostors"][1]["capture_ms"] = -0.5; },
       {"impostors[1]", "\"capture_ms\" must be >= 0"}},
  };
  for (const auto& [what, edit, parts] : cases) {
    nlohmann::json bad = good;
    bad.erase("checksum");
    edit(bad);
    writeBytes(file, placementFileText(bad));  // a valid checksum: the shape checks must find it
    std::vector<std::string> all{file};
    all.insert(all.end(), parts.begin(), parts.end());
    expectError([&] { readPlacementIndex(dir); }, all, what);
    // The writer's check (the same function) refuses it too.
    EXPECT_THROW(placementFromJson(bad, "in memory"), Error) << what;
  }
  // And the JSON damage that the checksum and the text form catch.
  writeBytes(file, good_text);
  ASSERT_NO_THROW(readPlacementIndex(dir));
  nlohmann::json stale = good;
  stale["scene"] = "edited.glb";
  writeBytes(file, stale.dump(1) + "\n");
  expectError([&] { readPlacementIndex(dir); }, {file, "checksum mismatch"}, "edited without a new checksum");
  writeBytes(file, good.dump(2) + "\n");
  expectError([&] { readPlacementIndex(dir); }, {file, "not the text the placement writer wrote"}, "reformatted");
  nlohmann::json no_checksum = good;
  no_checksum.erase("checksum");
  writeBytes(file, no_checksum.dump(1) + "\n");
  expectError([&] { readPlacementIndex(dir); }, {file, "missing \"checksum\""}, "no checksum");
  writeBytes(file, "[1, 2]\n");
  expectError([&] { readPlacementIndex(dir); }, {file, "expected an object"}, "an array");
  fs::remove(file);
  expectError([&] { readPlacementIndex(dir); }, {file, "cannot open"}, "no index");
  expectError([&] { readPlacementIndex(dir + "/absent"); }, {"absent", "not found"}, "no directory");
}

TEST(PlacementStoreIntegrityTest, TheWriterRefusesABadIndexBeforeWritingAnything) {
  const std::string dir = test::scratchDir("placement_refused").string();
  const Content c = makeContent(21);
  writeDatabase(dir, c);
  const std::string before = storedContent(dir);
  const std::string index_text = readBytes((fs::path(dir) / kPlacementIndexFile).string());
  PlacementIndex bad = readPlacementIndex(dir);
  bad.cpvs[0].impostors = {77};  // no such impostor
  ASSERT_TRUE(bad.find(77) == nullptr);
  bad.generation += 1;
  expectError([&] { writePlacementIndex(dir, bad); }, {"refused before writing", "cpvs[0].impostors[0]", "77"},
              "a cpv naming a missing impostor");
  bad = readPlacementIndex(dir);
  bad.nodes[0].children[0] = 0;
  expectError([&] { writePlacementIndex(dir, bad); }, {"refused before writing", "nodes[0].children"}, "bad children");
  bad = readPlacementIndex(dir);
  bad.impostors[0].layers[0].texture_check.known = false;  // a file not written by writePlacedImpostor
  expectError([&] { writePlacementIndex(dir, bad); }, {"impostors[0].layers[0]", "texture_crc32"}, "no check");
  EXPECT_EQ(readBytes((fs::path(dir) / kPlacementIndexFile).string()), index_text);
  EXPECT_EQ(storedContent(dir), before);
}

TEST(PlacementStoreIntegrityTest, AWriteFailingAtAnyFileOperationLeavesThePreviousDatabase) {
  const Content old_content = makeContent(31), new_content = makeContent(32, {1, 2, 3, 8});
  const std::string dir = test::scratchDir("placement_failed_rewrite").string();
  const std::string old_db = test::scratchDir("placement_failed_rewrite_old").string();
  writeDatabase(old_db, old_content);
  const std::string old_expected = storedContent(old_db);
  const std::string new_expected = [&] {
    const std::string fresh = test::scratchDir("placement_failed_rewrite_new").string();
    writeDatabase(fresh, new_content);
    return storedContent(fresh);
  }();
  ASSERT_NE(old_expected, new_expected);

  // The file operations of a complete rewrite, in order.
  std::vector<std::pair<std::string, std::string>> operations;
  fs::copy(old_db, dir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  setFileOperationHook([&](const char* op, const std::string& path) {
    operations.emplace_back(op, fs::relative(path, dir).generic_string());
  });
  const PlacementIndex rewritten = writeDatabase(dir, new_content);
  setFileOperationHook({});
  EXPECT_EQ(rewritten.generation, 2u);
  EXPECT_EQ(storedContent(dir), new_expected);
  EXPECT_EQ(filesIn(dir), namedFiles(rewritten)) << "files of generation 1 left behind";
  std::set<std::string> kinds;
  for (const auto& [op, path] : operations) kinds.insert(op);
  EXPECT_EQ(kinds, (std::set<std::string>{"create", "write", "fsync", "rename", "sync-dir"}));
  const auto rename_index = std::find(operations.begin(), operations.end(),
                                      std::pair<std::string, std::string>("rename", kPlacementIndexFile));
  ASSERT_NE(rename_index, operations.end());
  const size_t rename_at = size_t(rename_index - operations.begin()) + 1;  // 1-based
  ASSERT_GT(operations.size(), 40u);

  size_t saw_old = 0, saw_new = 0;
  for (size_t fail_at = 1; fail_at <= operations.size(); ++fail_at) {
    const std::string where = "failed before operation " + std::to_string(fail_at) + " (" +
                              operations[fail_at - 1].first + " " + operations[fail_at - 1].second + ")";
    fs::remove_all(dir);
    fs::copy(old_db, dir, fs::copy_options::recursive);
    size_t count = 0;
    setFileOperationHook([&](const char* op, const std::string& path) {
      if (++count == fail_at) throw Error(path, std::string("injected failure before ") + op);
    });
    EXPECT_THROW(writeDatabase(dir, new_content), Error) << where;
    setFileOperationHook({});
    std::string read;
    try {
      read = storedContent(dir);
    } catch (const Error& e) {
      ADD_FAILURE() << where << ": the database is not readable: " << e.what();
      continue;
    }
    // Before the index's rename the old database, after it the new one (only the index's directory sync is left).
    const bool expect_new = fail_at > rename_at;
    EXPECT_EQ(read, expect_new ? new_expected : old_expected) << where;
    (expect_new ? saw_new : saw_old) += 1;
    if (!expect_new) {
      EXPECT_EQ(readPlacementIndex(dir).generation, 1u) << where;
    }
    // A later write over the debris completes and leaves the new database alone in the directory.
    const PlacementIndex again = writeDatabase(dir, new_content);
    EXPECT_EQ(storedContent(dir), new_expected) << where;
    EXPECT_EQ(filesIn(dir), namedFiles(again)) << where;
  }
  EXPECT_GT(saw_old, 40u);
  EXPECT_GT(saw_new, 0u);
}

TEST(PlacementStoreIntegrityTest, GenerationsSkipThoseOfFilesLeftByAKilledWrite) {
  const std::string dir = test::scratchDir("placement_generations").string();
  EXPECT_EQ(nextPlacementGeneration(dir), 1u);
  const Content c = makeContent(41);
  EXPECT_EQ(writeDatabase(dir, c).generation, 1u);
  EXPECT_EQ(nextPlacementGeneration(dir), 2u);
  // A killed write of generation 7 left a layer file (and a temporary) behind.
  writeBytes((fs::path(dir) / placedLayerFileName(7, 1, 0, false)).string(), "debris");
  writeBytes((fs::path(dir) / placedLayerFileName(7, 1, 1, false)).string() + ".tmp", "debris");
  EXPECT_EQ(nextPlacementGeneration(dir), 8u);
  const PlacementIndex index = writeDatabase(dir, c);
  EXPECT_EQ(index.generation, 8u);
  EXPECT_EQ(filesIn(dir), namedFiles(index));
  EXPECT_EQ(placedLayerFileName(8, 12, 3, true), "impostors/g000008.i000012.03.ids.png");
}

}  // namespace
}  // namespace farfield::store
