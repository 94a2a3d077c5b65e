// Shared by the placement database tests (test_placement_store_*.cpp): file helpers, random plan inputs, hand-made
// layered impostors (no GPU), random view spaces, whole databases and an error check naming every part.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/store/placement_store.h"

namespace farfield::store::placement_test {

namespace fs = std::filesystem;

inline constexpr size_t kSceneObjects = 40;

inline std::string readBytes(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
inline void writeBytes(const std::string& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

// Every regular file under dir, relative to it.
inline std::set<std::string> filesIn(const std::string& dir) {
  std::set<std::string> out;
  for (const auto& f : fs::recursive_directory_iterator(dir))
    if (f.is_regular_file()) out.insert(fs::relative(f.path(), dir).generic_string());
  return out;
}

inline std::set<std::string> namedFiles(const PlacementIndex& index) {
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
inline PlanInputs randomInputs(std::mt19937& rng, bool small) {
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

inline impostor::LayeredImpostor makeImpostor(const PlanInputs& in, std::mt19937& rng) {
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

inline std::vector<uint32_t> randomObjects(std::mt19937& rng) {
  std::set<uint32_t> s;
  const size_t n = 1 + rng() % 6;
  while (s.size() < n) s.insert(1 + uint32_t(rng() % kSceneObjects));
  return {s.begin(), s.end()};
}

// ---- Random view spaces: a regular BSP like placement/view_space.h's ---------------------------------------------

inline Vdi randomVdi(std::mt19937& rng, int level, uint32_t cell) {
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
inline void buildBsp(std::mt19937& rng, PlacementIndex& index, int node, int depth, const std::vector<uint32_t>& ids) {
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

inline void randomViewSpace(std::mt19937& rng, PlacementIndex& index, int depth, const std::vector<uint32_t>& ids) {
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
inline Content makeContent(uint32_t seed, const std::vector<uint32_t>& ids = {2, 5, 9}, int depth = 4) {
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

inline PlacementIndex writeDatabase(const std::string& dir, const Content& c) {
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
inline std::string storedContent(const std::string& dir) {
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

// Runs fn and expects a farfield::Error whose message holds every one of `parts`.
inline void expectError(const std::function<void()>& fn, const std::vector<std::string>& parts,
                        const std::string& what) {
  try {
    fn();
    ADD_FAILURE() << what << ": no error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    for (const std::string& p : parts)
      EXPECT_NE(msg.find(p), std::string::npos) << what << ": \"" << p << "\" not in: " << msg;
  }
}

}  // namespace farfield::store::placement_test
