#include "farfield/gen/figure_builder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::gen {
namespace {

// Signed volume by the divergence theorem: positive when a closed mesh's faces point outwards.
double signedVolume(const scene::Mesh& m) {
  double v = 0.0;
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
               c = m.positions[m.indices[3 * t + 2]];
    v += double(glm::dot(a, glm::cross(b, c))) / 6.0;
  }
  return v;
}

// Every triangle's winding agrees with its vertices' normals.
void expectNormalsFollowWinding(const scene::Mesh& m) {
  ASSERT_EQ(m.normals.size(), m.positions.size());
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    const uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1], i2 = m.indices[3 * t + 2];
    const Vec3 face = glm::cross(m.positions[i1] - m.positions[i0], m.positions[i2] - m.positions[i0]);
    if (glm::length(face) < 1e-8f) continue;
    for (uint32_t i : {i0, i1, i2}) EXPECT_GT(glm::dot(face, m.normals[i]), 0.0f) << "triangle " << t;
  }
}

TEST(FigureBuilder, ABoxIsClosedFacesOutwardsAndFollowsItsJoints) {
  FigureBuilder b("box");
  const uint16_t root = b.addJoint("root", -1, Vec3(0, 0, 1));
  const uint16_t arm = b.addJoint("arm", root, Vec3(0.5f, 0, 1));
  const uint32_t red = b.addMaterial(3, {200, 10, 20, 255});
  const uint32_t blue = b.addMaterial(9, {10, 20, 200, 255});
  b.addBox(Vec3(1, 2, 3), Vec3(0.1f, 0.2f, 0.3f), {root, arm, 0.25f}, red);
  b.addBox(Vec3(0, 0, 0), Vec3(0.5f, 0.5f, 0.5f), {arm, arm, 0.0f}, blue);
  const scene::SkinnedModel m = b.build({});
  ASSERT_EQ(m.mesh.triangleCount(), 24u);
  ASSERT_EQ(m.mesh.positions.size(), 48u);
  EXPECT_NEAR(signedVolume(m.mesh), 8.0 * 0.1 * 0.2 * 0.3 + 1.0, 1e-5);
  expectNormalsFollowWinding(m.mesh);
  for (size_t v = 0; v < 24; ++v) {
    EXPECT_EQ(m.joints[v][0], root);
    EXPECT_EQ(m.joints[v][1], arm);
    EXPECT_EQ(m.weights[v], Vec4(0.75f, 0.25f, 0.0f, 0.0f));
    EXPECT_NEAR(std::abs(m.mesh.positions[v].x - 1.0f), 0.1f, 1e-6f);
  }
  for (size_t v = 24; v < 48; ++v) EXPECT_EQ(m.weights[v], Vec4(1.0f, 0.0f, 0.0f, 0.0f));
  // Regions per triangle; each material's uv samples its own colour in the palette texture.
  for (size_t t = 0; t < 24; ++t) EXPECT_EQ(m.regions[t], t < 12 ? 3 : 9);
  auto colourAt = [&](size_t v) {
    const Vec2 uv = m.mesh.uvs[v];
    return m.texture->at(int(uv.x * float(m.texture->width())), int(uv.y * float(m.texture->height())));
  };
  EXPECT_EQ(colourAt(0), image::Rgba8(200, 10, 20, 255));
  EXPECT_EQ(colourAt(30), image::Rgba8(10, 20, 200, 255));
  // The skeleton: inverse bind matrices undo the joints' positions; rest poses are the offsets from the parents.
  EXPECT_EQ(Vec3(m.skeleton.inverse_bind[arm] * Vec4(0.5f, 0, 1, 1)), Vec3(0.0f));
  EXPECT_EQ(m.skeleton.nodes[arm].rest.translation, Vec3(0.5f, 0, 0));
  EXPECT_EQ(m.skeleton.nodes[arm].parent, 0);
}

TEST(FigureBuilder, ATubeEnclosesItsPrismAndFacesOutwards) {
  for (const Vec3 dir : {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 0, 0), Vec3(-0.6f, 0, 0.8f)}) {
    FigureBuilder b("tube");
    const uint16_t j = b.addJoint("j", -1, Vec3(0));
    const uint32_t mat = b.addMaterial(0, {255, 255, 255, 255});
    const float r1 = 0.2f, r2 = 0.1f, length = 0.8f;
    const int sides = 6;
    const TubeRing rings[] = {{Vec3(0.1f, 0.2f, 0.3f), Vec2(r1, r2), {j, j, 0.0f}},
                              {Vec3(0.1f, 0.2f, 0.3f) + 0.5f * length * dir, Vec2(r1, r2), {j, j, 0.0f}},
                              {Vec3(0.1f, 0.2f, 0.3f) + length * dir, Vec2(r1, r2), {j, j, 0.0f}}};
    b.addTube(rings, sides, mat);
    const scene::SkinnedModel m = b.build({});
    EXPECT_EQ(m.mesh.triangleCount(), size_t(2 * sides * 2 + 2 * (sides - 2)));
    // A hexagon inscribed in the ellipse with radii r1, r2: area sides / 2 * r1 * r2 * sin(2 pi / sides).
    const double area = sides / 2.0 * r1 * r2 * std::sin(2.0 * kPi / sides);
    EXPECT_NEAR(signedVolume(m.mesh), area * length, 1e-5);
    expectNormalsFollowWinding(m.mesh);
  }
}

TEST(FigureBuilder, AnOpenTubeHasNoCapsAndBlendsItsRings) {
  FigureBuilder b("tube");
  const uint16_t a = b.addJoint("a", -1, Vec3(0));
  const uint16_t c = b.addJoint("c", a, Vec3(0, 0, 1));
  const uint32_t mat = b.addMaterial(0, {255, 255, 255, 255});
  const TubeRing rings[] = {{Vec3(0, 0, 0), Vec2(0.1f), {a, c, 0.0f}}, {Vec3(0, 0, 1), Vec2(0.1f), {a, c, 0.4f}}};
  b.addTube(rings, 5, mat, false, false);
  const scene::SkinnedModel m = b.build({});
  EXPECT_EQ(m.mesh.triangleCount(), 10u);
  ASSERT_EQ(m.weights.size(), 10u);
  for (size_t v = 0; v < 5; ++v) EXPECT_EQ(m.weights[v], Vec4(1, 0, 0, 0));
  for (size_t v = 5; v < 10; ++v) {
    EXPECT_EQ(m.joints[v][1], c);
    EXPECT_NEAR(m.weights[v].x, 0.6f, 1e-6f);
    EXPECT_NEAR(m.weights[v].y, 0.4f, 1e-6f);
  }
}

TEST(FigureBuilder, ALoopingAnimationClosesAndPlantsTheRoot) {
  FigureBuilder b("swing");
  const uint16_t root = b.addJoint("root", -1, Vec3(0, 0, 1));
  const uint16_t leg = b.addJoint("leg", root, Vec3(0, 0, 1));
  const uint32_t mat = b.addMaterial(0, {255, 255, 255, 255});
  b.addBox(Vec3(0, 0, 0.5f), Vec3(0.05f, 0.05f, 0.5f), {leg, leg, 0.0f}, mat);  // a 1 m leg hanging from z = 1
  const float amplitude = 0.5f;
  auto pose = [&](float phase, std::vector<scene::NodePose>& poses) {
    poses[leg].rotation = glm::angleAxis(amplitude * std::sin(float(2.0 * kPi) * phase), Vec3(0, 1, 0));
  };
  const scene::Animation anim = b.loopingAnimation("walk", 2.0f, 9, pose, true);
  EXPECT_EQ(anim.name, "walk");
  EXPECT_FLOAT_EQ(anim.duration, 2.0f);
  ASSERT_EQ(anim.channels.size(), 4u);
  for (const scene::AnimationChannel& ch : anim.channels) {
    ASSERT_EQ(ch.times.size(), 9u);
    EXPECT_FLOAT_EQ(ch.times[4], 1.0f);
    EXPECT_EQ(ch.values.front(), ch.values.back());
  }
  const scene::SkinnedModel m = b.build({anim});
  // The leg's lowest corner touches the ground at every key: by hand, the corner (x +-0.05, z -1 below the hip)
  // turned by the key's angle is at -(cos a + 0.05 |sin a|) below the root.
  for (int k = 0; k < 8; ++k) {
    const float angle = amplitude * std::sin(float(2.0 * kPi) * float(k) / 8.0f);
    const float depth = std::cos(angle) + 0.05f * std::abs(std::sin(angle));
    const scene::AnimationChannel& root_t = anim.channels[0];
    ASSERT_EQ(root_t.node, root);
    EXPECT_NEAR(root_t.values[size_t(k)].z, depth, 1e-5f) << "key " << k;
    float lowest = 1e9f;
    for (const Vec3& p : scene::skinMesh(m, scene::jointMatrices(m, &m.animations[0], 0.25f * float(k))).positions)
      lowest = std::min(lowest, p.z);
    EXPECT_NEAR(lowest, 0.0f, 1e-5f) << "key " << k;
  }
}

TEST(FigureBuilder, BadInputIsAnErrorNamingTheFigure) {
  FigureBuilder b("figure-x");
  const uint16_t j = b.addJoint("j", -1, Vec3(0));
  auto message = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message([&] { b.addJoint("k", 5, Vec3(0)); }).find("figure-x"), std::string::npos);
  EXPECT_NE(message([&] { b.addJoint("k", 0, Vec3(NAN, 0, 0)); }).find("not finite"), std::string::npos);
  EXPECT_NE(message([&] { b.addMaterial(16, {}); }).find("region 16"), std::string::npos);
  for (int i = 0; i < 16; ++i) b.addMaterial(0, {});
  EXPECT_NE(message([&] { b.addMaterial(0, {}); }).find("at most 16"), std::string::npos);
  const TubeRing one[] = {{Vec3(0), Vec2(0.1f), {j, j, 0.0f}}};
  EXPECT_NE(message([&] { b.addTube(one, 6, 0); }).find("2 rings"), std::string::npos);
  const TubeRing along_y[] = {{Vec3(0), Vec2(0.1f), {j, j, 0.0f}}, {Vec3(0, 1, 0), Vec2(0.1f), {j, j, 0.0f}}};
  EXPECT_NE(message([&] { b.addTube(along_y, 6, 0); }).find("side vector"), std::string::npos);
  const TubeRing bad_joint[] = {{Vec3(0), Vec2(0.1f), {j, 7, 0.5f}}, {Vec3(0, 0, 1), Vec2(0.1f), {j, j, 0.0f}}};
  EXPECT_NE(message([&] { b.addTube(bad_joint, 6, 0); }).find("out of range"), std::string::npos);
  EXPECT_NE(message([&] { b.addBox(Vec3(0), Vec3(0.1f), {j, j, 0.0f}, 40); }).find("material 40"), std::string::npos);
  EXPECT_NE(message([&] { b.loopingAnimation("walk", 0.0f, 5, [](float, std::vector<scene::NodePose>&) {}, false); })
                .find("positive duration"),
            std::string::npos);
}

}  // namespace
}  // namespace farfield::gen
