#include "farfield/gpu/gpu_mesh.h"

#include <gtest/gtest.h>

#include "farfield/core/error.h"
#include "farfield/scene/builtin.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

TEST_F(GpuTest, MeshCountsAndBounds) {
  const scene::Mesh box = scene::makeBox(Vec3(-1, -2, 0), Vec3(3, 4, 5));
  GpuMesh mesh(box);
  EXPECT_EQ(mesh.indexCount(), box.indices.size());
  EXPECT_EQ(mesh.triangleCount(), box.indices.size() / 3);
  EXPECT_EQ(mesh.bounds().lo, Vec3(-1, -2, 0));
  EXPECT_EQ(mesh.bounds().hi, Vec3(3, 4, 5));
  EXPECT_EQ(mesh.byteSize(), box.positions.size() * 32 + box.indices.size() * 4);
  EXPECT_NE(mesh.vertexArray(), 0u);
  GpuMesh moved = std::move(mesh);
  EXPECT_EQ(moved.indexCount(), box.indices.size());
  EXPECT_EQ(mesh.vertexArray(), 0u);
}

TEST_F(GpuTest, EmptyMeshDrawsNothing) {
  const GpuMesh mesh{scene::Mesh{}};
  EXPECT_EQ(mesh.indexCount(), 0u);
  EXPECT_EQ(mesh.vertexArray(), 0u);
  EXPECT_TRUE(mesh.bounds().empty());
}

TEST_F(GpuTest, BadMeshesAreErrors) {
  scene::Mesh mesh = scene::makeUnitCube();
  mesh.indices.back() = uint32_t(mesh.positions.size());
  EXPECT_THROW(GpuMesh{mesh}, Error);
  mesh = scene::makeUnitCube();
  mesh.indices.pop_back();
  EXPECT_THROW(GpuMesh{mesh}, Error);
  mesh = scene::makeUnitCube();
  mesh.normals.pop_back();
  EXPECT_THROW(GpuMesh{mesh}, Error);
  mesh = scene::makeUnitCube();
  mesh.uvs.resize(3);
  EXPECT_THROW(GpuMesh{mesh}, Error);
}

}  // namespace
}  // namespace farfield::gpu
