// The crowd's shadows: the light box's fit (no GL) and, on the shared headless context, one agent's shadow on the
// ground against a CPU projection of its skinned mesh along the light, for skinned and impostor casters.
#include "farfield/runtime/crowd_shadows.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/image/png_io.h"
#include "farfield/runtime/crowd_runtime.h"
#include "farfield/scene/gltf_skin.h"
#include "grey_quad.h"
#include "support/test_support.h"

namespace farfield::runtime {
namespace {

Camera streetCamera() {
  Camera c;
  c.eye = Vec3(0, 0, 1.7f);
  c.at = Vec3(10, 2, 1.0f);
  c.width = 256;
  c.height = 192;
  return c;
}

// Every caster left out lies outside the receivers' light-space bounds (brute force over dense receiver samples),
// every caster kept has a footprint meeting them, and each kept sphere projects inside the map.
TEST(CrowdShadows, FitKeepsExactlyTheSpheresThatCanShadowWhatIsSeen) {
  const Camera camera = streetCamera();
  const Vec3 light(-0.4f, -0.3f, -0.85f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> x(-60.0f, 120.0f), y(-80.0f, 80.0f);
  std::vector<CasterSphere> spheres(400);
  for (CasterSphere& s : spheres) s = {Vec3(x(rng), y(rng), 0.9f), 0.95f};
  const float distance = 40.0f;
  const ShadowFit fit = fitShadow(camera, light, spheres, distance, 1024);
  ASSERT_FALSE(fit.casters.empty());
  ASSERT_LT(fit.casters.size(), spheres.size());
  // Independent check: a sphere can shadow a seen point within `distance` only if some point of the view frustum
  // (sampled) lies on the light's line through the sphere, i.e. its distance to that line is at most the radius.
  const Vec3 f = glm::normalize(light);
  const Vec3 fwd = camera.forward(), right = glm::normalize(glm::cross(fwd, camera.up)), up = glm::cross(right, fwd);
  const float ty = std::tan(camera.fov_y / 2.0f), tx = ty * camera.aspect();
  std::vector<Vec3> samples;
  for (int i = 0; i <= 24; ++i)
    for (int j = 0; j <= 24; ++j)
      for (int k = 0; k <= 24; ++k) {
        const float d = camera.near_plane + (distance - camera.near_plane) * float(k) / 24.0f;
        const Vec3 ray = fwd + right * (tx * (-1.0f + float(i) / 12.0f)) + up * (ty * (-1.0f + float(j) / 12.0f));
        samples.push_back(camera.eye + ray * d);  // at distance d along the view axis
      }
  auto canShadow = [&](const CasterSphere& s, float slack) {
    for (const Vec3& p : samples) {
      const Vec3 v = p - s.centre;
      if (glm::length(v - f * glm::dot(v, f)) <= s.radius + slack) return true;
    }
    return false;
  };
  size_t kept = 0;
  for (size_t i = 0; i < spheres.size(); ++i) {
    const bool in = std::binary_search(fit.casters.begin(), fit.casters.end(), uint32_t(i));
    kept += in;
    // The fit uses the axis-aligned light-space bounds of the frustum: a superset of the exact test, never less.
    if (canShadow(spheres[i], -0.05f)) {
      EXPECT_TRUE(in) << "sphere " << i << " shadows what is seen but was left out";
    }
    if (in) {
      // Its footprint meets the map (its centre within a radius of it).
      const Vec4 c = fit.projection.view_proj * Vec4(spheres[i].centre, 1.0f);
      const float r = spheres[i].radius * 2.0f / (fit.projection.texel_m * 1024.0f);
      EXPECT_LE(std::abs(c.x), 1.0f + r + 1e-4f);
      EXPECT_LE(std::abs(c.y), 1.0f + r + 1e-4f);
      EXPECT_GE(c.z, 0.0f);
      EXPECT_LE(c.z, 1.0f);
    }
  }
  EXPECT_EQ(kept, fit.casters.size());
  EXPECT_GT(fit.projection.texel_m, 0.0f);
  // Where the shadows can fall on screen, for the spheres well in front of the camera (nearer ones make the fit
  // take the whole frame): points of each kept sphere swept along the light down to a metre below its lowest point
  // (sampled on the sphere's surface at both ends and between) project inside some caster's rectangle.
  std::vector<CasterSphere> ahead;
  for (const CasterSphere& s : spheres)
    if (s.centre.x > 8.0f) ahead.push_back(s);
  const ShadowFit near_fit = fitShadow(camera, light, ahead, distance, 1024);
  ASSERT_GT(near_fit.screen_rects.size(), 3u);
  const Mat4 vp = camera.viewProjection();
  size_t tested = 0;
  for (uint32_t i : near_fit.casters) {
    const CasterSphere& s = ahead[i];
    const float drop = (2.0f * s.radius + 1.0f) / -f.z;
    for (int k = 0; k <= 8; ++k)
      for (int a = 0; a < 12; ++a)
        for (int b = 0; b < 6; ++b) {
          const float th = float(a) * float(kPi) / 6.0f, ph = -float(kPi) / 2.0f + float(b) * float(kPi) / 5.0f;
          const Vec3 p = s.centre + f * (drop * float(k) / 8.0f) +
                         s.radius * Vec3(std::cos(ph) * std::cos(th), std::cos(ph) * std::sin(th), std::sin(ph));
          const Vec4 clip = vp * Vec4(p, 1.0f);
          ASSERT_GT(clip.w, camera.near_plane);
          const Vec2 px = (Vec2(clip) / clip.w * 0.5f + 0.5f) * Vec2(float(camera.width), float(camera.height));
          if (px.x < 0.0f || px.y < 0.0f || px.x >= float(camera.width) || px.y >= float(camera.height)) continue;
          ++tested;
          bool inside = false;
          for (const glm::ivec4& r : near_fit.screen_rects)
            inside = inside || (px.x >= float(r.x) && px.x < float(r.z) && px.y >= float(r.y) && px.y < float(r.w));
          EXPECT_TRUE(inside) << "sphere " << i << " point at pixel " << px.x << ", " << px.y;
        }
  }
  EXPECT_GT(tested, 100u);
  EXPECT_THROW(fitShadow(camera, Vec3(0.0f), spheres, distance, 1024), Error);
}

class CrowdShadowsGl : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

// Pixel centres inside the triangle (a, b, c) in pixel coordinates.
void rasterise(const Vec2& a, const Vec2& b, const Vec2& c, int w, int h, std::vector<uint8_t>& mask) {
  const float area = cross2(b - a, c - a);
  if (std::abs(area) < 1e-12f) return;
  const int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x})))),
            x1 = std::min(w - 1, int(std::ceil(std::max({a.x, b.x, c.x}))));
  const int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y})))),
            y1 = std::min(h - 1, int(std::ceil(std::max({a.y, b.y, c.y}))));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const Vec2 p(float(x) + 0.5f, float(y) + 0.5f);
      const float u = cross2(b - a, p - a) / area, v = cross2(c - b, p - b) / area, t = cross2(a - c, p - c) / area;
      if (u >= 0.0f && v >= 0.0f && t >= 0.0f) mask[size_t(y) * size_t(w) + size_t(x)] = 1;
    }
}

TEST_F(CrowdShadowsGl, AnAgentDarkensTheGroundWhereItsSilhouetteFallsAlongTheLight) {
  FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
  const scene::SkinnedModel man = scene::importSkinnedModel(man_glb.string());
  CrowdRuntimeOptions o;
  o.palette_poses = 4;
  o.frames = 4;
  o.texel_m = 0.015f;
  CrowdModelOptions mo;
  mo.facing_deg = 0.0f;
  CrowdRuntime rt(std::span(&man, 1), std::span(&mo, 1), o);

  // The ground: a 20 m quad at z = 0, grey, drawn by the city's renderer.
  const test::GreyQuad ground_quad({Vec3(-10, -10, 0), Vec3(10, -10, 0), Vec3(10, 10, 0), Vec3(-10, 10, 0)},
                                   Vec3(0, 0, 1), 0.6f);
  const gpu::DrawItem& item = ground_quad.item;
  const gpu::GpuMaterial& grey = ground_quad.material;
  gpu::Renderer renderer;
  const gpu::LightSettings light = renderer.light();

  Camera camera;
  camera.eye = Vec3(1.2f, -3.2f, 3.0f);
  camera.at = Vec3(-0.5f, -0.4f, 0.2f);
  camera.width = camera.height = 200;
  camera.near_plane = 0.5f;
  camera.far_plane = 100.0f;
  std::vector<CrowdAgentState> agents(1);
  agents[0].heading = 0.6f;
  agents[0].phase = 0.25f;  // palette pose 1 of 4
  agents[0].object_id = kAgentIdBit | 7u;

  // CPU: the skinned mesh in the world, each triangle projected along the light onto z = 0, then into the image.
  const scene::Animation& walk = man.animations[size_t(man.findAnimation("walk"))];
  const scene::Mesh posed = scene::skinMesh(man, scene::jointMatrices(man, &walk, walk.start + walk.duration * 0.25f));
  const Mat4 agent_to_world = glm::rotate(Mat4(1.0f), agents[0].heading, Vec3(0, 0, 1)) * rt.gpuModel(0).modelToAgent();
  const Vec3 d = glm::normalize(light.direction);
  std::vector<uint8_t> expected(size_t(camera.width) * size_t(camera.height), 0);
  auto toPixel = [&](const Vec3& p) {
    const Vec3 world = Vec3(agent_to_world * Vec4(p, 1.0f));
    const Vec3 q = world - d * (world.z / d.z);
    return Vec2(camera.project(q));
  };
  for (size_t t = 0; t < posed.triangleCount(); ++t)
    rasterise(toPixel(posed.positions[posed.indices[3 * t]]), toPixel(posed.positions[posed.indices[3 * t + 1]]),
              toPixel(posed.positions[posed.indices[3 * t + 2]]), camera.width, camera.height, expected);

  gpu::RenderTarget plain(200, 200), geometry(200, 200), impostor(200, 200);
  auto frame = [&](gpu::RenderTarget& t, int kind) {
    renderer.render(camera, std::span(&item, 1), t);
    CrowdShadowOptions so;
    so.map_size = 1024;
    if (kind == 0) {
      t.bindForOpaquePass();
      rt.draw(camera, agents, CrowdPolicy::Geometry, light);
    } else {
      const CrowdFrameStats st =
          rt.drawShadowed(camera, agents, kind == 1 ? CrowdPolicy::Geometry : CrowdPolicy::Impostor, light, t, so);
      EXPECT_EQ(st.shadow_casters, 1u);
    }
    rt.finish();
  };
  frame(plain, 0);
  frame(geometry, 1);
  frame(impostor, 2);
  const int w = camera.width, h = camera.height;
  const image::ColorImage a = plain.readColor(), g = geometry.readColor(), im = impostor.readColor();
  const image::IdImage ia = plain.readIds(), ig = geometry.readIds(), ii = impostor.readIds();
  if (std::getenv("FF_DEBUG_SHADOW")) {
    image::writePng("/tmp/sh_plain.png", a);
    image::writePng("/tmp/sh_geo.png", g);
    image::writePng("/tmp/sh_imp.png", im);
    image::ColorImage m(w, h);
    for (size_t i = 0; i < m.pixelCount(); ++i) m.pixels()[i] = expected[i] ? image::Rgba8{255, 0, 0, 255} : a.pixels()[i];
    image::writePng("/tmp/sh_expected.png", m);
  }
  // The ground lit and in shadow, written out from the shading model.
  const float ndl = std::max(-d.z, 0.0f);
  const Vec3 lit = Vec3(grey.base_color) * (Vec3(light.ambient) + light.color * ndl);
  const Vec3 dark = Vec3(grey.base_color) * light.ambient;
  size_t ground = 0, both = 0, either = 0, inner = 0, inner_dark = 0, outer = 0, outer_dark = 0, value_off = 0,
         imp_both = 0, imp_either = 0;
  auto at = [&](int x, int y) { return expected[size_t(std::clamp(y, 0, h - 1)) * size_t(w) + size_t(std::clamp(x, 0, w - 1))]; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      if (ia.pixels()[i] != 1u || ig.pixels()[i] != 1u || ii.pixels()[i] != 1u) continue;  // the ground alone
      ++ground;
      ASSERT_LE(std::abs(int(a.pixels()[i].r) - int(std::lround(lit.r * 255.0f))), 2);
      const bool dg = int(a.pixels()[i].g) - int(g.pixels()[i].g) > 20;
      const bool di = int(a.pixels()[i].g) - int(im.pixels()[i].g) > 20;
      const bool e = expected[i] != 0;
      both += e && dg;
      either += e || dg;
      imp_both += dg && di;
      imp_either += dg || di;
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) n += at(x + dx, y + dy);
      if (n == 9) {
        ++inner;
        inner_dark += dg;
        value_off += std::abs(int(g.pixels()[i].r) - int(std::lround(dark.r * 255.0f))) > 3;
      } else if (n == 0) {
        ++outer;
        outer_dark += dg;
      }
    }
  ASSERT_GT(ground, 20000u);
  ASSERT_GT(inner, 150u) << "the shadow must be in view";
  EXPECT_GT(double(both), 0.85 * double(either)) << both << " of " << either;
  EXPECT_GT(double(inner_dark), 0.98 * double(inner)) << inner_dark << " of " << inner;
  EXPECT_LT(double(outer_dark), 0.002 * double(outer)) << outer_dark << " of " << outer;
  EXPECT_LT(double(value_off), 0.02 * double(inner)) << "shadowed ground keeps the ambient term alone";
  // The impostor, seen from the light's nearest view, casts nearly the geometry's shadow.
  EXPECT_GT(double(imp_both), 0.8 * double(imp_either)) << imp_both << " of " << imp_either;

  // Mixed with impostor casters: the near agent is drawn as geometry (the geometry frame's ids) and casts the
  // impostor's shadow (the impostor frame's ground, pixel for pixel, but next to the agent, where the receivers'
  // normals come from depths the two frames do not share); without the option, the geometry's shadow.
  auto groundInBoth = [&](int x, int y) {
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const size_t j = size_t(std::clamp(y + dy, 0, h - 1)) * size_t(w) + size_t(std::clamp(x + dx, 0, w - 1));
        if (ig.pixels()[j] != 1u || ii.pixels()[j] != 1u) return false;
      }
    return true;
  };
  for (bool impostor_casters : {true, false}) {
    gpu::RenderTarget mixed(200, 200);
    renderer.render(camera, std::span(&item, 1), mixed);
    CrowdShadowOptions so;
    so.map_size = 1024;
    so.impostor_casters = impostor_casters;
    const CrowdFrameStats st = rt.drawShadowed(camera, agents, CrowdPolicy::Mixed, light, mixed, so);
    rt.finish();
    EXPECT_EQ(st.geometry, 1u);
    const image::ColorImage mc = mixed.readColor();
    EXPECT_EQ(mixed.readIds().pixels(), ig.pixels());
    const image::ColorImage& shadow_of = impostor_casters ? im : g;
    size_t compared = 0, differ = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (!groundInBoth(x, y)) continue;
        const size_t i = size_t(y) * size_t(w) + size_t(x);
        ++compared;
        differ += mc.pixels()[i].r != shadow_of.pixels()[i].r || mc.pixels()[i].g != shadow_of.pixels()[i].g;
      }
    EXPECT_GT(compared, 20000u);
    EXPECT_EQ(differ, 0u) << (impostor_casters ? "impostor" : "geometry") << " casters";
  }
}

}  // namespace
}  // namespace farfield::runtime
