#include "farfield/scene/gltf_skin.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "support/test_support.h"

namespace farfield::scene {
namespace {

template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// A one-triangle skinned glTF written by hand (two joints, one animation): each defect is one switch.
struct TinySkin {
  uint16_t bad_joint = 0;     // joint index of vertex 2 (0 or 1 valid)
  float weight0 = 1.0f;       // first weight of vertex 1 (the other three 0)
  bool inverse_bind = true;
  bool truncate = false;
  bool image_past_buffer = false;  // a textured material whose image's buffer view ends 100 kB past the buffer

  std::string write(const std::string& name) const {
    std::vector<unsigned char> bin;
    auto put = [&](const void* p, size_t n) {
      const auto* b = static_cast<const unsigned char*>(p);
      bin.insert(bin.end(), b, b + n);
    };
    const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    put(pos, sizeof(pos));                                     // 0: 36 bytes
    const uint16_t joints[12] = {0, 0, 0, 0, 1, 0, 0, 0, bad_joint, 0, 0, 0};
    put(joints, sizeof(joints));                               // 36: 24 bytes
    const float weights[12] = {1, 0, 0, 0, weight0, 0, 0, 0, 1, 0, 0, 0};
    put(weights, sizeof(weights));                             // 60: 48 bytes
    float ibm[32] = {};
    for (int j = 0; j < 2; ++j)
      for (int d = 0; d < 4; ++d) ibm[j * 16 + d * 5] = 1.0f;
    put(ibm, sizeof(ibm));                                     // 108: 128 bytes
    const float times[2] = {0.0f, 1.0f};
    put(times, sizeof(times));                                 // 236: 8 bytes
    const float rot[8] = {0, 0, 0, 1, 0, 0, 1, 0};
    put(rot, sizeof(rot));                                     // 244: 32 bytes -> 276
    const size_t full = bin.size();
    if (truncate) bin.resize(100);
    const std::filesystem::path dir = farfield::test::scratchDir(name);
    std::ofstream(dir / "t.bin", std::ios::binary).write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
    std::string skin = inverse_bind ? R"({"joints": [1, 2], "inverseBindMatrices": 3})" : R"({"joints": [1, 2]})";
    const std::string json = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
 "nodes": [{"mesh": 0, "skin": 0}, {"children": [2]}, {"translation": [1, 0, 0]}],
 "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2})" +
                             std::string(image_past_buffer ? R"(, "material": 0)" : "") + R"(}]}],)" +
                             std::string(image_past_buffer ? R"(
 "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
 "textures": [{"source": 0}], "images": [{"bufferView": 6, "mimeType": "image/png"}],)" : "") + R"(
 "skins": [)" + skin + R"(],
 "animations": [{"name": "Walk", "channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}}],
   "samplers": [{"input": 4, "output": 5}]}],
 "buffers": [{"uri": "t.bin", "byteLength": )" + std::to_string(full) + R"(}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24},
   {"buffer": 0, "byteOffset": 60, "byteLength": 48}, {"buffer": 0, "byteOffset": 108, "byteLength": 128},
   {"buffer": 0, "byteOffset": 236, "byteLength": 8}, {"buffer": 0, "byteOffset": 244, "byteLength": 32},
   {"buffer": 0, "byteOffset": 200, "byteLength": 100000}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
   {"bufferView": 1, "componentType": 5123, "count": 3, "type": "VEC4"},
   {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC4"},
   {"bufferView": 3, "componentType": 5126, "count": 2, "type": "MAT4"},
   {"bufferView": 4, "componentType": 5126, "count": 2, "type": "SCALAR"},
   {"bufferView": 5, "componentType": 5126, "count": 2, "type": "VEC4"}]})";
    std::ofstream(dir / "t.gltf") << json;
    return (dir / "t.gltf").string();
  }
};

TEST(GltfSkin, ReadsTheHandWrittenSkin) {
  SkinImportStats stats;
  const SkinnedModel m = importSkinnedModel(TinySkin{}.write("skin_ok"), &stats);
  EXPECT_EQ(m.mesh.triangleCount(), 1u);
  ASSERT_EQ(m.skeleton.joints.size(), 2u);
  ASSERT_EQ(m.animations.size(), 1u);
  EXPECT_EQ(m.animations[0].name, "Walk");
  EXPECT_FLOAT_EQ(m.animations[0].duration, 1.0f);
  EXPECT_TRUE(stats.warnings().empty());
  // Joint 1 (node translated by x = 1) is the child of joint 0; its parent comes first.
  EXPECT_LT(m.skeleton.nodes[m.skeleton.joints[1]].parent, int(m.skeleton.joints[1]));
}

TEST(GltfSkin, JointIndexOutOfRangeIsAnError) {
  TinySkin t;
  t.bad_joint = 7;
  const std::string e = errorOf([&] { importSkinnedModel(t.write("skin_joint")); });
  EXPECT_NE(e.find("joint index 7"), std::string::npos) << e;
  EXPECT_NE(e.find("t.gltf"), std::string::npos) << e;
}

TEST(GltfSkin, NanWeightIsAnError) {
  TinySkin t;
  t.weight0 = std::numeric_limits<float>::quiet_NaN();
  const std::string e = errorOf([&] { importSkinnedModel(t.write("skin_nan")); });
  EXPECT_NE(e.find("vertex 1: weight 0"), std::string::npos) << e;
}

TEST(GltfSkin, WeightsNotSummingToOneAreRenormalisedAndCounted) {
  TinySkin t;
  t.weight0 = 0.5f;
  SkinImportStats stats;
  const SkinnedModel m = importSkinnedModel(t.write("skin_renorm"), &stats);
  EXPECT_EQ(stats.renormalised_vertices, 1u);
  EXPECT_FLOAT_EQ(m.weights[1].x, 1.0f);
  ASSERT_EQ(stats.warnings().size(), 1u);
}

TEST(GltfSkin, MissingInverseBindMatricesAreIdentityAndCounted) {
  TinySkin t;
  t.inverse_bind = false;
  SkinImportStats stats;
  const SkinnedModel m = importSkinnedModel(t.write("skin_noibm"), &stats);
  EXPECT_TRUE(stats.identity_inverse_bind);
  EXPECT_EQ(m.skeleton.inverse_bind[1], Mat4(1.0f));
}

// An image whose buffer view runs past its buffer (what the fuzzer found: the image callback read past the buffer):
// the model is read without its texture, with a warning, and nothing is read outside the buffer (make test-asan).
TEST(GltfSkin, ImageViewPastItsBufferLeavesTheTextureOut) {
  TinySkin t;
  t.image_past_buffer = true;
  const SkinnedModel m = importSkinnedModel(t.write("skin_image_view"));
  EXPECT_EQ(m.mesh.triangleCount(), 1u);
  EXPECT_FALSE(m.texture);
}

TEST(GltfSkin, TruncatedBufferIsAnError) {
  TinySkin t;
  t.truncate = true;
  const std::string e = errorOf([&] { importSkinnedModel(t.write("skin_trunc")); });
  EXPECT_NE(e.find("t.gltf"), std::string::npos) << e;
}

TEST(GltfSkin, ReadsTheRealModels) {
  FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
  FF_SHARED_FILE_OR_SKIP(fox_glb, "models/Fox.glb");
  const SkinnedModel man = importSkinnedModel(man_glb.string());
  EXPECT_EQ(man.mesh.triangleCount(), 4672u);
  EXPECT_EQ(man.skeleton.joints.size(), 19u);
  ASSERT_FALSE(man.animations.empty());
  EXPECT_GT(man.animations[0].duration, 0.5f);
  EXPECT_TRUE(man.texture);
  const SkinnedModel fox = importSkinnedModel(fox_glb.string());
  EXPECT_EQ(fox.mesh.triangleCount(), 576u);
  EXPECT_EQ(fox.animations.size(), 3u);
  EXPECT_NE(fox.animations[size_t(fox.findAnimation("walk"))].name.find("Walk"), std::string::npos);
  // The man stands about 1.5 m tall along Z once turned Z up (CesiumMan's units are metres).
  const Box3 b = animatedBounds(man, &man.animations[0], 4);
  EXPECT_GT(b.hi.z - b.lo.z, 1.2f);
  EXPECT_GT(b.hi.z - b.lo.z, b.hi.x - b.lo.x);
}

}  // namespace
}  // namespace farfield::scene

namespace farfield::scene {
namespace {

// Every truncation of a real skinned model (and a flipped byte in its JSON chunk) is a clear error naming the file,
// or a model that passes validation; never a crash.
TEST(GltfSkin, TruncatedAndCorruptedRealModelsFailCleanly) {
  FF_SHARED_FILE_OR_SKIP(src, "models/Fox.glb");
  std::ifstream in(src, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);
  const std::filesystem::path dir = farfield::test::scratchDir("skin_truncated");
  size_t errors = 0;
  for (int k = 1; k < 24; ++k) {
    const size_t n = bytes.size() * size_t(k) / 24;
    std::string name = "t";  // (not literal + string: GCC 12 warns falsely with -Wrestrict)
    name += std::to_string(k);
    name += ".glb";
    const std::string file = (dir / name).string();
    std::ofstream(file, std::ios::binary).write(bytes.data(), std::streamsize(n));
    const std::string e = errorOf([&] { importSkinnedModel(file); });
    EXPECT_NE(e.find(file), std::string::npos) << "cut at " << n << ": " << e;
    errors += e.empty() ? 0 : 1;
  }
  EXPECT_EQ(errors, 23u);
  for (size_t at : {size_t(30), size_t(200), size_t(600)}) {
    std::vector<char> flipped = bytes;
    flipped[at] = char(flipped[at] ^ 0x5a);
    std::string name = "f";
    name += std::to_string(at);
    name += ".glb";
    const std::string file = (dir / name).string();
    std::ofstream(file, std::ios::binary).write(flipped.data(), std::streamsize(flipped.size()));
    try {
      validateSkinnedModel(importSkinnedModel(file));
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace farfield::scene
