#include "farfield/scene/mesh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "farfield/core/error.h"
#include "farfield/scene/builtin.h"

namespace farfield::scene {
namespace {

Vec3 triangleNormal(const Mesh& m, size_t t) {
  const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
             c = m.positions[m.indices[3 * t + 2]];
  return glm::normalize(glm::cross(b - a, c - a));
}

Vec3 triangleCentroid(const Mesh& m, size_t t) {
  return (m.positions[m.indices[3 * t]] + m.positions[m.indices[3 * t + 1]] + m.positions[m.indices[3 * t + 2]]) /
         3.0f;
}

TEST(Mesh, BoxBoundsAndCounts) {
  const Mesh box = makeBox({1, 2, 3}, {4, 6, 8});
  EXPECT_EQ(box.triangleCount(), 12u);
  EXPECT_EQ(box.vertexCount(), 24u);
  EXPECT_EQ(box.bounds.lo, Vec3(1, 2, 3));
  EXPECT_EQ(box.bounds.hi, Vec3(4, 6, 8));
  // Every position lies on the surface of the box.
  for (const Vec3& p : box.positions) {
    int on_face = 0;
    for (int a = 0; a < 3; ++a) on_face += (p[a] == box.bounds.lo[a] || p[a] == box.bounds.hi[a]);
    EXPECT_EQ(on_face, 3) << "box corners only";
  }
  EXPECT_NO_THROW(box.validate("box"));
}

TEST(Mesh, BoxFacesPointOutward) {
  const Vec3 lo(-1, 0, 2), hi(3, 1, 7);
  const Mesh box = makeBox(lo, hi);
  const Vec3 center = (lo + hi) * 0.5f;
  int per_axis_dir[6] = {};
  for (size_t t = 0; t < box.triangleCount(); ++t) {
    const Vec3 n = triangleNormal(box, t);
    const Vec3 outward = triangleCentroid(box, t) - center;
    // Counter-clockwise winding seen from outside: the geometric normal points away from the centre, along an axis.
    EXPECT_GT(glm::dot(n, outward), 0.0f) << "triangle " << t;
    int axis = -1;
    for (int a = 0; a < 3; ++a)
      if (std::abs(n[a]) > 0.999f) axis = a;
    ASSERT_GE(axis, 0) << "triangle " << t << " not axis aligned";
    per_axis_dir[axis * 2 + (n[axis] > 0 ? 1 : 0)]++;
    // The stored vertex normals agree with the geometry.
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(glm::dot(box.normals[box.indices[3 * t + k]], n), 1.0f, 1e-5f);
    // Per-face uvs span 0..1.
    for (int k = 0; k < 3; ++k) {
      const Vec2 uv = box.uvs[box.indices[3 * t + k]];
      EXPECT_TRUE((uv.x == 0.0f || uv.x == 1.0f) && (uv.y == 0.0f || uv.y == 1.0f));
    }
  }
  for (int d = 0; d < 6; ++d) EXPECT_EQ(per_axis_dir[d], 2) << "two triangles per face";
}

TEST(Mesh, SphereAndGroundFacesPointOutward) {
  const Mesh sphere = makeSphere(2.0f, 12, 6);
  ASSERT_GT(sphere.triangleCount(), 0u);
  for (size_t t = 0; t < sphere.triangleCount(); ++t)
    EXPECT_GT(glm::dot(triangleNormal(sphere, t), triangleCentroid(sphere, t)), 0.0f) << "triangle " << t;
  for (const Vec3& p : sphere.positions) EXPECT_NEAR(glm::length(p), 2.0f, 1e-5f);
  EXPECT_NO_THROW(sphere.validate("sphere"));

  const Mesh ground = makeGroundQuad({-3, -2}, {5, 4}, 2.0f);
  EXPECT_EQ(ground.triangleCount(), 2u);
  for (size_t t = 0; t < 2; ++t) EXPECT_NEAR(triangleNormal(ground, t).z, 1.0f, 1e-6f);
  EXPECT_EQ(ground.bounds.lo, Vec3(-3, -2, 0));
  EXPECT_EQ(ground.bounds.hi, Vec3(5, 4, 0));
  // 8 m wide at 2 m per repeat: u spans 4.
  float umin = 1e9f, umax = -1e9f;
  for (const Vec2& uv : ground.uvs) umin = std::min(umin, uv.x), umax = std::max(umax, uv.x);
  EXPECT_FLOAT_EQ(umax - umin, 4.0f);
}

TEST(Mesh, ComputeNormalsIsAreaWeighted) {
  // Vertex 0 is shared by a triangle of area 2 in the z = 0 plane (normal +z) and one of area 0.5 in the x = 0
  // plane (normal +x): its normal is (0.5, 0, 2) normalised.
  Mesh m;
  m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 1, 0}, {0, 0, 1}};
  m.indices = {0, 1, 2, 0, 3, 4};
  m.computeNormals();
  ASSERT_EQ(m.normals.size(), 5u);
  const Vec3 expected = glm::normalize(Vec3(0.5f, 0.0f, 2.0f));
  EXPECT_NEAR(glm::distance(m.normals[0], expected), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::distance(m.normals[1], Vec3(0, 0, 1)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::distance(m.normals[4], Vec3(1, 0, 0)), 0.0f, 1e-6f);
}

TEST(Mesh, AppendTransformsAndKeepsWinding) {
  Mesh m = makeBox(Vec3(0), Vec3(1));
  // A mirror in x: the appended box must still face outward.
  const Mat4 mirror = glm::scale(glm::translate(Mat4(1.0f), Vec3(10, 0, 0)), Vec3(-1, 1, 1));
  m.append(makeBox(Vec3(0), Vec3(1)), mirror);
  EXPECT_EQ(m.triangleCount(), 24u);
  EXPECT_EQ(m.vertexCount(), 48u);
  EXPECT_EQ(m.bounds.lo, Vec3(0, 0, 0));
  EXPECT_EQ(m.bounds.hi, Vec3(10, 1, 1));
  const Vec3 c2(9.5f, 0.5f, 0.5f);
  for (size_t t = 12; t < 24; ++t) {
    const Vec3 n = triangleNormal(m, t);
    EXPECT_GT(glm::dot(n, triangleCentroid(m, t) - c2), 0.0f) << "triangle " << t;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(glm::dot(m.normals[m.indices[3 * t + k]], n), 1.0f, 1e-5f);
  }
  EXPECT_NO_THROW(m.validate("appended"));
  EXPECT_EQ(m.byteSize(), 48u * (12 + 12 + 8) + 72u * 4);
}

TEST(Mesh, ValidateRejectsBadData) {
  const Mesh good = makeUnitCube();
  {
    Mesh m = good;
    m.positions[5].y = std::numeric_limits<float>::quiet_NaN();
    try {
      m.validate("nan.obj");
      FAIL() << "expected farfield::Error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("nan.obj"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("vertex 5"), std::string::npos) << e.what();
    }
  }
  {
    Mesh m = good;
    m.positions[0].x = std::numeric_limits<float>::infinity();
    EXPECT_THROW(m.validate("inf"), Error);
  }
  {
    Mesh m = good;
    m.indices[7] = 24;  // one past the end
    try {
      m.validate("badindex.ply");
      FAIL() << "expected farfield::Error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("badindex.ply"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
    }
  }
  {
    Mesh m = good;
    m.indices.pop_back();
    EXPECT_THROW(m.validate("count"), Error);
  }
  {
    Mesh m = good;
    m.normals.pop_back();
    EXPECT_THROW(m.validate("normals"), Error);
  }
  {
    Mesh m = good;
    m.uvs[3].x = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(m.validate("uvs"), Error);
  }
}

}  // namespace
}  // namespace farfield::scene
