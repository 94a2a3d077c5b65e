#include "farfield/impostor/environment_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "farfield/core/error.h"
#include "impostor/impostor_fixture.h"

namespace farfield::impostor {
namespace {

using test::BoxScene;
using test::ImpostorGpuTest;

ErrorBound testBound(double px = 2.0) { return ErrorBound{px, 512, 512, degToRad(45.0)}; }

// Objects scattered around a street-level cell: boxes 5-30 m wide at 20-500 m, some straddling the far-field cube.
std::vector<EnvMapObject> scatter(std::mt19937& rng, int count) {
  std::uniform_real_distribution<float> angle(0.0f, float(2.0 * kPi)), dist(20.0f, 500.0f), size(5.0f, 30.0f),
      height(3.0f, 60.0f);
  std::vector<EnvMapObject> out;
  for (int i = 0; i < count; ++i) {
    const float a = angle(rng), r = dist(rng), w = size(rng);
    const Vec3 c(r * std::cos(a), r * std::sin(a), 0.0f);
    out.push_back({uint32_t(i + 1), Box3::fromPoints(c - Vec3(w, w, 0.0f), c + Vec3(w, w, height(rng)))});
  }
  return out;
}

// The face holding point p (largest coordinate of p - c), as environment_map.h numbers them.
int faceOf(const Vec3& p, const Vec3& c) {
  const Vec3 q = p - c;
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(q[i]) > std::abs(q[k])) k = i;
  return 2 * k + (q[k] >= 0.0f ? 0 : 1);
}

const EnvMapFace* findFace(const EnvMapPlan& plan, int face) {
  for (const EnvMapFace& f : plan.faces)
    if (f.face == face) return &f;
  return nullptr;
}

TEST(EnvironmentMapPlanTest, EveryFarPointIsInALayerOfItsFaceAndDrawnWithinTheBoundFromTheWholeCell) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const Box3 cell = Box3::fromPoints(Vec3(-14.0f, -16.0f, 1.2f), Vec3(14.0f, 16.0f, 1.7f));
  for (double px : {1.0, 2.0, 4.0}) {
    const ErrorBound bound = testBound(px);
    for (double d : {30.0, 60.0, 150.0}) {
      const std::vector<EnvMapObject> objects = scatter(rng, 60);
      const EnvMapPlan plan = planEnvironmentMap(cell, d, objects, bound);
      ASSERT_LE(plan.error_angle, bound.angle() * (1.0 + 1e-9));
      double worst = 0.0;
      size_t far = 0, points = 0;
      for (const EnvMapObject& o : objects) {
        const bool near = std::binary_search(plan.near_objects.begin(), plan.near_objects.end(), o.id);
        Box3 cube;
        cube.lo = plan.centre - Vec3(float(d));
        cube.hi = plan.centre + Vec3(float(d));
        EXPECT_EQ(near, o.bounds.overlaps(cube)) << "object " << o.id;
        if (near) continue;
        ++far;
        for (int s = 0; s < 40; ++s) {
          const Vec3 p = o.bounds.lo + Vec3(unit(rng), unit(rng), unit(rng)) * o.bounds.extent();
          const EnvMapFace* face = findFace(plan, faceOf(p, plan.centre));
          ASSERT_NE(face, nullptr) << "object " << o.id << ": no face holds its point";
          ASSERT_TRUE(std::binary_search(face->objects.begin(), face->objects.end(), o.id));
          for (int v = 0; v < 8; ++v) {
            // Viewpoints anywhere in the cell, corners one time in four (the worst case is at the half-diagonal).
            const Vec3 t = v % 4 == 0 ? Vec3(float(v & 1), float((v >> 1) & 1), float((v >> 2) & 1))
                                      : Vec3(unit(rng), unit(rng), unit(rng));
            const Vec3 eye = cell.lo + t * cell.extent();
            worst = std::max(worst, envMapPointError(face->plan, eye, p));  // throws if no layer holds p
            ++points;
          }
        }
      }
      ASSERT_GT(far, 10u);
      EXPECT_LE(worst, bound.angle() * (1.0 + 1e-6)) << px << " px, d " << d;
      // Not vacuous: the sampled errors come close to the bound (the spacing is not far too fine).
      EXPECT_GT(worst, 0.25 * bound.angle()) << px << " px, d " << d << " over " << points << " samples";
    }
  }
}

TEST(EnvironmentMapPlanTest, LayersFollowTheBoundAndTheDistance) {
  std::mt19937 rng(5);
  const Box3 cell = Box3::fromPoints(Vec3(-10.0f, -10.0f, 1.2f), Vec3(10.0f, 10.0f, 1.7f));
  const std::vector<EnvMapObject> objects = scatter(rng, 80);
  const EnvMapPlan fine = planEnvironmentMap(cell, 40.0, objects, testBound(1.0));
  const EnvMapPlan coarse = planEnvironmentMap(cell, 40.0, objects, testBound(4.0));
  const EnvMapPlan far = planEnvironmentMap(cell, 200.0, objects, testBound(1.0));
  EXPECT_GT(fine.layers(), 2 * coarse.layers());  // dw grows with the bound's angle
  EXPECT_LT(far.layers(), fine.layers());          // fewer slabs beyond a larger distance
  EXPECT_GT(far.near_objects.size(), fine.near_objects.size());
  EXPECT_EQ(fine.slab_width_w, 2.0 * std::sin(testBound(1.0).angle()) / fine.radius);
  // Nothing lies below the cube (the boxes stand on z = 0, the cell at 1.2-1.7 m); tall boxes may reach the top face.
  for (const EnvMapFace& f : fine.faces) EXPECT_NE(f.face, 5);
  for (const EnvMapFace& f : fine.faces) {
    ASSERT_EQ(f.layer_objects.size(), f.plan.layers.size());
    for (size_t i = 1; i < f.plan.layers.size(); ++i)  // far to near, slabs disjoint
      EXPECT_LE(f.plan.layers[i - 1].z_hi, f.plan.layers[i].z_lo + 1e-3f);
  }
}

// The layers a view draws: looking along +x from the cell's centre every quad of the +x face is in view and none of
// the -x face; the fill is each counted quad's area over the square of its distance less the cell's half-diagonal,
// recomputed here from the quads' corners, each capped at the frame; a wider cell (nearer viewpoints) fills more.
TEST(EnvironmentMapPlanTest, TheLayersInViewAreTheQuadsTheFrustumMeets) {
  std::mt19937 rng(11);
  const std::vector<EnvMapObject> objects = scatter(rng, 300);
  const Box3 cell = Box3::fromPoints(Vec3(-10.0f, -10.0f, 1.0f), Vec3(10.0f, 10.0f, 2.0f));
  const ErrorBound bound = testBound();
  const EnvMapPlan plan = planEnvironmentMap(cell, 100.0, objects, bound);
  const EnvMapFace* px = findFace(plan, 0);
  const EnvMapFace* nx = findFace(plan, 1);
  ASSERT_NE(px, nullptr);
  ASSERT_NE(nx, nullptr);
  const Vec3 c = cell.center();
  const auto lookAlong = [&](const Vec3& dir) {
    Camera camera;
    camera.eye = c;
    camera.at = c + dir;
    camera.up = Vec3(0.0f, 0.0f, 1.0f);
    camera.width = 512;
    camera.height = 512;
    camera.fov_y = float(degToRad(45.0));
    camera.near_plane = 0.5f;
    camera.far_plane = 20000.0f;
    return Frustum::fromMatrix(camera.viewProjection());
  };
  const Frustum ahead = lookAlong(Vec3(1.0f, 0.0f, 0.0f));
  const EnvMapLayersInView seen = envMapLayersInView(plan, ahead, bound);
  EXPECT_GE(seen.quads, px->plan.layers.size());
  EXPECT_LE(seen.quads, plan.layers() - nx->plan.layers.size());
  // Brute force over the quads' corners: a quad is counted exactly when the frustum meets its corners' box.
  size_t expected_quads = 0;
  double expected_fill = 0.0;
  const double frame = 512.0 * 512.0;
  for (const EnvMapFace& face : plan.faces)
    for (const LayerPlan& layer : face.plan.layers) {
      const Vec3 centre = c + (face.plan.shaft.apex - c) * (1.0f - layer.depth / face.plan.shaft.min_distance);
      Box3 box;
      for (float su : {-1.0f, 1.0f})
        for (float sv : {-1.0f, 1.0f})
          box.expand(centre + face.plan.right * (su * layer.half_u) + face.plan.up * (sv * layer.half_v));
      if (!ahead.intersects(box)) continue;
      ++expected_quads;
      const double t = double(glm::length(centre - c)) - plan.radius;
      expected_fill += std::min(4.0 * layer.half_u * layer.half_v * std::pow(bound.focalPixels() / t, 2.0), frame) *
                       double(layer.cover);  // the share of the quad its tiles draw
    }
  EXPECT_EQ(seen.quads, expected_quads);
  EXPECT_NEAR(seen.fill_pixels, expected_fill, 1e-3 * expected_fill);
  EXPECT_GT(seen.fill_pixels, 0.0);
  EXPECT_LE(seen.fill_pixels, double(seen.quads) * frame);
  const EnvMapLayersInView behind = envMapLayersInView(plan, lookAlong(Vec3(-1.0f, 0.0f, 0.0f)), bound);
  EXPECT_GE(behind.quads, nx->plan.layers.size());
  EXPECT_LE(behind.quads, plan.layers() - px->plan.layers.size());
}

TEST(EnvironmentMapPlanTest, BadInputIsAnErrorNamingIt) {
  const Box3 cell = Box3::fromPoints(Vec3(-10.0f, -10.0f, 1.2f), Vec3(10.0f, 10.0f, 1.7f));
  const std::vector<EnvMapObject> one = {{1, Box3::fromPoints(Vec3(100.0f), Vec3(110.0f))}};
  EXPECT_THROW(planEnvironmentMap(cell, 10.0, one, testBound()), Error);  // inside the half-diagonal
  EXPECT_THROW(planEnvironmentMap(Box3(), 100.0, one, testBound()), Error);
  const std::vector<EnvMapObject> zero = {{0, Box3::fromPoints(Vec3(100.0f), Vec3(110.0f))}};
  EXPECT_THROW(planEnvironmentMap(cell, 100.0, zero, testBound()), Error);
  const std::vector<EnvMapObject> empty = {{1, Box3()}};
  EXPECT_THROW(planEnvironmentMap(cell, 100.0, empty, testBound()), Error);
  EnvMapOptions bad;
  bad.texel_pixels = 0.0;
  EXPECT_THROW(planEnvironmentMap(cell, 100.0, one, testBound(), bad), Error);
  try {
    planEnvironmentMap(cell, 10.0, one, testBound());
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("far-field distance"), std::string::npos) << e.what();
  }
}

// Drawn from the cell's centre, the captured faces show what the far-field geometry shows there.
TEST_F(ImpostorGpuTest, EnvironmentMapFromItsCentreMatchesTheFarFieldGeometry) {
  BoxScene s;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> pos(-200.0f, 200.0f), size(4.0f, 12.0f), height(5.0f, 40.0f);
  std::vector<EnvMapObject> objects;
  while (objects.size() < 40) {
    const Vec3 c(pos(rng), pos(rng), 0.0f);
    if (std::max(std::abs(c.x), std::abs(c.y)) < 80.0f) continue;
    const float w = size(rng);
    const Vec3 colour(0.2f + 0.6f * float(objects.size() % 5) / 4.0f, 0.5f, 0.8f - 0.15f * float(objects.size() % 4));
    const uint32_t id = s.addBox(c - Vec3(w, w, 0.0f), c + Vec3(w, w, height(rng)), colour);
    objects.push_back({id, s.boxes.back()});
  }
  const gpu::GpuScene scene(s.scene);
  const Box3 cell = Box3::fromPoints(Vec3(-8.0f, -8.0f, 1.2f), Vec3(8.0f, 8.0f, 1.7f));
  const ErrorBound bound = testBound(2.0);
  const EnvMapPlan plan = planEnvironmentMap(cell, 60.0, objects, bound);
  ASSERT_TRUE(plan.near_objects.empty());
  ASSERT_EQ(plan.faces.size(), 4u);
  std::vector<GpuLayeredImpostor> faces;
  double planned = 0.0, texels = 0.0;
  for (const EnvMapFace& f : plan.faces) {
    LayeredImpostor captured = captureLayered(*renderer_, scene, f.objects, f.plan);
    measureLayerCover(captured);
    // The cover planned from the objects each slab meets bounds the tiles the capture gives.
    for (size_t i = 0; i < f.plan.layers.size(); ++i) {
      const LayerPlan& lp = f.plan.layers[i];
      const double n = double(lp.width) * lp.height;
      EXPECT_GE(double(lp.cover) * n, double(captured.plan.layers[i].cover) * n - 1e-3) << "face " << f.face << " layer " << i;
      planned += double(lp.cover) * n;
      texels += n;
    }
    faces.emplace_back(captured);
  }
  EXPECT_LT(planned, 0.8 * texels);  // an environment map's layers are mostly empty: the tiles skip most of them
  std::vector<gpu::DrawItem> impostor_items, geometry_items = scene.drawItems();
  for (const GpuLayeredImpostor& f : faces) f.appendDrawItems(impostor_items, 1);

  for (const Vec3& dir : {Vec3(1, 0, 0), Vec3(0.6f, 0.8f, 0.0f), Vec3(-1, 0.3f, 0.0f), Vec3(0.2f, -1, 0.05f)}) {
    Camera camera;
    camera.eye = plan.centre;
    camera.at = plan.centre + dir;
    camera.up = Vec3(0, 0, 1);
    camera.fov_y = float(bound.fov_y);
    camera.width = bound.width;
    camera.height = bound.height;
    camera.near_plane = 0.5f;
    camera.far_plane = 2000.0f;
    gpu::RenderTarget target(bound.width, bound.height);
    const auto render = [&](const std::vector<gpu::DrawItem>& items) {
      target.bind();
      target.clear(Vec4(0.0f));
      renderer_->draw(camera, items, target);
      return target.readDepth();
    };
    const image::DepthImage geometry = render(geometry_items);
    const image::DepthImage layered = render(impostor_items);
    // Coverage: where the geometry is, the layers are (a pixel of slack at silhouettes, from texel sampling).
    size_t covered = 0, missed = 0, extra = 0;
    for (size_t i = 0; i < geometry.pixelCount(); ++i) {
      const bool g = geometry.pixels()[i] > 0.0f, l = layered.pixels()[i] > 0.0f;
      covered += g ? 1 : 0;
      missed += g && !l ? 1 : 0;
      extra += l && !g ? 1 : 0;
    }
    ASSERT_GT(covered, 2000u);
    EXPECT_LT(double(missed + extra) / double(covered), 0.03) << "direction " << dir.x << "," << dir.y;
  }
}

}  // namespace
}  // namespace farfield::impostor
