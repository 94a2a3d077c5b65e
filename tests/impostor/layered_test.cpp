#include "farfield/impostor/layered.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/image/metrics.h"
#include "impostor/impostor_fixture.h"
#include "impostor/layered_cluster.h"

namespace farfield::impostor {
namespace {

using test::BoxScene;
using test::Cluster;
using test::ImpostorGpuTest;
using test::testBound;
using test::viewFrom;

// Angle (radians) between a and b seen from eye, in double.
double angleAt(const DVec3& eye, const DVec3& a, const DVec3& b) {
  const DVec3 u = a - eye, v = b - eye;
  return std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v));
}

// Where the capture eye's ray through p meets the plane of depth `plane` (the point a layer draws p at).
DVec3 onPlane(const LayeredPlan& plan, const DVec3& p, double plane) {
  const DVec3 e(plan.capture_eye), apex(plan.shaft.apex), axis(plan.shaft.axis);
  const double d = plan.shaft.min_distance;
  const double zp = glm::dot(p - apex, axis);
  return e + (p - e) * ((d - plane) / (d - zp));
}

struct SpacingCheck {
  double worst = 0.0;        // largest angle between a boundary point and its drawn place, radians
  double worst_ratio = 0.0;  // the same over the plan's error_angle
  double worst_crack = 0.0;  // largest angle between a boundary point's places on its two neighbouring planes
};

// Brute force over viewpoints sampled in the shaft (near ones densely: parallax falls with distance) and points of
// the box on the layer boundaries (the farthest from a layer plane), each drawn on both neighbouring planes.
SpacingCheck checkSpacing(const LayeredPlan& plan, std::mt19937& rng, int viewpoints, int points) {
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const DVec3 apex(plan.shaft.apex), axis(plan.shaft.axis), right(plan.right), up(plan.up);
  // The frame box of the cluster, for rejection sampling on the boundary planes.
  double ulo = 1e30, uhi = -1e30, vlo = 1e30, vhi = -1e30;
  for (int i = 0; i < 8; ++i) {
    const DVec3 c = DVec3((i & 1) ? plan.box.hi.x : plan.box.lo.x, (i & 2) ? plan.box.hi.y : plan.box.lo.y,
                          (i & 4) ? plan.box.hi.z : plan.box.lo.z) - apex;
    ulo = std::min(ulo, glm::dot(c, right)), uhi = std::max(uhi, glm::dot(c, right));
    vlo = std::min(vlo, glm::dot(c, up)), vhi = std::max(vhi, glm::dot(c, up));
  }
  const Box3 inside{plan.box.lo - Vec3(1e-4f), plan.box.hi + Vec3(1e-4f)};
  std::vector<DVec3> eyes;
  for (int i = 0; i < viewpoints; ++i) {
    // Distances up to 4 d, squared so that half lie within 1.75 d; rims (v = 1) one time in four.
    const float u = unit(rng);
    const float v = i % 4 == 0 ? 1.0f : unit(rng);
    eyes.push_back(DVec3(plan.shaft.sample(u * u, v, unit(rng), 4.0f * plan.shaft.min_distance)));
  }
  SpacingCheck out;
  const size_t n = plan.layers.size();
  for (int k = 0; k < points; ++k) {
    const size_t boundary = size_t(k) % (n + 1);  // 0 = the far side of layer 0, n = the near side of the last
    const double z = boundary < n ? plan.layers[boundary].z_lo : plan.layers[n - 1].z_hi;
    DVec3 p;
    bool found = false;
    for (int attempt = 0; attempt < 200 && !found; ++attempt) {
      p = apex + axis * z + right * (ulo + (uhi - ulo) * unit(rng)) + up * (vlo + (vhi - vlo) * unit(rng));
      found = inside.contains(Vec3(p));
    }
    if (!found) continue;
    std::vector<double> planes;
    if (boundary > 0) planes.push_back(plan.layers[boundary - 1].depth);
    if (boundary < n) planes.push_back(plan.layers[boundary].depth);
    for (double plane : planes) {
      const DVec3 q = onPlane(plan, p, plane);
      for (const DVec3& eye : eyes) {
        const double a = angleAt(eye, p, q);
        out.worst = std::max(out.worst, a);
        out.worst_ratio = std::max(out.worst_ratio, a / plan.error_angle);
      }
    }
    if (planes.size() == 2) {
      const DVec3 q0 = onPlane(plan, p, planes[0]), q1 = onPlane(plan, p, planes[1]);
      for (const DVec3& eye : eyes) out.worst_crack = std::max(out.worst_crack, angleAt(eye, q0, q1));
    }
  }
  return out;
}

TEST(LayeredPlanTest, SpacingKeepsTheParallaxOfBoundaryPointsUnderTheBoundFromTheWholeShaft) {
  std::mt19937 rng(2005);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const float apex_angles[] = {11.25f, 22.5f, 45.0f, 90.0f, 150.0f, 180.0f};
  const float distances[] = {1.6f, 3.0f, 12.0f};  // times the box's half diagonal
  ErrorBound bound;
  bound.pixels = 1.0;
  bound.width = bound.height = 512;
  bound.fov_y = degToRad(45.0);  // the paper's setting (section 6.2)
  double worst_ratio = 0.0, least_ratio = 1e30;
  int plans = 0;
  for (float apex_angle : apex_angles)
    for (float distance : distances)
      for (int trial = 0; trial < 4; ++trial) {
        const Vec3 extent(2.0f + 30.0f * unit(rng), 2.0f + 30.0f * unit(rng), 2.0f + 30.0f * unit(rng));
        const Vec3 centre(100.0f * unit(rng), 100.0f * unit(rng), 10.0f * unit(rng));
        const Box3 box = Box3::fromPoints(centre - 0.5f * extent, centre + 0.5f * extent);
        Vec3 axis(unit(rng) - 0.5f, unit(rng) - 0.5f, unit(rng) - 0.3f);
        if (trial == 0) axis = Vec3(0.0f, -1.0f, 0.0f);  // along a box axis: faces on the slab planes
        // The apex off the box's centre now and then (the cluster's centre need not be its box's).
        const Vec3 apex = centre + (trial == 2 ? 0.2f * extent * Vec3(unit(rng), -unit(rng), unit(rng)) : Vec3(0.0f));
        const float half_diagonal = 0.5f * glm::length(extent);
        const Shaft shaft = Shaft::make(apex, axis, float(degToRad(apex_angle)), distance * half_diagonal * 2.0f);
        LayeredOptions options;
        options.max_layers = 100000;
        options.bound_cracks = trial == 3;
        const LayeredPlan plan = planLayered(box, shaft, bound, options);
        ASSERT_FALSE(plan.layers_capped);
        ASSERT_LE(plan.error_angle, plan.bound_angle * (1.0 + 1e-9));
        ASSERT_LE(plan.spacing, plan.max_spacing * (1.0 + 1e-9));
        // The count is the smallest that fits: one layer fewer would exceed the allowed spacing.
        const double depth = double(plan.z_hi) - plan.z_lo;
        if (plan.layers.size() > 1) {
          EXPECT_GT(depth / double(plan.layers.size() - 1), plan.max_spacing);
        }
        const SpacingCheck check = checkSpacing(plan, rng, 300, 40 * int(std::min<size_t>(plan.layers.size(), 50)));
        EXPECT_LE(check.worst, plan.error_angle * (1.0 + 1e-6))
            << "apex " << apex_angle << " deg, distance " << shaft.min_distance << ", " << plan.layers.size()
            << " layers: measured " << check.worst << " rad, bound " << plan.error_angle;
        EXPECT_LE(check.worst, bound.angle() * (1.0 + 1e-6));
        // Cracks: a boundary point drawn on both neighbouring planes, in opposite directions from its place.
        EXPECT_LE(check.worst_crack, 2.0 * plan.error_angle * (1.0 + 1e-6));
        if (options.bound_cracks) {
          EXPECT_LE(check.worst_crack, bound.angle() * (1.0 + 1e-6));
        }
        worst_ratio = std::max(worst_ratio, check.worst_ratio);
        least_ratio = std::min(least_ratio, check.worst_ratio);
        ++plans;
      }
  // The bound is an upper bound and not a loose one: the sampled worst case comes close to it.
  RecordProperty("worst_ratio", std::to_string(worst_ratio));
  RecordProperty("least_ratio", std::to_string(least_ratio));
  std::printf("spacing: %d plans, measured / bound between %.3f and %.3f\n", plans, least_ratio, worst_ratio);
  EXPECT_GT(worst_ratio, 0.7);
  EXPECT_GT(least_ratio, 0.15);
}

TEST(LayeredPlanTest, LayersAndTexelsFollowTheShaftAndTheBound) {
  const Box3 box = Box3::fromPoints(Vec3(-10.0f), Vec3(10.0f));
  ErrorBound bound;  // 10 px at 640 x 360, 60 degrees
  const auto count = [&](float apex_deg, float distance, double pixels) {
    ErrorBound b = bound;
    b.pixels = pixels;
    return planLayered(box, Shaft::make(Vec3(0.0f), Vec3(1.0f, 0.2f, 0.1f), float(degToRad(apex_deg)), distance), b)
        .layers.size();
  };
  // Wider shafts, nearer viewers and tighter bounds need more layers; far enough, one layer does.
  EXPECT_LT(count(11.25f, 100.0f, 2.0), count(45.0f, 100.0f, 2.0));
  EXPECT_LT(count(45.0f, 400.0f, 2.0), count(45.0f, 100.0f, 2.0));
  EXPECT_LT(count(45.0f, 100.0f, 4.0), count(45.0f, 100.0f, 1.0));
  EXPECT_EQ(count(11.25f, 20000.0f, 2.0), 1u);

  // Texels: at most one (corner) pixel of the bound's frame from every viewpoint of the shaft (sampled, against the
  // corners and centre of each layer's quad), exactly one from the nearest; or coarser when capped.
  const Shaft wide = Shaft::make(Vec3(0.0f), Vec3(0, -1, 0), 0.5f, 60.0f);
  const LayeredPlan plan = planLayered(box, wide, bound);
  EXPECT_NEAR(plan.texel_angle, bound.cornerPixelAngle(), 1e-9);
  EXPECT_FALSE(plan.resolution_capped);
  ASSERT_GE(plan.layers.size(), 3u);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double tightest = 0.0;
  for (const LayerPlan& layer : plan.layers) {
    const double texel = 2.0 * layer.half_u / layer.width;
    EXPECT_NEAR(2.0 * layer.half_v / layer.height, texel, 1e-6);
    const Vec3 centre = wide.apex + layer.depth * wide.axis;
    for (int k = 0; k < 2000; ++k) {
      const Vec3 eye = wide.sample(u(rng), u(rng), u(rng), 3.0f * wide.min_distance);
      for (const Vec2 corner : {Vec2(0.0f), Vec2(-1, -1), Vec2(-1, 1), Vec2(1, -1), Vec2(1, 1)}) {
        const Vec3 p = centre + corner.x * layer.half_u * plan.right + corner.y * layer.half_v * plan.up;
        const double angle = texel / double(glm::length(eye - p));
        EXPECT_LE(angle, bound.cornerPixelAngle() * (1.0 + 1e-4));
        tightest = std::max(tightest, angle);
      }
    }
  }
  EXPECT_GT(tightest, 0.5 * bound.cornerPixelAngle());  // not needlessly fine
  // The far side of the cluster, seen from further away, has coarser texels than the near side.
  const auto texel = [](const LayerPlan& l) { return 2.0 * l.half_u / l.width; };
  EXPECT_GT(texel(plan.layers.front()), 1.1 * texel(plan.layers.back()));
  LayeredOptions capped;
  capped.max_texture_size = 16;
  const LayeredPlan small = planLayered(box, Shaft::make(Vec3(0.0f), Vec3(0, -1, 0), 0.5f, 200.0f), bound, capped);
  EXPECT_TRUE(small.resolution_capped);
  EXPECT_GT(small.texel_angle, 5.0 * bound.cornerPixelAngle());
  for (const LayerPlan& layer : small.layers) EXPECT_LE(std::max(layer.width, layer.height), 16);

  // Too few layers allowed: the plan says it cannot keep the bound.
  LayeredOptions few;
  few.max_layers = 1;
  const LayeredPlan one = planLayered(box, Shaft::make(Vec3(0.0f), Vec3(0, -1, 0), 1.5f, 60.0f), bound, few);
  EXPECT_TRUE(one.layers_capped);
  EXPECT_FALSE(one.keepsBound());
  EXPECT_GT(one.error_angle, bound.angle());
}

TEST(LayeredPlanTest, BadInputIsAnErrorNamingIt) {
  const Box3 box = Box3::fromPoints(Vec3(-5.0f), Vec3(5.0f));
  const Shaft shaft = Shaft::make(Vec3(0.0f), Vec3(0, -1, 0), 0.5f, 100.0f);
  const ErrorBound bound;
  const auto message = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  using ::testing::HasSubstr;
  EXPECT_THAT(message([&] { planLayered(Box3{}, shaft, bound); }), HasSubstr("layered impostor box"));
  Box3 nan_box = box;
  nan_box.hi.x = std::nanf("");
  EXPECT_THAT(message([&] { planLayered(nan_box, shaft, bound); }), HasSubstr("layered impostor box"));
  ErrorBound zero = bound;
  zero.pixels = 0.0;
  EXPECT_THAT(message([&] { planLayered(box, shaft, zero); }), HasSubstr("layered impostor error bound"));
  ErrorBound no_frame = bound;
  no_frame.width = 0;
  EXPECT_THAT(message([&] { planLayered(box, shaft, no_frame); }), HasSubstr("layered impostor error bound"));
  // Viewpoints next to or inside the cluster.
  const Shaft inside = Shaft::make(Vec3(0.0f), Vec3(0, -1, 0), 0.5f, 6.0f);
  EXPECT_THAT(message([&] { planLayered(box, inside, bound); }), HasSubstr("layered impostor shaft"));
  Shaft bad_angle = shaft;
  bad_angle.apex_angle = 0.0f;
  EXPECT_THAT(message([&] { planLayered(box, bad_angle, bound); }), HasSubstr("layered impostor shaft"));
  LayeredOptions options;
  options.max_texture_size = 0;
  EXPECT_THAT(message([&] { planLayered(box, shaft, bound, options); }), HasSubstr("layered impostor options"));
}

// --- rendered -----------------------------------------------------------------------------------------------------

// How far each pixel is from being right (pixels): a pixel showing object A where the reference shows B is right
// after a move of min(distance in the impostor frame to a pixel showing B, distance in the reference to a pixel
// showing A); background counts as an object. Ids, unlike colours, have no filtering or shading in them, so this is
// the geometric displacement of what the pixel shows: a silhouette moved by s pixels gives at most s, a crack w pixels
// wide between two layers (the same surface drawn on both, apart) at most w / 2, and a missing or misplaced object
// its full extent. Searched up to `radius`.
struct Displacement {
  double max = 0.0;
  size_t over = 0;  // pixels displaced by more than the threshold given
  size_t wrong = 0;  // pixels showing another object than the reference
};
double nearest(const image::IdImage& ids, int x, int y, uint32_t id, int radius) {
  double best = radius + 1.0;
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx) {
      const int nx = x + dx, ny = y + dy;
      if (nx < 0 || ny < 0 || nx >= ids.width() || ny >= ids.height() || ids.at(nx, ny) != id) continue;
      best = std::min(best, std::hypot(double(dx), double(dy)));
    }
  return best;
}
Displacement displacement(const image::IdImage& reference, const image::IdImage& drawn, double threshold,
                          int radius = 24) {
  Displacement out;
  for (int y = 0; y < reference.height(); ++y)
    for (int x = 0; x < reference.width(); ++x) {
      const uint32_t want = reference.at(x, y), got = drawn.at(x, y);
      if (want == got) continue;
      ++out.wrong;
      const double moved = std::min(nearest(drawn, x, y, want, radius), nearest(reference, x, y, got, radius));
      out.max = std::max(out.max, moved);
      out.over += moved > threshold ? 1 : 0;
    }
  return out;
}

struct Comparison {
  double max_px = 0.0;           // largest displacement, either direction, over the viewpoints
  size_t over = 0;               // pixels over the threshold
  size_t wrong = 0;              // pixels showing another object, over the viewpoints
  double bad_color_share = 0.0;  // largest share of pixels whose colour differs by more than 24/255
};

Comparison compareFromShaft(gpu::Renderer& renderer, const Cluster& c, const gpu::GpuScene& scene,
                            const GpuLayeredImpostor& impostor, const ErrorBound& bound, double threshold) {
  std::vector<gpu::DrawItem> geometry, layers;
  scene.appendDrawItems(c.ids, geometry);
  impostor.appendDrawItems(layers);
  // Fixed viewpoints: the nearest ones, where parallax is largest, including the rim of the cone.
  const float samples[][3] = {{0.0f, 1.0f, 0.0f},  {0.0f, 1.0f, 0.25f}, {0.0f, 1.0f, 0.6f}, {0.2f, 0.5f, 0.8f},
                              {0.5f, 1.0f, 0.4f}, {0.0f, 0.0f, 0.0f},  {1.0f, 0.8f, 0.1f}};
  Comparison out;
  for (const auto& s : samples) {
    const Camera camera = viewFrom(c.shaft.sample(s[0], s[1], s[2], 2.0f * c.shaft.min_distance), c.shaft, bound);
    const test::Frame reference = test::renderItems(renderer, camera, geometry);
    const test::Frame drawn = test::renderItems(renderer, camera, layers);
    const Displacement moved = displacement(reference.ids, drawn.ids, threshold);
    out.max_px = std::max(out.max_px, moved.max);
    out.over += moved.over;
    out.wrong += moved.wrong;
    out.bad_color_share = std::max(out.bad_color_share, image::shareOverThreshold(reference.color, drawn.color, 24));
  }
  return out;
}

TEST_F(ImpostorGpuTest, LayeredImpostorMatchesGeometryFromTheShaftAndOneLayerDoesNot) {
  const Cluster c;
  const gpu::GpuScene scene(c.s.scene);
  const ErrorBound bound = testBound();
  const LayeredPlan plan = planLayered(c.box, c.shaft, bound);
  ASSERT_TRUE(plan.keepsBound());
  ASSERT_GE(plan.layers.size(), 4u);
  const GpuLayeredImpostor layered(captureLayered(*renderer_, scene, c.ids, plan));
  // The bound in pixels anywhere in the frame, plus the sampling: half a texel (at most a pixel) where the capture
  // rasterised, half a pixel where the frame does, and bilinear alpha at the cut-out edge.
  const double threshold = bound.pixels + 2.0;
  const Comparison good = compareFromShaft(*renderer_, c, scene, layered, bound, threshold);

  LayeredOptions one_layer;
  one_layer.layer_count = 1;
  const LayeredPlan flat = planLayered(c.box, c.shaft, bound, one_layer);
  const GpuLayeredImpostor single(captureLayered(*renderer_, scene, c.ids, flat));
  const Comparison bad = compareFromShaft(*renderer_, c, scene, single, bound, threshold);
  // The same layers holding only the faces turned towards the capture eye: the box sides along the axis, which the
  // shaft's other viewpoints see, are missing.
  LayeredOptions hollow_options;
  hollow_options.solid_slices = false;
  const GpuLayeredImpostor hollow(
      captureLayered(*renderer_, scene, c.ids, planLayered(c.box, c.shaft, bound, hollow_options)));
  const Comparison holes = compareFromShaft(*renderer_, c, scene, hollow, bound, threshold);
  std::printf("rendered: %zu layers (bound %.2f px): max displacement %.2f px, %zu px over %.1f, %zu wrong, colour "
              "share %.4f\n  one layer (plan %.1f px): %.2f px, %zu px over, %zu wrong, colour share %.4f\n  hollow "
              "slices: %.2f px, %zu px over, %zu wrong\n",
              plan.layers.size(), bound.pixelsOf(plan.error_angle), good.max_px, good.over, threshold, good.wrong,
              good.bad_color_share, bound.pixelsOf(flat.error_angle), bad.max_px, bad.over, bad.wrong,
              bad.bad_color_share, holes.max_px, holes.over, holes.wrong);
  EXPECT_LE(good.max_px, threshold);
  EXPECT_EQ(good.over, 0u);
  EXPECT_GT(flat.error_angle, 3.0 * bound.angle());
  EXPECT_GT(bad.max_px, threshold + 2.0);
  EXPECT_GT(bad.over, 20u);
  EXPECT_GT(bad.bad_color_share, 2.0 * good.bad_color_share);
  EXPECT_GT(bad.wrong, 4 * good.wrong);
  EXPECT_GT(holes.wrong, 2 * good.wrong);
}

TEST_F(ImpostorGpuTest, LayeredPlanEstimatesAreTheMeasuredMemory) {
  const Cluster c;
  const gpu::GpuScene scene(c.s.scene);
  for (bool ids : {true, false}) {
    LayeredOptions options;
    options.id_textures = ids;
    const LayeredPlan plan = planLayered(c.box, c.shaft, testBound(), options);
    const LayeredImpostor impostor = captureLayered(*renderer_, scene, c.ids, plan);
    // The plan counts a quad a layer; drawn as tiles, the rectangles are counted once measured (layer_tiles_test).
    const GpuLayeredImpostor gpu_impostor(impostor, LayerDraw::WholeQuads);
    EXPECT_EQ(gpu_impostor.gpuBytes(), plan.bytes());
    EXPECT_EQ(impostor.cpuBytes(), size_t(plan.texels) * 4 * (ids ? 2 : 1));
    EXPECT_GE(plan.texture_bytes, impostor.cpuBytes());  // the atlases hold every layer (and their padding)
    EXPECT_EQ(gpu_impostor.quads(), plan.quads());
    EXPECT_EQ(gpu_impostor.draws(), plan.draws());
    EXPECT_LT(plan.draws(), plan.quads());  // the layers share atlases: fewer draw calls than layers
    uint64_t texels = 0;
    size_t data = 0;
    for (const Layer& layer : impostor.layers) {
      texels += layer.color.pixelCount();
      data += layer.data_texels;
      EXPECT_GT(layer.data_texels, 0u);  // every slab of this cluster holds something
    }
    EXPECT_EQ(texels, plan.texels);
    // The textures are mostly data: the footprints are the slabs' own, not the whole box's.
    EXPECT_GT(double(data) / double(texels), 0.1);
    std::vector<gpu::DrawItem> items;
    gpu_impostor.appendDrawItems(items, 7);
    ASSERT_EQ(items.size(), plan.draws());  // one draw call per atlas
  }
}

TEST_F(ImpostorGpuTest, CroppedLayersDrawTheSameImageWithFewerTexels) {
  const Cluster c;
  const gpu::GpuScene scene(c.s.scene);
  const ErrorBound bound = testBound();
  const LayeredImpostor full = captureLayered(*renderer_, scene, c.ids, planLayered(c.box, c.shaft, bound));
  const LayeredImpostor cropped = cropLayered(full);
  ASSERT_TRUE(cropped.plan.cropped);
  EXPECT_LT(cropped.plan.texels, full.plan.texels);
  EXPECT_LT(cropped.plan.bytes(), full.plan.bytes());
  for (size_t i = 0; i < full.layers.size(); ++i) {
    // Nothing but transparent black outside the crop, and the crop's texels are the captured ones.
    const LayerPlan& lp = cropped.plan.layers[i];
    const Layer& a = full.layers[i];
    const Layer& b = cropped.layers[i];
    ASSERT_EQ(b.color.width(), lp.width);
    size_t data_outside = 0;
    for (int y = 0; y < a.color.height(); ++y)
      for (int x = 0; x < a.color.width(); ++x) {
        const bool inside = x >= lp.crop_x && y >= lp.crop_y && x < lp.crop_x + lp.width && y < lp.crop_y + lp.height;
        if (inside)
          ASSERT_EQ(b.color.at(x - lp.crop_x, y - lp.crop_y), a.color.at(x, y));
        else
          data_outside += a.color.at(x, y) != image::Rgba8(0, 0, 0, 0) || a.ids.at(x, y) != 0 ? 1 : 0;
      }
    EXPECT_EQ(data_outside, 0u) << "layer " << i;
    EXPECT_EQ(b.data_texels, a.data_texels);
  }
  // From the shaft's viewpoints the two draw the same pixels (ids exactly, colours up to rounding of the moved
  // quads' texture coordinates).
  const GpuLayeredImpostor gpu_full(full), gpu_cropped(cropped);
  EXPECT_EQ(gpu_cropped.gpuBytes(), cropped.plan.bytes());
  std::vector<gpu::DrawItem> items_full, items_cropped;
  gpu_full.appendDrawItems(items_full);
  gpu_cropped.appendDrawItems(items_cropped);
  test::expectSameImage(*renderer_, c, bound, items_full, items_cropped);
  // A crop outside its image, a wrong count, or cropping twice are errors.
  LayeredPlan plan = full.plan;
  std::vector<LayerCrop> crops(plan.layers.size(), LayerCrop{0, 0, 1, 1});
  crops[0] = {plan.layers[0].width, 0, 1, 1};
  EXPECT_THROW(cropLayers(plan, crops), Error);
  EXPECT_THROW(cropLayers(plan, std::vector<LayerCrop>(1, LayerCrop{0, 0, 1, 1})), Error);
  LayeredPlan twice = cropped.plan;
  EXPECT_THROW(cropLayers(twice, std::vector<LayerCrop>(twice.layers.size(), LayerCrop{0, 0, 1, 1})), Error);
  EXPECT_THROW(captureLayered(*renderer_, scene, c.ids, cropped.plan), Error);
}

TEST_F(ImpostorGpuTest, LayeredCaptureRejectsObjectsNotInTheSceneOrOutsideTheBox) {
  const Cluster c;
  const gpu::GpuScene scene(c.s.scene);
  const LayeredPlan plan = planLayered(c.box, c.shaft, testBound());
  const std::vector<uint32_t> missing = {1, 99}, zero = {0}, none;
  EXPECT_THROW(captureLayered(*renderer_, scene, missing, plan), Error);
  EXPECT_THROW(captureLayered(*renderer_, scene, zero, plan), Error);
  EXPECT_THROW(captureLayered(*renderer_, scene, none, plan), Error);
  EXPECT_THROW(captureLayered(*renderer_, scene, c.ids, LayeredPlan{}), Error);
  // A plan for a box holding only the first object, asked to capture the second one too.
  const LayeredPlan part = planLayered(c.s.boxes[0], c.shaft, testBound());
  const std::vector<uint32_t> two = {c.ids[0], c.ids[1]};
  try {
    captureLayered(*renderer_, scene, two, part);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("layered impostor object 2"));
  }
}

}  // namespace
}  // namespace farfield::impostor
