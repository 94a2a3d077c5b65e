// A flat grey quad drawn by the city's renderer, standing in for the ground or a wall in the crowd tests.
#pragma once

#include <array>

#include "farfield/gpu/gpu_mesh.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/mesh.h"

namespace farfield::test {

// Corners counter-clockwise seen from the side `normal` points to; object id 1. Not movable: item points at the
// members.
struct GreyQuad {
  GreyQuad(const std::array<Vec3, 4>& corners, const Vec3& normal, float grey) : gpu(mesh(corners, normal)) {
    material.base_color = Vec4(grey, grey, grey, 1.0f);
    item = gpu::DrawItem{&gpu, &material, Mat4(1.0f), 1u};
  }
  GreyQuad(const GreyQuad&) = delete;
  GreyQuad& operator=(const GreyQuad&) = delete;

  gpu::GpuMesh gpu;
  gpu::GpuMaterial material;
  gpu::DrawItem item;

 private:
  static scene::Mesh mesh(const std::array<Vec3, 4>& corners, const Vec3& normal) {
    scene::Mesh m;
    m.positions.assign(corners.begin(), corners.end());
    m.normals.assign(4, normal);
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
  }
};

}  // namespace farfield::test
