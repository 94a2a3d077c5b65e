#include "farfield/scene/export_gltf.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include <tiny_gltf.h>

#include "farfield/core/error.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/import.h"
#include "support/test_support.h"

namespace farfield::scene {
namespace {

void expectBoxNear(const Box3& a, const Box3& b, const std::string& what) {
  const float scale = std::max(1.0f, glm::length(b.extent()));
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(a.lo[i], b.lo[i], 1e-4f * scale) << what;
    EXPECT_NEAR(a.hi[i], b.hi[i], 1e-4f * scale) << what;
  }
}

// Builtin "cubes" plus an object with a rotated, translated, scaled transform that shares a mesh, a parent and an
// unlit, double-sided, translucent material.
Scene testScene() {
  Scene s = builtinScene("cubes");
  Material m;
  m.name = "glass";
  m.base_color = {0.2f, 0.4f, 0.6f, 0.5f};
  m.unlit = true;
  m.double_sided = true;
  m.texture = s.materials[0].texture;  // shared with the ground: written once
  Object o;
  o.name = "turned";
  o.parts = {{s.objects[3].parts[0].mesh, s.addMaterial(m)}};
  o.transform = glm::translate(Mat4(1.0f), Vec3(30, -5, 2)) *
                glm::rotate(Mat4(1.0f), 0.7f, glm::normalize(Vec3(1, 2, 3))) * glm::scale(Mat4(1.0f), Vec3(1, 2, 0.5f));
  o.parent = 2;
  o.footprint = {{29, -6}, {31, -6}, {30, -4}};
  s.addObject(o);
  return s;
}

// A .glb, or a .gltf with its buffer in a .bin beside it (scenes over a .glb's 4 GiB).
void expectRoundTrip(const std::string& path) {
  SCOPED_TRACE(path);
  const Scene src = testScene();
  exportGlb(src, path);
  const Scene back = importScene(path);
  EXPECT_NO_THROW(back.validate(path));

  EXPECT_EQ(back.triangleCount(), src.triangleCount());
  expectBoxNear(back.bounds(), src.bounds(), "scene bounds");
  ASSERT_EQ(back.objects.size(), src.objects.size());
  for (size_t i = 0; i < src.objects.size(); ++i) {
    const Object& a = src.objects[i];
    const Object& b = back.objects[i];
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.parent, a.parent) << a.name;
    expectBoxNear(b.world_bounds, a.world_bounds, a.name);
    ASSERT_EQ(b.footprint.size(), a.footprint.size()) << a.name;
    for (size_t k = 0; k < a.footprint.size(); ++k) EXPECT_NEAR(glm::distance(b.footprint[k], a.footprint[k]), 0.0f, 1e-5f);
    ASSERT_EQ(b.parts.size(), a.parts.size());
    const Material& ma = src.materials[a.parts[0].material];
    const Material& mb = back.materials[b.parts[0].material];
    EXPECT_NEAR(glm::distance(ma.base_color, mb.base_color), 0.0f, 1e-6f) << a.name;
    EXPECT_EQ(ma.unlit, mb.unlit);
    EXPECT_EQ(ma.double_sided, mb.double_sided);
    EXPECT_EQ(bool(ma.texture), bool(mb.texture));
    // Every world-space vertex comes back where it was (transforms converted to Y up and back).
    const Mesh& mesh_a = src.meshes[a.parts[0].mesh];
    const Mesh& mesh_b = back.meshes[b.parts[0].mesh];
    ASSERT_EQ(mesh_a.positions.size(), mesh_b.positions.size());
    for (size_t v = 0; v < mesh_a.positions.size(); ++v) {
      const Vec3 pa(a.transform * Vec4(mesh_a.positions[v], 1.0f)), pb(b.transform * Vec4(mesh_b.positions[v], 1.0f));
      EXPECT_NEAR(glm::distance(pa, pb), 0.0f, 1e-4f) << a.name << " vertex " << v;
      if (!mesh_a.uvs.empty()) {
        EXPECT_EQ(mesh_a.uvs[v], mesh_b.uvs[v]);
      }
    }
  }
  // The texture keeps its size and (PNG is lossless) its pixels, and is stored once.
  const auto& ta = *src.materials[0].texture;
  const Material& ground = back.materials[back.objects[0].parts[0].material];
  ASSERT_TRUE(ground.texture);
  EXPECT_EQ(ground.texture->width(), ta.width());
  EXPECT_EQ(ground.texture->height(), ta.height());
  EXPECT_EQ(ground.texture->pixels(), ta.pixels());
  EXPECT_EQ(back.stats().textures, 1u);
}

TEST(ExportGlb, RoundTripKeepsGeometryTexturesAndExtras) {
  expectRoundTrip((test::scratchDir("export_glb") / "cubes.glb").string());
}

TEST(ExportGltf, RoundTripThroughAJsonFileAndItsBuffer) {
  const auto dir = test::scratchDir("export_gltf");
  expectRoundTrip((dir / "cubes.gltf").string());
  EXPECT_EQ(gltfBufferPath((dir / "cubes.gltf").string()), (dir / "cubes.bin").string());
  EXPECT_GT(std::filesystem::file_size(dir / "cubes.bin"), 0u);
  std::ifstream json(dir / "cubes.gltf");
  const nlohmann::json j = nlohmann::json::parse(json);
  EXPECT_EQ(j["buffers"][0]["uri"].get<std::string>(), "cubes.bin");
  EXPECT_LE(j["buffers"][0]["byteLength"].get<uint64_t>(), std::filesystem::file_size(dir / "cubes.bin"));
}

// The builder under exportGlb, as the store's exporters use it: a subset of objects carries only what it draws; a free
// mesh gets its own material (alpha mask, clamped sampler, unlit without normals); nodes nest with extras.
TEST(GltfBuilder, SubsetsFreeMeshesAndNodes) {
  const Scene src = testScene();
  const auto dir = test::scratchDir("gltf_builder");
  const std::string path = (dir / "subset.glb").string();
  GltfBuilder builder(path);
  const uint32_t ids[] = {3, 2};
  builder.addObjects(src, ids);
  Mesh quad;
  quad.positions = {{0, 0, 5}, {4, 0, 5}, {4, 2, 5}, {0, 2, 5}};
  quad.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  Material m;
  m.name = "cutout";
  m.unlit = true;
  m.double_sided = true;
  m.texture = std::make_shared<image::ColorImage>(4, 2, image::Rgba8(255, 0, 0, 0));
  const int mesh = builder.addMesh(quad, m, {true, 0.5f, true}, "quad");
  const int group = builder.addNode("group", -1, -1, worldToGltf(), nlohmann::json{{"what", "a group"}});
  builder.addNode("quad node", mesh, group, Mat4(1.0f), nlohmann::json{{"n", 3}});
  EXPECT_EQ(builder.addMesh(Mesh{}, m, {}, "empty"), -1);
  EXPECT_THROW(builder.addObjects(src, std::vector<uint32_t>{99}), Error);
  EXPECT_THROW(builder.addNode("bad", 1000, -1, Mat4(1.0f), nullptr), Error);
  EXPECT_GT(builder.write(), 0u);

  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, path)) << err;
  // Objects 3 and 2 (in that order), the group and its child: roots are the two objects and the group.
  ASSERT_EQ(model.scenes[0].nodes.size(), 3u);
  EXPECT_EQ(model.nodes[size_t(model.scenes[0].nodes[0])].name, src.object(3).name);
  EXPECT_EQ(model.nodes[size_t(model.scenes[0].nodes[1])].name, src.object(2).name);
  const tinygltf::Node& g = model.nodes[size_t(model.scenes[0].nodes[2])];
  EXPECT_EQ(g.name, "group");
  EXPECT_EQ(g.extras.Get("what").Get<std::string>(), "a group");
  ASSERT_EQ(g.children.size(), 1u);
  const tinygltf::Node& q = model.nodes[size_t(g.children[0])];
  EXPECT_EQ(q.extras.Get("n").GetNumberAsInt(), 3);
  // Only the meshes and materials the two objects use, plus the quad's.
  std::set<std::pair<uint32_t, uint32_t>> used;
  for (uint32_t id : ids)
    for (const Part& p : src.object(id).parts) used.insert({p.mesh, p.material});
  std::set<uint32_t> used_materials;
  for (const auto& [mesh_index, material] : used) used_materials.insert(material);
  EXPECT_EQ(model.materials.size(), used_materials.size() + 1);
  const tinygltf::Material& cut = model.materials.back();
  EXPECT_EQ(cut.alphaMode, "MASK");
  EXPECT_DOUBLE_EQ(cut.alphaCutoff, 0.5);
  EXPECT_TRUE(cut.doubleSided);
  EXPECT_TRUE(cut.extensions.count("KHR_materials_unlit"));
  const tinygltf::Texture& tex = model.textures[size_t(cut.pbrMetallicRoughness.baseColorTexture.index)];
  EXPECT_EQ(model.samplers[size_t(tex.sampler)].wrapS, TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE);
  const tinygltf::Primitive& prim = model.meshes[size_t(q.mesh)].primitives[0];
  EXPECT_FALSE(prim.attributes.count("NORMAL"));  // unlit: none
  EXPECT_TRUE(prim.attributes.count("TEXCOORD_0"));
  // The quad's world points come back through the group's matrix and the importer's Y-up to Z-up turn.
  const Scene back = importScene(path);
  ASSERT_EQ(back.objects.size(), 3u);
  const Object& o = back.objects[2];
  const Mesh& bm = back.meshes[o.parts[0].mesh];
  for (size_t v = 0; v < quad.positions.size(); ++v)
    EXPECT_NEAR(glm::distance(Vec3(o.transform * Vec4(bm.positions[v], 1.0f)), quad.positions[v]), 0.0f, 1e-5f);
}

// The buffer is streamed from the scene's meshes at write(): every accessor must hold exactly the mesh's data, normals
// made unit length at write time (computed when a mesh has none), the chunk lengths must add up to the file's size,
// and a free mesh that is gone before write() must still be written (the builder copies it).
const unsigned char* accessorBytes(const tinygltf::Model& model, int accessor) {
  const tinygltf::BufferView& view = model.bufferViews[size_t(model.accessors[size_t(accessor)].bufferView)];
  return model.buffers[size_t(view.buffer)].data.data() + view.byteOffset;
}

TEST(GltfBuilder, StreamedBufferHoldsEveryMeshAsGiven) {
  Scene src;
  Material plain;
  plain.name = "plain";
  const uint32_t material = src.addMaterial(plain);
  Mesh scaled;  // normals of length 3 and one of length 0
  scaled.positions = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 1}};
  scaled.normals = {{0, 0, 3}, {0, 3, 0}, {3, 0, 0}, {0, 0, 0}};
  scaled.indices = {0, 1, 2, 0, 2, 3};
  Mesh bare;  // no normals: computed
  bare.positions = {{5, 0, 0}, {6, 0, 0}, {5, 1, 0}};
  bare.indices = {0, 1, 2};
  for (const Mesh* m : {&scaled, &bare}) {
    Object o;
    o.name = m == &scaled ? "scaled" : "bare";
    o.parts = {{src.addMesh(*m), material}};
    src.addObject(o);
  }
  const std::string path = (test::scratchDir("gltf_streamed") / "streamed.glb").string();
  GltfBuilder builder(path);
  builder.addObjects(src);
  {
    Mesh gone;
    gone.positions = {{0, 0, 9}, {1, 0, 9}, {0, 1, 9}};
    gone.indices = {0, 2, 1};
    builder.addMesh(gone, plain, {}, "gone");
  }
  const size_t written = builder.write();
  EXPECT_EQ(written, std::filesystem::file_size(path));

  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, path)) << err;
  ASSERT_EQ(model.buffers.size(), 1u);
  ASSERT_EQ(model.meshes.size(), 3u);
  Mesh expected_gone;
  expected_gone.positions = {{0, 0, 9}, {1, 0, 9}, {0, 1, 9}};
  expected_gone.indices = {0, 2, 1};
  const std::vector<std::vector<Vec3>> expected_normals = {
      {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}}, {{0, 0, -1}, {0, 0, -1}, {0, 0, -1}}};
  const Mesh* meshes[] = {&src.meshes[0], &src.meshes[1], &expected_gone};
  for (size_t i = 0; i < 3; ++i) {
    const tinygltf::Primitive& prim = model.meshes[i].primitives.at(0);
    const Mesh& m = *meshes[i];
    const auto* positions = reinterpret_cast<const Vec3*>(accessorBytes(model, prim.attributes.at("POSITION")));
    const auto* normals = reinterpret_cast<const Vec3*>(accessorBytes(model, prim.attributes.at("NORMAL")));
    const auto* indices = reinterpret_cast<const uint32_t*>(accessorBytes(model, prim.indices));
    ASSERT_EQ(model.accessors[size_t(prim.indices)].count, m.indices.size());
    for (size_t v = 0; v < m.positions.size(); ++v) {
      EXPECT_EQ(positions[v], m.positions[v]) << "mesh " << i << " vertex " << v;
      EXPECT_NEAR(glm::distance(normals[v], expected_normals[i][v]), 0.0f, 1e-6f) << "mesh " << i << " vertex " << v;
    }
    for (size_t k = 0; k < m.indices.size(); ++k) EXPECT_EQ(indices[k], m.indices[k]) << "mesh " << i;
  }
}

TEST(ExportGlb, TruncatedFileGivesError) {
  const auto dir = test::scratchDir("export_glb_truncated");
  const std::string good = (dir / "cube.glb").string();
  exportGlb(builtinScene("cubes"), good);
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);
  for (size_t cut : {bytes.size() / 2, size_t(10), size_t(30), bytes.size() - 1}) {
    const std::string path = (dir / ("cut_" + std::to_string(cut) + ".glb")).string();
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(cut));
    try {
      importScene(path);
      ADD_FAILURE() << "cut at " << cut << ": expected farfield::Error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

TEST(ExportGlb, UnwritablePathGivesError) {
  const std::string path = (test::scratchDir("export_glb_bad") / "no_dir" / "x.glb").string();
  try {
    exportGlb(builtinScene("cube"), path);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("x.glb"), std::string::npos);
  }
}

}  // namespace
}  // namespace farfield::scene
