#include "farfield/scene/scene.h"

#include <gtest/gtest.h>

#include <set>

#include "farfield/core/error.h"
#include "farfield/scene/builtin.h"

namespace farfield::scene {
namespace {

// World bounds by transforming every vertex: independent of transformBox and of cached mesh bounds.
Box3 bruteForceBounds(const Scene& s, const Object& o) {
  Box3 b;
  for (const Part& p : o.parts)
    for (const Vec3& v : s.meshes[p.mesh].positions) b.expand(Vec3(o.transform * Vec4(v, 1.0f)));
  return b;
}

TEST(Scene, IdsAndWorldBounds) {
  Scene s;
  const uint32_t mesh = s.addMesh(makeUnitCube());
  const uint32_t mat = s.addMaterial(Material{});
  Object a;
  a.parts.push_back({mesh, mat});
  a.transform = glm::translate(Mat4(1.0f), Vec3(5, 0, 0));
  Object b = a;
  b.transform = glm::rotate(Mat4(1.0f), float(kPi / 4), Vec3(0, 0, 1));
  EXPECT_EQ(s.addObject(a), 1u);
  EXPECT_EQ(s.addObject(b), 2u);
  EXPECT_EQ(s.object(2).id, 2u);
  EXPECT_EQ(s.object(1).world_bounds.lo, Vec3(4.5f, -0.5f, -0.5f));
  EXPECT_EQ(s.object(1).world_bounds.hi, Vec3(5.5f, 0.5f, 0.5f));
  // A unit cube turned 45 degrees about z reaches sqrt(2)/2 in x and y.
  const float r = std::sqrt(2.0f) / 2.0f;
  EXPECT_NEAR(s.object(2).world_bounds.hi.x, r, 1e-5f);
  EXPECT_NEAR(s.object(2).world_bounds.lo.y, -r, 1e-5f);
  EXPECT_NEAR(s.object(2).world_bounds.hi.z, 0.5f, 1e-5f);
  EXPECT_NEAR(s.bounds().hi.x, 5.5f, 1e-6f);
  EXPECT_NEAR(s.bounds().lo.x, -r, 1e-5f);
  // Instanced: both objects count the shared mesh.
  EXPECT_EQ(s.triangleCount(), 24u);
  EXPECT_NO_THROW(s.validate("two"));

  // Moving a mesh and updating keeps world bounds current.
  for (Vec3& p : s.meshes[0].positions) p.z += 10.0f;
  s.updateBounds();
  EXPECT_NEAR(s.object(1).world_bounds.lo.z, 9.5f, 1e-6f);
}

TEST(Scene, CubesStats) {
  const Scene s = builtinScene("cubes");
  const SceneStats st = s.stats();
  EXPECT_EQ(st.objects, 26u);  // ground + 5 x 5 boxes
  EXPECT_EQ(st.triangles, 2u + 25u * 12u);
  EXPECT_EQ(st.textures, 1u);
  ASSERT_TRUE(s.materials[0].texture);
  EXPECT_EQ(st.texture_bytes, size_t(s.materials[0].texture->width()) * s.materials[0].texture->height() * 4);
  size_t bytes = 0, verts = 0;
  for (const Mesh& m : s.meshes) bytes += m.positions.size() * 32 + m.indices.size() * 4;
  for (const Object& o : s.objects)
    for (const Part& p : o.parts) verts += s.meshes[p.mesh].positions.size();
  EXPECT_EQ(st.geometry_bytes, bytes);
  EXPECT_EQ(st.vertices, verts);
  Box3 all;
  for (const Object& o : s.objects) {
    const Box3 b = bruteForceBounds(s, o);
    EXPECT_EQ(o.world_bounds.lo, b.lo) << o.name;
    EXPECT_EQ(o.world_bounds.hi, b.hi) << o.name;
    all.expand(b);
  }
  EXPECT_EQ(st.bounds.lo, all.lo);
  EXPECT_EQ(st.bounds.hi, all.hi);
  EXPECT_EQ(st.bounds.lo.z, 0.0f);
  // Varied heights: at least three distinct box heights.
  std::set<float> heights;
  for (size_t i = 1; i < s.objects.size(); ++i) heights.insert(s.objects[i].world_bounds.hi.z);
  EXPECT_GE(heights.size(), 3u);
  EXPECT_NO_THROW(s.validate("builtin:cubes"));
}

TEST(Scene, BuiltinCube) {
  const Scene s = builtinScene("cube");
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.triangleCount(), 12u);
  EXPECT_EQ(s.bounds().lo, Vec3(-0.5f));
  EXPECT_EQ(s.bounds().hi, Vec3(0.5f));
  EXPECT_EQ(s.materials[s.objects[0].parts[0].material].base_color, Vec4(1, 0, 0, 1));
  EXPECT_THROW(builtinScene("nope"), Error);
  EXPECT_EQ(builtinSceneNames().size(), 2u);
}

TEST(Scene, ValidateRejectsDanglingParts) {
  Scene s = builtinScene("cube");
  s.objects[0].parts[0].material = 7;
  try {
    s.validate("bad.glb");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.glb"), std::string::npos);
  }
  Scene t = builtinScene("cube");
  t.objects[0].id = 3;
  EXPECT_THROW(t.validate("ids"), Error);
}

}  // namespace
}  // namespace farfield::scene
