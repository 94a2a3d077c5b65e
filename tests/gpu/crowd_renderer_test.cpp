// GPU skinning with instancing against CPU skinning of the same poses, colour regions tinted per agent outfit (GL
// test: the shared headless context).
#include "farfield/gpu/crowd_renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"
#include "farfield/gpu/gpu_mesh.h"
#include "farfield/scene/gltf_skin.h"
#include "gpu/gpu_fixture.h"
#include "support/test_support.h"

namespace farfield::gpu {
namespace {

class CrowdRendererGlCutout : public test::GpuTest {};
// The same check for each way of skinning (gpu::Skinning).
class CrowdSkinningGl : public test::GpuTest, public ::testing::WithParamInterface<Skinning> {};

struct Compare {
  size_t covered = 0;  // pixels either image shows an agent
  size_t bad = 0;      // of those, off by more than 8/255 in some channel
};

Compare compare(const image::ColorImage& a, const image::IdImage& ia, const image::ColorImage& b,
                const image::IdImage& ib) {
  Compare c;
  for (size_t i = 0; i < a.pixelCount(); ++i) {
    if (ia.pixels()[i] == 0 && ib.pixels()[i] == 0) continue;
    ++c.covered;
    const image::Rgba8 p = a.pixels()[i], q = b.pixels()[i];
    for (int k = 0; k < 3; ++k)
      if (std::abs(int(p[k]) - int(q[k])) > 8) {
        ++c.bad;
        break;
      }
  }
  return c;
}

TEST_P(CrowdSkinningGl, InstancedGpuSkinningEqualsCpuSkinning) {
  FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
  const scene::SkinnedModel man = scene::importSkinnedModel(man_glb.string());
  const scene::Animation* walk = &man.animations[0];
  std::vector<std::vector<Mat4>> poses;
  for (int p = 0; p < 4; ++p) poses.push_back(scene::jointMatrices(man, walk, walk->start + 0.23f * float(p)));
  const Mat4 to_agent = glm::rotate(Mat4(1.0f), 0.3f, Vec3(0, 0, 1));
  SkinnedGpuModel gpu_model(man, to_agent, poses, {}, GetParam());
  EXPECT_EQ(gpu_model.skinning(), GetParam());
  CrowdRenderer crowd;
  // Three outfits of distinct region tints; agent i wears outfit i + 1 (mod 3).
  std::vector<Vec4> tints(3 * scene::kColorRegions);
  for (size_t k = 0; k < tints.size(); ++k)
    tints[k] = Vec4(0.4f + 0.6f * float(k % 2), 0.4f + 0.6f * float((k / 2) % 2), 0.4f + 0.6f * float((k / 5) % 2), 1.0f);
  crowd.setRegionTints(tints);
  EXPECT_THROW(crowd.setRegionTints(std::span(tints).first(5)), Error);
  Renderer renderer;
  const Camera camera = test::testCamera(Vec3(0.3f, -3.6f, 1.3f), Vec3(0.3f, 0.0f, 0.8f), 160);

  std::vector<CrowdAgentGpu> agents(3);
  for (int i = 0; i < 3; ++i) {
    agents[size_t(i)].pos_heading = Vec4(-1.0f + 1.2f * float(i), 0.3f * float(i), 0.0f, 0.9f * float(i) - 0.4f);
    agents[size_t(i)].index = uint32_t(i + 1);
    agents[size_t(i)].object_id = uint32_t(10 + i);
    agents[size_t(i)].tint = Vec4(1.0f, 0.9f - 0.2f * float(i), 0.8f, 1.0f);
    agents[size_t(i)].outfit = uint32_t(i + 4);  // outfit (i + 1) mod 3
  }
  RenderTarget gpu_target(160, 160);
  gpu_target.bindForOpaquePass();
  gpu_target.clear(renderer.light().sky_color);
  const FrameStats stats = crowd.drawSkinned(camera, gpu_model, agents, renderer.light());
  EXPECT_EQ(stats.draw_calls, 1u);
  EXPECT_EQ(stats.triangles, 3u * man.mesh.triangleCount());

  // CPU: each agent's pose skinned on the CPU, split by colour region, each part drawn as a plain mesh with the
  // agent's transform and tint times its region's tint in the agent's outfit.
  ASSERT_EQ(man.regions.size(), man.mesh.triangleCount());
  auto cpuFrame = [&](int pose_shift, RenderTarget& target) {
    std::vector<GpuMesh> meshes;
    meshes.reserve(3 * scene::kColorRegions);
    std::vector<GpuMaterial> materials(3 * scene::kColorRegions);
    Texture texture = Texture::fromImage(*man.texture, true);
    std::vector<DrawItem> items;
    for (int i = 0; i < 3; ++i) {
      const CrowdAgentGpu& a = agents[size_t(i)];
      const scene::Mesh posed = scene::skinMesh(man, poses[(a.index + uint32_t(pose_shift)) % 4]);
      const Mat4 agent = glm::translate(Mat4(1.0f), Vec3(a.pos_heading)) *
                         glm::rotate(Mat4(1.0f), a.pos_heading.w, Vec3(0, 0, 1)) * to_agent;
      for (int r = 0; r < scene::kColorRegions; ++r) {
        scene::Mesh part = posed;
        part.indices.clear();
        for (size_t t = 0; t < posed.triangleCount(); ++t)
          if (man.regions[t] == r) part.indices.insert(part.indices.end(), &posed.indices[3 * t], &posed.indices[3 * t] + 3);
        if (part.indices.empty()) continue;
        meshes.emplace_back(part);
        GpuMaterial& mat = materials[size_t(i * scene::kColorRegions + r)];
        mat.base_color = man.base_color * a.tint * tints[(a.outfit % 3) * scene::kColorRegions + size_t(r)];
        mat.texture = &texture;
        items.push_back(DrawItem{&meshes.back(), &mat, agent, a.object_id});
      }
    }
    renderer.render(camera, items, target);
  };
  RenderTarget cpu_target(160, 160);
  cpuFrame(0, cpu_target);
  const Compare same = compare(gpu_target.readColor(), gpu_target.readIds(), cpu_target.readColor(),
                               cpu_target.readIds());
  EXPECT_GT(same.covered, 1000u);  // the agents are in view
  EXPECT_LT(double(same.bad), 0.01 * double(same.covered)) << same.bad << " of " << same.covered;
  // And the comparison sees a wrong pose.
  RenderTarget wrong_target(160, 160);
  cpuFrame(1, wrong_target);
  const Compare wrong = compare(gpu_target.readColor(), gpu_target.readIds(), wrong_target.readColor(),
                                wrong_target.readIds());
  EXPECT_GT(double(wrong.bad), 0.05 * double(wrong.covered)) << wrong.bad << " of " << wrong.covered;
}

// A model whose texture is transparent is cut out (nothing drawn); an opaque one is drawn without the cut-out test.
TEST_F(CrowdRendererGlCutout, ATransparentTextureIsCutOutAndAnOpaqueOneDrawsWithoutTheTest) {
  FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
  scene::SkinnedModel man = scene::importSkinnedModel(man_glb.string());
  ASSERT_TRUE(man.texture);
  const std::vector<std::vector<Mat4>> poses{scene::jointMatrices(man, &man.animations[0], man.animations[0].start)};
  CrowdRenderer crowd;
  Renderer renderer;
  const Camera camera = test::testCamera(Vec3(0.0f, -3.6f, 1.0f), Vec3(0.0f, 0.0f, 0.8f), 96);
  std::vector<CrowdAgentGpu> agents(1);
  agents[0].object_id = 7;
  auto agentPixels = [&](const SkinnedGpuModel& model) {
    RenderTarget target(96, 96);
    target.bindForOpaquePass();
    target.clear(renderer.light().sky_color);
    crowd.drawSkinned(camera, model, agents, renderer.light());
    const image::IdImage ids = target.readIds();
    return size_t(std::count(ids.pixels().begin(), ids.pixels().end(), 7u));
  };
  const SkinnedGpuModel opaque(man, Mat4(1.0f), poses);
  EXPECT_FALSE(opaque.cutout());
  EXPECT_GT(agentPixels(opaque), 200u);
  image::ColorImage clear = *man.texture;
  for (image::Rgba8& t : clear.pixels()) t.a = 40;
  man.texture = std::make_shared<const image::ColorImage>(std::move(clear));
  const SkinnedGpuModel transparent(man, Mat4(1.0f), poses);
  EXPECT_TRUE(transparent.cutout());
  EXPECT_EQ(agentPixels(transparent), 0u);
}

INSTANTIATE_TEST_SUITE_P(Skinnings, CrowdSkinningGl, ::testing::Values(Skinning::Palette, Skinning::BakedPoses),
                         [](const ::testing::TestParamInfo<Skinning>& info) {
                           return info.param == Skinning::Palette ? "Palette" : "BakedPoses";
                         });

}  // namespace
}  // namespace farfield::gpu
