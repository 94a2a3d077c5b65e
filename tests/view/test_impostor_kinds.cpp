// The tint overlay: impostor items get their kind's colour multiplied into a copy of their material; geometry items
// (meshes of the scene) are left exactly as they were; the decisions are counted per kind.
#include "farfield/view/impostor_kinds.h"

#include <gtest/gtest.h>

#include "farfield/gpu/context.h"
#include "farfield/scene/builtin.h"

namespace farfield::view {
namespace {

TEST(ImpostorKinds, ImpostorItemsAreTintedAndGeometryIsNot) {
  gpu::sharedHeadlessContext();
  const scene::Scene scene = scene::builtinScene("cubes");
  const gpu::GpuScene gpu_scene(scene);
  const gpu::GpuMesh impostor_mesh(scene::makeUnitCube());
  gpu::GpuMaterial impostor_material;
  impostor_material.base_color = Vec4(0.5f, 0.5f, 0.5f, 1.0f);
  const uint32_t base = uint32_t(scene.objects.size() + 1);

  runtime::FramePlan plan;
  gpu_scene.appendDrawItems(std::vector<uint32_t>{1, 2}, plan.items);
  const size_t geometry = plan.items.size();
  plan.items.push_back({&impostor_mesh, &impostor_material, Mat4(1.0f), base + 0});  // layer 0: valid impostor
  plan.items.push_back({&impostor_mesh, &impostor_material, Mat4(1.0f), base + 1});  // layer 1: dynamic
  plan.layers = {runtime::LayerAsImpostor{0, 0, 0.0, 1.0}, runtime::LayerAsDynamic{1},
                 runtime::LayerAsGeometry{2, 100}};

  const std::vector<size_t> kinds = itemKinds(plan, gpu_scene, base);
  ASSERT_EQ(kinds.size(), geometry + 2);
  for (size_t i = 0; i < geometry; ++i) EXPECT_EQ(kinds[i], kDecisionKinds);
  EXPECT_EQ(kinds[geometry], 0u);
  EXPECT_EQ(kinds[geometry + 1], 3u);
  const auto counts = countDecisions(plan);
  EXPECT_EQ(counts[0], 1u);
  EXPECT_EQ(counts[1], 1u);
  EXPECT_EQ(counts[3], 1u);

  std::vector<gpu::GpuMaterial> materials;
  const std::vector<gpu::DrawItem> tinted = tintedItems(plan.items, kinds, materials);
  for (size_t i = 0; i < geometry; ++i) EXPECT_EQ(tinted[i].material, plan.items[i].material);
  EXPECT_EQ(materials.size(), 2u);
  EXPECT_EQ(tinted[geometry].material->base_color, Vec4(0.5f, 0.5f, 0.5f, 1.0f) * decisionTint(0));
  EXPECT_EQ(tinted[geometry + 1].material->base_color, Vec4(0.5f, 0.5f, 0.5f, 1.0f) * decisionTint(3));
  EXPECT_EQ(impostor_material.base_color, Vec4(0.5f, 0.5f, 0.5f, 1.0f));  // the plan's material is untouched
}

}  // namespace
}  // namespace farfield::view
