#include "farfield/impostor/multi_view.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/scene/gltf_skin.h"
#include "support/test_support.h"

namespace farfield::impostor {
namespace {

TEST(MultiView, NearestViewIsTheBruteForceNearest) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (const ViewGrid grid : {ViewGrid{}, ViewGrid{8, 3, float(kPi / 4)}, ViewGrid{5, 7, float(kPi / 2)},
                              ViewGrid::octahedralGrid(16), ViewGrid::octahedralGrid(5), ViewGrid::octahedralGrid(2)}) {
    for (int i = 0; i < 4000; ++i) {
      Vec3 d(u(rng), u(rng), u(rng));
      if (glm::length(d) < 1e-3f) continue;
      d = glm::normalize(d);
      float best = -2.0f;
      for (int c = 0; c < grid.viewCount(); ++c) best = std::max(best, glm::dot(grid.direction(c), d));
      const int got = nearestView(grid, d);
      ASSERT_GE(got, 0);
      ASSERT_LT(got, grid.viewCount());
      EXPECT_NEAR(glm::dot(grid.direction(got), d), best, 1e-5f) << grid.azimuths << "x" << grid.elevations;
    }
  }
}

TEST(MultiView, LayoutCoversTheModelAndWorstAngleIsHalfASpacing) {
  Box3 b;
  b.expand(Vec3(-0.3f, -0.2f, 0.0f));
  b.expand(Vec3(0.3f, 0.2f, 1.8f));
  const ViewGrid grid;
  const gpu::AtlasLayout l = atlasLayout(b, grid, 4, 0.03f);
  EXPECT_GE(l.half_size.y, 0.9f);
  EXPECT_GE(l.half_size.x, std::sqrt(0.3f * 0.3f + 0.2f * 0.2f));
  EXPECT_EQ(l.cell_height, int(std::ceil(2.0f * l.half_size.y / 0.03f)));
  // 32 x 8 over the quarter circle: azimuth spacing 11.25 deg, elevation spacing 11.25 deg; the worst direction
  // lies between four views or above the top ring: more than half a spacing, at most one.
  const float worst = float(radToDeg(worstViewAngle(grid)));
  EXPECT_GT(worst, 5.6f);
  EXPECT_LT(worst, 11.3f);  // the zenith, above the top ring (78.75 deg)
}

// The octahedral map and its inverse: round trip on the upper hemisphere, the horizon on the square's edge, the zenith
// at its centre, a lower direction at its horizontal part; and the views spread more evenly than azimuth x elevation
// rings for the same count (the rings crowd at the zenith and leave the gap above the top ring).
TEST(MultiView, OctahedralMapRoundTripsAndSpreadsTheViews) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 2000; ++i) {
    Vec3 d(u(rng), u(rng), std::abs(u(rng)));
    if (glm::length(d) < 1e-3f) continue;
    d = glm::normalize(d);
    const Vec2 p = octahedralPoint(d);
    EXPECT_LE(std::max(std::abs(p.x), std::abs(p.y)), 1.0f + 1e-6f);
    EXPECT_LT(glm::length(octahedralDirection(p) - d), 1e-5f);
  }
  EXPECT_LT(glm::length(octahedralDirection(Vec2(0.0f)) - Vec3(0, 0, 1)), 1e-6f);
  const Vec2 horizon = octahedralPoint(glm::normalize(Vec3(1, 2, 0)));
  EXPECT_NEAR(std::max(std::abs(horizon.x), std::abs(horizon.y)), 1.0f, 1e-6f);
  EXPECT_LT(glm::length(octahedralPoint(Vec3(1, 2, -3)) - horizon), 1e-6f);
  const ViewGrid rings, octa = ViewGrid::octahedralGrid(16);
  EXPECT_EQ(octa.viewCount(), rings.viewCount());
  EXPECT_LT(worstViewAngle(octa), 0.9f * worstViewAngle(rings));  // measured 9.2 against 11.25 degrees
  // Every view of the octahedral grid looks from the upper hemisphere, and no two coincide.
  for (int a = 0; a < octa.viewCount(); ++a) {
    EXPECT_GE(octa.direction(a).z, 0.0f);
    for (int b = a + 1; b < octa.viewCount(); ++b) EXPECT_LT(glm::dot(octa.direction(a), octa.direction(b)), 0.9999f);
  }
  // The bound's choice on the octahedral map keeps the bound, one side fewer does not.
  const double focal = 512.0 / (2.0 * std::tan(kPi / 6.0));
  const BoundChoice c = chooseForBound(2.0, focal, 20.0, 0.35, float(kPi / 2), true);
  const double allowed = 2.0 * 20.0 / (focal * 0.35);
  EXPECT_TRUE(c.grid.octahedral);
  EXPECT_LE(worstViewAngle(c.grid), allowed + 1e-6);
  EXPECT_GT(worstViewAngle(ViewGrid::octahedralGrid(c.grid.azimuths - 1)), allowed);
}

class MultiViewGl : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

struct Coverage {
  size_t both = 0, either = 0, bad = 0;
};

Coverage compareAgents(const gpu::RenderTarget& a, const gpu::RenderTarget& b) {
  const image::ColorImage ca = a.readColor(), cb = b.readColor();
  const image::IdImage ia = a.readIds(), ib = b.readIds();
  Coverage c;
  for (size_t i = 0; i < ca.pixelCount(); ++i) {
    const bool x = ia.pixels()[i] != 0, y = ib.pixels()[i] != 0;
    if (!x && !y) continue;
    ++c.either;
    if (x && y) ++c.both;
    for (int k = 0; k < 3; ++k)
      if (std::abs(int(ca.pixels()[i][k]) - int(cb.pixels()[i][k])) > 24) {
        ++c.bad;
        break;
      }
  }
  return c;
}

// Seen from one of its capture views (a distant, narrow camera on the view's direction: nearly the orthographic
// capture), the impostor shows what the skinned geometry shows: the same pixels covered, colours within 24/255 but
// for texture detail resampled twice (atlas texels of 8 mm against pixels of 14 mm) and silhouette pixels; with an
// outfit of strong, distinct colour-region tints, both tinted alike (and not like another outfit).
TEST_F(MultiViewGl, ImpostorSeenFromACaptureViewReproducesTheGeometry) {
  FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
  const scene::SkinnedModel man = scene::importSkinnedModel(man_glb.string());
  const scene::Animation* walk = &man.animations[0];
  std::vector<std::vector<Mat4>> poses;
  for (int p = 0; p < 2; ++p) poses.push_back(scene::jointMatrices(man, walk, walk->start + 0.4f * float(p)));
  const Mat4 to_agent = glm::rotate(Mat4(1.0f), float(kPi / 2), Vec3(0, 0, 1));
  gpu::SkinnedGpuModel model(man, to_agent, poses);
  gpu::CrowdRenderer crowd;
  std::vector<Vec4> tints(2 * scene::kColorRegions, Vec4(1.0f));  // outfit 0 white, outfit 1 a colour per region
  for (int r = 0; r < scene::kColorRegions; ++r)
    tints[size_t(scene::kColorRegions + r)] =
        Vec4(0.3f + 0.7f * float(r % 2), 0.3f + 0.7f * float((r / 2) % 2), 0.3f + 0.7f * float((r / 4) % 2), 1.0f);
  crowd.setRegionTints(tints);
  EXPECT_EQ(crowd.outfitCount(), 2u);
  std::set<uint8_t> regions(man.regions.begin(), man.regions.end());
  EXPECT_GE(regions.size(), 8u) << "CesiumMan's one material is split by joints";
  Box3 bounds;
  for (const auto& pose : poses)
    for (const Vec3& p : scene::skinMesh(man, pose).positions) bounds.expand(Vec3(to_agent * Vec4(p, 1.0f)));
  // An azimuth x elevation grid and an octahedral one (5 x 5: cells on the horizon and between it and the zenith,
  // whose straight-down camera the test's up vector cannot frame).
  const std::pair<ViewGrid, std::vector<int>> grids[] = {{ViewGrid{8, 3, float(kPi / 4)}, {3, 8 + 5, 16 + 1}},
                                                         {ViewGrid::octahedralGrid(5), {2, 5 + 3, 10 + 1, 20 + 1}}};
  for (const auto& [grid, cells] : grids) {
  const gpu::AtlasLayout layout = atlasLayout(bounds, grid, 2, 0.008f);
  EXPECT_EQ(layout.octahedral, grid.octahedral);
  MultiViewImpostor imp = bakeMultiView(crowd, model, layout, grid);
  EXPECT_EQ(imp.byteSize(), size_t(layout.width()) * size_t(layout.height()) * 2 * 8);

  gpu::LightSettings light;
  const float heading = 0.7f;
  for (const int cell : cells) {
    gpu::CrowdAgentGpu agent;
    agent.pos_heading = Vec4(2.0f, -1.0f, 0.0f, heading);
    agent.index = 1;
    agent.object_id = 5;
    agent.outfit = 1;
    const Vec3 local = grid.direction(cell);
    const Vec3 world_dir = Vec3(glm::rotate(Mat4(1.0f), heading, Vec3(0, 0, 1)) * Vec4(local, 0.0f));
    const Vec3 centre = Vec3(agent.pos_heading) +
                        Vec3(glm::rotate(Mat4(1.0f), heading, Vec3(0, 0, 1)) * Vec4(layout.centre, 0.0f));
    Camera camera;
    camera.eye = centre + world_dir * 60.0f;
    camera.at = centre;
    camera.width = camera.height = 160;
    camera.fov_y = float(2.0 * std::atan(1.1 / 60.0));
    camera.near_plane = 10.0f;
    camera.far_plane = 200.0f;
    ASSERT_EQ(nearestView(grid, local), cell);

    gpu::RenderTarget geo(160, 160), imp_target(160, 160), wrong(160, 160), other_outfit(160, 160);
    auto draw = [&](gpu::RenderTarget& t, int mode, uint32_t view, uint32_t outfit = 1, bool blend = false) {
      t.bindForOpaquePass();
      t.clear(light.sky_color);
      gpu::CrowdAgentGpu a = agent;
      a.outfit = outfit;
      if (mode == 0) {
        crowd.drawSkinned(camera, model, std::span(&a, 1), light);
      } else {
        a.view = view;
        crowd.drawImpostors(camera, *imp.atlas, std::span(&a, 1), light, blend);
      }
    };
    draw(geo, 0, 0);
    draw(imp_target, 1, uint32_t(cell));
    draw(other_outfit, 1, uint32_t(cell), 0);
    // Blending the views around the capture direction gives (almost) all the weight to the capture view.
    gpu::RenderTarget blended(160, 160);
    draw(blended, 1, 0u, 1, true);
    const Coverage b = compareAgents(geo, blended);
    EXPECT_GT(double(b.both), 0.93 * double(b.either)) << "cell " << cell << " blended";
    EXPECT_LT(double(b.bad), 0.15 * double(b.either)) << "cell " << cell << " blended: " << b.bad << " of " << b.either;
    const Coverage o = compareAgents(geo, other_outfit);
    EXPECT_GT(double(o.bad), 0.3 * double(o.either)) << "cell " << cell << ": the tints must show";
    // The next view of the row (the one before it at the row's end).
    draw(wrong, 1, uint32_t(cell % grid.azimuths + 1 < grid.azimuths ? cell + 1 : cell - 1));
    const Coverage c = compareAgents(geo, imp_target);
    EXPECT_GT(c.either, 1000u);  // the agent fills part of the frame (less from above)
    EXPECT_GT(double(c.both), 0.93 * double(c.either)) << "cell " << cell;
    EXPECT_LT(double(c.bad), 0.15 * double(c.either)) << "cell " << cell << ": " << c.bad << " of " << c.either;
    const Coverage w = compareAgents(geo, wrong);
    EXPECT_LT(double(w.both), 0.85 * double(w.either)) << "cell " << cell << ": the wrong view must not match";
  }
  }
}

}  // namespace
}  // namespace farfield::impostor

namespace farfield::impostor {
namespace {

TEST(MultiView, ChoiceFromTheBoundKeepsTheBoundAndIsNotWasteful) {
  // 512 px at 60 degrees (focal 443 px), a 0.35 m half width, impostors from 20 m on.
  const double focal = 512.0 / (2.0 * std::tan(kPi / 6.0));
  for (double error_px : {1.0, 2.0, 4.0}) {
    const BoundChoice c = chooseForBound(error_px, focal, 20.0, 0.35);
    EXPECT_NEAR(c.texel_m, 20.0 / focal, 1e-6);
    const double allowed = error_px * 20.0 / (focal * 0.35);
    EXPECT_LE(worstViewAngle(c.grid), allowed + 1e-6) << error_px;
    // One elevation fewer (and its azimuths) breaks the bound: the choice is the coarsest of its family.
    ViewGrid coarser = c.grid;
    coarser.elevations -= 1;
    coarser.azimuths = std::max(3, int(std::ceil(2.0 * kPi / (double(coarser.max_elevation) / coarser.elevations))));
    if (coarser.elevations >= 1) {
      EXPECT_GT(worstViewAngle(coarser), allowed) << error_px;
    }
  }
  EXPECT_THROW(chooseForBound(0.0, focal, 20.0, 0.35), Error);
}

}  // namespace
}  // namespace farfield::impostor

namespace farfield::impostor {
namespace {

// A vertex on a unit circle, one turn per cycle of 16 poses: the frame shown for pose p is k poses away, k at most
// half the frame spacing, and the error is the chord 2 sin(pi k / 16).
TEST(MultiView, FramesFromTheBoundAreTheFewestThatKeepIt) {
  const int poses = 16;
  std::vector<std::vector<Vec3>> positions(poses);
  for (int p = 0; p < poses; ++p) {
    const float a = float(2.0 * kPi) * float(p) / float(poses);
    positions[size_t(p)] = {Vec3(std::cos(a), std::sin(a), 0.0f), Vec3(0.0f)};
  }
  auto chord = [&](int k) { return 2.0 * std::sin(kPi * double(k) / double(poses)); };
  EXPECT_NEAR(frameError(positions, 16), 0.0, 1e-6);
  EXPECT_NEAR(frameError(positions, 8), chord(1), 1e-5);
  EXPECT_NEAR(frameError(positions, 4), chord(2), 1e-5);
  EXPECT_NEAR(frameError(positions, 2), chord(4), 1e-5);
  EXPECT_NEAR(frameError(positions, 1), chord(8), 1e-5);
  EXPECT_EQ(framesForBound(positions, 0.5), 8);
  EXPECT_EQ(framesForBound(positions, 0.2), 16);
  EXPECT_EQ(framesForBound(positions, 1.5), 2);
  EXPECT_EQ(framesForBound(positions, 2.5), 1);
  EXPECT_THROW(frameError(positions, 3), Error);
}

}  // namespace
}  // namespace farfield::impostor
