#include "farfield/scene/import.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "support/test_support.h"

namespace farfield::scene {
namespace {

// Runs f, expects a farfield::Error whose message contains every one of `needles`.
template <class F>
void expectError(F&& f, const std::vector<std::string>& needles) {
  try {
    f();
    ADD_FAILURE() << "expected farfield::Error";
  } catch (const Error& e) {
    for (const std::string& n : needles)
      EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << "'" << n << "' not in: " << e.what();
  }
}

const Object* findObject(const Scene& s, const std::string& name) {
  for (const Object& o : s.objects)
    if (o.name == name) return &o;
  return nullptr;
}

// The placeholder, checked texel by texel against its definition: 64 x 64, 8-texel squares alternating between
// two opaque colours (magenta at the top left), so it shows on any surface.
void expectCheckerboard(const std::shared_ptr<const image::ColorImage>& t) {
  ASSERT_TRUE(t);
  ASSERT_EQ(t->width(), 64);
  ASSERT_EQ(t->height(), 64);
  const image::Rgba8 a = t->at(0, 0), b = t->at(8, 0);
  EXPECT_EQ(a, image::Rgba8(255, 0, 255, 255));
  EXPECT_NE(a, b);
  EXPECT_EQ(b.a, 255);
  // Far apart in every channel sum, so the squares are visible under any lighting.
  EXPECT_GT(std::abs(int(a.r) + a.g + a.b - (int(b.r) + b.g + b.b)), 300);
  int mismatches = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) mismatches += t->at(x, y) != (((x / 8) % 2) == ((y / 8) % 2) ? a : b);
  EXPECT_EQ(mismatches, 0);
}

const ImportStats::MissingTexture* findMissing(const ImportStats& st, const std::string& name) {
  for (const auto& m : st.missing_textures)
    if (m.name == name) return &m;
  return nullptr;
}

TEST(Import, TexturedObjWithMtl) {
  const std::string path = (test::testDataDir() / "scene" / "textured_quad.obj").string();
  const Scene s = importScene(path);
  EXPECT_NO_THROW(s.validate(path));
  EXPECT_EQ(s.triangleCount(), 3u);  // the quad is triangulated into two
  const Object* quad = findObject(s, "quad");
  const Object* tri = findObject(s, "tri");
  ASSERT_TRUE(quad && tri);
  ASSERT_EQ(quad->parts.size(), 1u);

  // Y up in the file: (x, y, z) -> (x, -z, y). The quad spans x 0..2, y 0..1 at z 0 in the file.
  EXPECT_NEAR(glm::distance(quad->world_bounds.lo, Vec3(0, 0, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::distance(quad->world_bounds.hi, Vec3(2, 0, 1)), 0.0f, 1e-6f);
  // The triangle at file z = -1 spans file y 0..3: world y = 1, z 0..3.
  EXPECT_NEAR(glm::distance(tri->world_bounds.lo, Vec3(0, 1, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::distance(tri->world_bounds.hi, Vec3(1, 1, 3)), 0.0f, 1e-6f);

  // Winding survives: the file's front face looks along +z (file), which is -y in the world.
  const Mesh& qm = s.meshes[quad->parts[0].mesh];
  for (size_t t = 0; t < qm.triangleCount(); ++t) {
    Vec3 p[3];
    for (int k = 0; k < 3; ++k) p[k] = Vec3(quad->transform * Vec4(qm.positions[qm.indices[3 * t + k]], 1.0f));
    const Vec3 n = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
    EXPECT_NEAR(n.y, -1.0f, 1e-5f);
  }

  // Texture: the 4 x 2 PNG, row 0 at the top (red, green, blue, white), row 1 (black, yellow, cyan, magenta).
  const Material& mat = s.materials[quad->parts[0].material];
  ASSERT_TRUE(mat.texture);
  ASSERT_EQ(mat.texture->width(), 4);
  ASSERT_EQ(mat.texture->height(), 2);
  EXPECT_EQ(mat.texture->at(0, 0), image::Rgba8(255, 0, 0, 255));
  EXPECT_EQ(mat.texture->at(1, 1), image::Rgba8(255, 255, 0, 255));
  EXPECT_NE(mat.texture_path.find("textured_quad.png"), std::string::npos);
  // uvs use the top-left origin: the file's vt (0, 0) (bottom-left of the image in OBJ) comes out as (0, 1).
  ASSERT_EQ(qm.uvs.size(), qm.positions.size());
  bool found_origin = false;
  for (size_t i = 0; i < qm.positions.size(); ++i)
    if (glm::length(qm.positions[i]) < 1e-6f) {
      found_origin = true;
      EXPECT_NEAR(qm.uvs[i].x, 0.0f, 1e-6f);
      EXPECT_NEAR(qm.uvs[i].y, 1.0f, 1e-6f);
    }
  EXPECT_TRUE(found_origin);

  const Material& plain = s.materials[tri->parts[0].material];
  EXPECT_FALSE(plain.texture);
  EXPECT_NEAR(plain.base_color.r, 0.5f, 1e-6f);
  EXPECT_NEAR(plain.base_color.g, 0.25f, 1e-6f);
  EXPECT_NEAR(plain.base_color.b, 1.0f, 1e-6f);
  // Normals were generated for the triangle (no vn in the file) and are unit length.
  const Mesh& tm = s.meshes[tri->parts[0].mesh];
  ASSERT_EQ(tm.normals.size(), tm.positions.size());
  for (const Vec3& n : tm.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
}

// A hand-written .gltf with an external buffer and an external texture next to it.
std::string writeGltf(const std::filesystem::path& dir, const std::string& image_uri, const std::string& extra_node = "") {
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::ofstream(dir / "tri.bin", std::ios::binary).write(reinterpret_cast<const char*>(pos), sizeof(pos));
  const std::string path = (dir / "tri.gltf").string();
  std::ofstream(path) << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"name": "n", "translation": [0, 0, -5], "mesh": 0)" << extra_node << R"(}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
    "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "baseColorTexture": {"index": 0}}}],
    "textures": [{"source": 0}], "images": [{"uri": ")" << image_uri << R"("}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "buffers": [{"uri": "tri.bin", "byteLength": 36}]})";
  return path;
}

TEST(Import, GltfWithExternalBufferAndTexture) {
  const auto dir = test::scratchDir("import_gltf");
  std::filesystem::copy_file(test::testDataDir() / "scene" / "textured_quad.png", dir / "tex.png");
  const Scene s = importScene(writeGltf(dir, "tex.png"));
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].name, "n");
  EXPECT_EQ(s.triangleCount(), 1u);
  // glTF is Y up: the file's (x, y, z) + (0, 0, -5) lands at world (x, 5, y).
  EXPECT_NEAR(glm::distance(s.bounds().lo, Vec3(0, 5, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::distance(s.bounds().hi, Vec3(1, 5, 1)), 0.0f, 1e-6f);
  const Material& m = s.materials[s.objects[0].parts[0].material];
  ASSERT_TRUE(m.texture);
  EXPECT_EQ(m.texture->width(), 4);
  EXPECT_EQ(m.texture->at(3, 0), image::Rgba8(255, 255, 255, 255));
  EXPECT_EQ(m.base_color, Vec4(0.5f, 0.5f, 0.5f, 1.0f));

  // The same file naming a texture that is not there: a counted warning and the placeholder, the rest imported.
  const auto dir2 = test::scratchDir("import_gltf_missing");
  ImportStats st;
  const Scene missing = importScene(writeGltf(dir2, "gone.png"), {}, &st);
  EXPECT_EQ(missing.triangleCount(), 1u);
  ASSERT_EQ(st.missing_textures.size(), 1u);
  EXPECT_EQ(st.missing_textures[0].name, "gone.png");
  EXPECT_NE(st.missing_textures[0].reason.find("gone.png"), std::string::npos) << st.missing_textures[0].reason;
  EXPECT_EQ(st.placeholder_materials, 1u);
  expectCheckerboard(missing.materials[missing.objects[0].parts[0].material].texture);
  ASSERT_EQ(st.warnings().size(), 2u);
  EXPECT_EQ(st.warnings()[0].rfind("1 texture missing", 0), 0u) << st.warnings()[0];
  EXPECT_NE(st.warnings()[0].find("gone.png"), std::string::npos);
  // An embedded image whose bytes are no image: the same.
  ImportStats st_bad;
  const Scene undecodable = importScene(writeGltf(dir2, "data:image/png;base64,bm90IGFuIGltYWdl"), {}, &st_bad);
  ASSERT_EQ(st_bad.missing_textures.size(), 1u);
  EXPECT_EQ(st_bad.missing_textures[0].name, "image 0");
  EXPECT_NE(st_bad.missing_textures[0].reason.find("cannot decode"), std::string::npos);
  expectCheckerboard(undecodable.materials[undecodable.objects[0].parts[0].material].texture);
  // And one whose node is its own child is still an error.
  const auto dir3 = test::scratchDir("import_gltf_cycle");
  std::filesystem::copy_file(dir / "tex.png", dir3 / "tex.png");
  expectError([&] { importScene(writeGltf(dir3, "tex.png", R"(, "children": [0])")); }, {"tri.gltf", "reached twice"});
}

// A hand-written .gltf whose texture is a PNG in a buffer view of its external buffer; the view claims `extra` bytes
// more than the image has (past the buffer's end when extra > 0).
std::string writeGltfImageInView(const std::filesystem::path& dir, size_t extra) {
  std::ifstream png(test::testDataDir() / "scene" / "textured_quad.png", std::ios::binary);
  const std::vector<char> image((std::istreambuf_iterator<char>(png)), std::istreambuf_iterator<char>());
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::ofstream bin(dir / "tri.bin", std::ios::binary);
  bin.write(reinterpret_cast<const char*>(pos), sizeof(pos));
  bin.write(image.data(), std::streamsize(image.size()));
  bin.close();
  const std::string path = (dir / "tri.gltf").string();
  std::ofstream(path) << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"name": "n", "mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
    "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
    "textures": [{"source": 0}], "images": [{"bufferView": 1, "mimeType": "image/png"}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]}],
    "bufferViews": [{"buffer": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": )" << image.size() + extra << R"(}],
    "buffers": [{"uri": "tri.bin", "byteLength": )" << 36 + image.size() << R"(}]})";
  return path;
}

// An image in a buffer view is read through the view, checked against its buffer: a view past the buffer's end (a
// corrupt file; the fuzzer's glTF skin input made the image callback read past the buffer) is a counted missing
// texture naming the image and the bytes, not a read outside the buffer.
TEST(Import, GltfImageInABufferViewIsCheckedAgainstItsBuffer) {
  const auto dir = test::scratchDir("import_gltf_view_image");
  ImportStats st;
  const Scene s = importScene(writeGltfImageInView(dir, 0), {}, &st);
  const Material& m = s.materials[s.objects[0].parts[0].material];
  ASSERT_TRUE(m.texture);
  EXPECT_FALSE(TextureFiles::isPlaceholder(m.texture));
  EXPECT_EQ(m.texture->width(), 4);
  EXPECT_TRUE(st.missing_textures.empty());

  const auto dir2 = test::scratchDir("import_gltf_view_past_buffer");
  ImportStats st2;
  const Scene past = importScene(writeGltfImageInView(dir2, 100000), {}, &st2);
  EXPECT_EQ(past.triangleCount(), 1u);
  ASSERT_EQ(st2.missing_textures.size(), 1u);
  EXPECT_EQ(st2.missing_textures[0].name, "image 0");
  EXPECT_NE(st2.missing_textures[0].reason.find("past the buffer"), std::string::npos) << st2.missing_textures[0].reason;
  expectCheckerboard(past.materials[past.objects[0].parts[0].material].texture);
}

TEST(Import, ZUpFileKeepsCoordinates) {
  const auto dir = test::scratchDir("import_zup");
  const std::string path = (dir / "tri.ply").string();
  std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                         "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                         "0 0 5\n4 0 5\n0 2 7\n3 0 1 2\n";
  ImportOptions opt;
  opt.up_axis = 'z';
  const Scene s = importScene(path, opt);
  EXPECT_EQ(s.triangleCount(), 1u);
  EXPECT_NEAR(glm::distance(s.bounds().lo, Vec3(0, 0, 5)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::distance(s.bounds().hi, Vec3(4, 2, 7)), 0.0f, 1e-6f);
}

TEST(Import, MalformedInputsNameTheFile) {
  const auto data = test::testDataDir() / "scene";
  expectError([&] { importScene((data / "nan_vertex.obj").string()); },
              {"nan_vertex.obj", "vertex 2", "non-finite coordinate"});
  expectError([&] { importScene((data / "no_such_model.obj").string()); }, {"no_such_model.obj", "not found"});

  const auto dir = test::scratchDir("import_malformed");
  const std::string xyz = (dir / "points.xyz").string();
  std::ofstream(xyz) << "1 2 3\n";
  expectError([&] { importScene(xyz); }, {"points.xyz", "unknown scene format '.xyz'", ".obj", ".glb"});

  // Bytes that are no OBJ at all, and an OBJ with no faces.
  const std::string garbage = (dir / "garbage.glb").string();
  std::ofstream(garbage, std::ios::binary) << std::string("glTF\x02\x00\x00\x00garbage", 15);
  expectError([&] { importScene(garbage); }, {"garbage.glb"});
  const std::string empty = (dir / "empty.obj").string();
  std::ofstream(empty) << "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expectError([&] { importScene(empty); }, {"empty.obj"});
  const std::string lines = (dir / "lines.obj").string();
  std::ofstream(lines) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n";
  expectError([&] { importScene(lines); }, {"lines.obj", "no triangles"});
  // A quad and a two-vertex face in one mesh: the quad is kept, the line skipped.
  const std::string mixed = (dir / "mixed.obj").string();
  std::ofstream(mixed) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\nf 1 2\n";
  EXPECT_EQ(importScene(mixed).triangleCount(), 2u);

  // A truncated AC3D file (the last surface's references cut off) is corrupt model data: an error naming it.
  std::ifstream full(data / "textured_box.ac");
  std::string text((std::istreambuf_iterator<char>(full)), std::istreambuf_iterator<char>());
  const std::string cut = (dir / "cut.ac").string();
  std::ofstream(cut) << text.substr(0, text.rfind("refs 4") + 8);
  expectError([&] { importScene(cut); }, {"cut.ac"});
}

// Missing or unreadable textures are counted warnings with a checkerboard in their place, never a failed import.
TEST(Import, MissingTexturesBecomeCountedPlaceholders) {
  const auto data = test::testDataDir() / "scene";
  // OBJ whose material names a file that is not there.
  ImportStats st;
  const Scene obj = importScene((data / "missing_texture.obj").string(), {}, &st);
  EXPECT_EQ(obj.triangleCount(), 1u);
  ASSERT_EQ(st.missing_textures.size(), 1u);
  EXPECT_EQ(st.missing_textures[0].name, "does_not_exist.png");
  EXPECT_NE(st.missing_textures[0].reason.find("no file"), std::string::npos) << st.missing_textures[0].reason;
  EXPECT_EQ(st.placeholder_materials, 1u);
  const Material& m = obj.materials[obj.objects[0].parts[0].material];
  expectCheckerboard(m.texture);
  EXPECT_TRUE(TextureFiles::isPlaceholder(m.texture));
  EXPECT_TRUE(m.texture_path.empty());  // not from a file

  // A texture that exists but is not an image, named by two materials: one file missing, two placeholders.
  const auto dir = test::scratchDir("import_bad_texture");
  std::ofstream(dir / "bad.png") << "not a png";
  std::ofstream(dir / "bad_tex.mtl") << "newmtl m\nmap_Kd bad.png\nnewmtl n\nKd 1 0 0\nmap_Kd bad.png\n";
  const std::string bad_tex = (dir / "bad_tex.obj").string();
  std::ofstream(bad_tex) << "mtllib bad_tex.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\no a\nusemtl m\n"
                            "f 1/1 2/1 3/1\no b\nusemtl n\nf 2/1 4/1 3/1\n";
  ImportStats st2;
  const Scene bad = importScene(bad_tex, {}, &st2);
  EXPECT_EQ(bad.triangleCount(), 2u);
  ASSERT_EQ(st2.missing_textures.size(), 1u);
  EXPECT_EQ(st2.missing_textures[0].name, "bad.png");
  EXPECT_NE(st2.missing_textures[0].reason.find("cannot decode"), std::string::npos) << st2.missing_textures[0].reason;
  EXPECT_EQ(st2.placeholder_materials, 2u);
  for (const Object& o : bad.objects) expectCheckerboard(bad.materials[o.parts[0].material].texture);
  // Without stats the import still succeeds (the warnings go to the log).
  EXPECT_EQ(importScene(bad_tex).triangleCount(), 2u);
}

// AC3D (the TORCS track format): one texture found, one missing, one object with TORCS's four texture lines.
TEST(Import, Ac3dTexturesMissingAndMultiTextured) {
  const std::string path = (test::testDataDir() / "scene" / "textured_box.ac").string();
  ImportStats st;
  const Scene s = importScene(path, {}, &st);
  EXPECT_NO_THROW(s.validate(path));
  EXPECT_EQ(s.triangleCount(), 2u + 1u + 2u);
  const Object* wall = findObject(s, "wall");
  const Object* lost = findObject(s, "lost");
  const Object* track = findObject(s, "track");
  ASSERT_TRUE(wall && lost && track);
  // The found texture is the 4 x 2 PNG; the track keeps its first (base) texture line, the same file.
  for (const Object* o : {wall, track}) {
    const Material& m = s.materials[o->parts[0].material];
    ASSERT_TRUE(m.texture);
    ASSERT_EQ(m.texture->width(), 4);
    EXPECT_EQ(m.texture->at(0, 0), image::Rgba8(255, 0, 0, 255));
    EXPECT_NE(m.texture_path.find("textured_quad.png"), std::string::npos);
  }
  expectCheckerboard(s.materials[lost->parts[0].material].texture);
  // One file missing (the other texture lines of the track are not used, so not reported), one AC3D object with
  // extra texture lines.
  ASSERT_EQ(st.missing_textures.size(), 1u);
  EXPECT_TRUE(findMissing(st, "no_such_texture.png"));
  EXPECT_FALSE(findMissing(st, "ERROR"));
  EXPECT_EQ(st.placeholder_materials, 1u);
  EXPECT_EQ(st.extra_ac3d_textures, 1u);
  const std::vector<std::string> w = st.warnings();
  ASSERT_EQ(w.size(), 3u);
  EXPECT_NE(w[0].find("1 texture missing"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("no_such_texture.png"), std::string::npos) << w[0];
  EXPECT_NE(w[2].find("1 AC3D objects"), std::string::npos) << w[2];
  // AC3D is Y up: the wall spans file x 0..2, y 0..1 at z 0 -> world x 0..2, z 0..1.
  EXPECT_NEAR(glm::distance(wall->world_bounds.hi, Vec3(2, 0, 1)), 0.0f, 1e-6f);
}

TEST(Import, WarningsNameTheFirstFilesAndCountTheRest) {
  ImportStats st;
  for (char i = '0'; i < '8'; ++i) st.missing_textures.push_back({std::string("t") + i + ".png", "no file"});
  st.placeholder_materials = 11;
  const std::vector<std::string> w = st.warnings(3);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_EQ(w[0], "8 textures missing or unreadable (checkerboard placeholders on 11 materials): t0.png, t1.png, "
                  "t2.png, ... and 5 more");
  EXPECT_TRUE(ImportStats().warnings().empty());
  ImportStats other;
  other.missing_textures = {{"t1.png", "no file"}, {"u.png", "no file"}};
  other.placeholder_materials = 2;
  st.merge(other);
  EXPECT_EQ(st.missing_textures.size(), 9u);
  EXPECT_EQ(st.placeholder_materials, 13u);
}

TEST(Import, LoadSceneSpecs) {
  EXPECT_EQ(loadScene("builtin:cube").triangleCount(), 12u);
  EXPECT_THROW(loadScene("builtin:nope"), Error);
  const std::string path = (test::testDataDir() / "scene" / "textured_quad.obj").string();
  EXPECT_EQ(loadScene(path).triangleCount(), 3u);
}

}  // namespace
}  // namespace farfield::scene
