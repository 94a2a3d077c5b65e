#include "farfield/gpu/gpu_culler.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <set>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gpu/gl_barrier_check.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/render_target.h"
#include "gpu/gpu_fixture.h"
#include "gpu/street_scene.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

// A triangle as its three corner positions, rotated so that the smallest corner comes first (winding kept).
using Triangle = std::array<std::array<float, 3>, 3>;
Triangle canonical(const Vec3& a, const Vec3& b, const Vec3& c) {
  Triangle t{{{a.x, a.y, a.z}, {b.x, b.y, b.z}, {c.x, c.y, c.z}}};
  const size_t first = size_t(std::min_element(t.begin(), t.end()) - t.begin());
  std::rotate(t.begin(), t.begin() + std::ptrdiff_t(first), t.end());
  return t;
}

TEST_F(GpuTest, ArenaClustersHoldEveryTriangleOfTheirMeshOnceInsideTheirBounds) {
  const scene::Scene scene = test::streetCanyonScene(true);
  ArenaOptions options;
  const SceneArena arena(scene, options);
  const std::vector<uint32_t> indices = arena.readIndices();
  const std::vector<Vec3> positions = arena.readVertexPositions();
  uint64_t triangles = 0;
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
    const scene::Mesh& mesh = scene.meshes[m];
    std::multiset<Triangle> want, got;
    for (size_t i = 0; i < mesh.indices.size(); i += 3)
      want.insert(canonical(mesh.positions[mesh.indices[i]], mesh.positions[mesh.indices[i + 1]],
                            mesh.positions[mesh.indices[i + 2]]));
    const auto [first, count] = arena.meshClusters(m);
    for (uint32_t c = first; c < first + count; ++c) {
      const ArenaCluster& cluster = arena.clusters()[c];
      ASSERT_EQ(cluster.index_count % 3, 0u);
      ASSERT_LE(cluster.index_count / 3, options.max_triangles);
      std::set<uint32_t> vertices;
      for (uint32_t i = cluster.first_index; i < cluster.first_index + cluster.index_count; i += 3) {
        Vec3 p[3];
        for (int k = 0; k < 3; ++k) {
          const uint32_t v = cluster.base_vertex + indices[i + uint32_t(k)];
          ASSERT_LT(v, positions.size());
          vertices.insert(v);
          p[k] = positions[v];
          EXPECT_TRUE(cluster.bounds.contains(p[k])) << "mesh " << m << " cluster " << c;
          EXPECT_LE(glm::length(p[k] - cluster.center), cluster.radius * (1.0f + 1e-5f) + 1e-6f);
        }
        got.insert(canonical(p[0], p[1], p[2]));
      }
      EXPECT_LE(vertices.size(), options.max_vertices);
    }
    EXPECT_TRUE(got == want) << "mesh " << m << ": " << got.size() << " triangles in clusters, " << want.size()
                             << " in the mesh";
    triangles += want.size();
  }
  uint64_t instance_triangles = 0;
  for (const scene::Object& o : scene.objects)
    for (const scene::Part& part : o.parts) instance_triangles += scene.meshes[part.mesh].indices.size() / 3;
  EXPECT_EQ(arena.triangleCount(), instance_triangles);
  // Groups hold contiguous instances of one kind, and every instance is in its group.
  uint32_t next = 0;
  for (uint32_t g = 0; g < arena.groups().size(); ++g) {
    const MaterialGroup& group = arena.groups()[g];
    EXPECT_EQ(group.first_instance, next);
    for (uint32_t i = group.first_instance; i < group.first_instance + group.instance_count; ++i)
      EXPECT_EQ(arena.instances()[i].group, g);
    next += group.instance_count;
  }
  EXPECT_EQ(next, arena.instances().size());
  EXPECT_GE(arena.groups().size(), 4u);  // plain, textured, double-sided, mirrored
  (void)triangles;
}

// Brute force: every triangle of a cluster whose cone rejects an eye faces away from it.
TEST_F(GpuTest, ArenaConesRejectOnlyClustersWhoseTrianglesAllFaceAway) {
  scene::Scene scene = test::streetCanyonScene(true);
  for (int segments : {16, 40, 64}) {
    scene::Object ball;
    ball.parts.push_back({scene.addMesh(scene::makeSphere(1.0f + 0.1f * float(segments), segments, segments / 2)), 0});
    scene.addObject(std::move(ball));
  }
  const SceneArena arena(scene);
  const std::vector<uint32_t> indices = arena.readIndices();
  const std::vector<Vec3> positions = arena.readVertexPositions();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  size_t rejected = 0, tested = 0;
  std::vector<const ArenaCluster*> coned;
  for (const ArenaCluster& c : arena.clusters())
    if (c.cone_cutoff < 1.0f) coned.push_back(&c);
  ASSERT_GT(coned.size(), 40u);  // the spheres' clusters
  for (int trial = 0; trial < 200; ++trial) {
    const ArenaCluster& cluster = *coned[size_t(trial * 7919) % coned.size()];
    for (int e = 0; e < 20; ++e) {
      const Vec3 eye = cluster.center + Vec3(u(rng), u(rng), u(rng)) * (cluster.radius * 4.0f + 1.0f);
      ++tested;
      if (!coneRejects(cluster, eye)) continue;
      ++rejected;
      for (uint32_t i = cluster.first_index; i < cluster.first_index + cluster.index_count; i += 3) {
        const Vec3 a = positions[cluster.base_vertex + indices[i]], b = positions[cluster.base_vertex + indices[i + 1]],
                   c = positions[cluster.base_vertex + indices[i + 2]];
        const Vec3 n = glm::cross(b - a, c - a);
        if (n == Vec3(0.0f)) continue;  // no area (a sphere's pole): faces nowhere, draws nothing
        ASSERT_LT(glm::dot(n, eye - a), 0.0f) << "a triangle of a rejected cluster faces the eye (trial " << trial << ")";
      }
    }
  }
  EXPECT_GT(rejected, tested / 5);
}

class GpuCullerTest : public GpuTest {
 protected:
  void SetUp() override {
    GpuTest::SetUp();
    scene_ = test::streetCanyonScene(true);
    gpu_scene_ = std::make_unique<GpuScene>(scene_);
    arena_ = std::make_unique<SceneArena>(scene_);
    renderer_ = std::make_unique<Renderer>();
    target_ = RenderTarget(96, 64);
  }

  // A walk down the street with turns, and a few cuts to other places (the next frame then has no history).
  static std::vector<Camera> walk(unsigned seed, int frames) {
    std::mt19937 rng(seed);
    std::vector<Camera> cameras;
    Camera camera = test::streetCanyonCamera(rng, false);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int f = 0; f < frames; ++f) {
      if (f % 12 == 11) {
        camera = test::streetCanyonCamera(rng, f % 24 == 23);
      } else {
        const Vec3 step(0.3f * u(rng), 1.5f, 0.0f);
        camera.eye += step;
        camera.at += step + Vec3(0.3f * u(rng), 0.0f, 0.05f * u(rng));
        if (camera.eye.y > 55.0f) camera.eye.y -= 100.0f, camera.at.y -= 100.0f;
      }
      cameras.push_back(camera);
    }
    return cameras;
  }

  // The frame that drawing every cluster in the frustum gives (GpuScene's culled items: pixel-identical to all), and
  // its pixels that depend on draw order: those where the frame drawn with the last of equally deep surfaces winning
  // differs (coplanar faces of different objects; the street's low kiosks share their top plane).
  struct Reference {
    image::ColorImage color;
    image::IdImage ids;
    std::vector<bool> tie;
  };
  Reference reference(const Camera& camera, RenderMode mode, std::span<const uint32_t> objects = {}) {
    Reference r;
    std::vector<DrawItem> items;
    gpu_scene_->appendDrawItems(objects, items, camera);
    renderer_->render(camera, items, target_, mode);
    r.color = target_.readColor();
    r.ids = target_.readIds();
    renderer_->setLastWinsTies(true);
    renderer_->render(camera, items, target_, mode);
    renderer_->setLastWinsTies(false);
    const image::ColorImage color = target_.readColor();
    const image::IdImage ids = target_.readIds();
    r.tie.resize(ids.pixels().size());
    for (size_t i = 0; i < r.tie.size(); ++i)
      r.tie[i] = ids.pixels()[i] != r.ids.pixels()[i] || !(color.pixels()[i] == r.color.pixels()[i]);
    return r;
  }

  // Pixels of the target that differ from the reference where it does not depend on draw order.
  size_t differences(const Reference& want, bool colour, size_t* ties = nullptr) const {
    const image::IdImage ids = target_.readIds();
    const image::ColorImage color = target_.readColor();
    size_t n = 0;
    for (size_t i = 0; i < want.tie.size(); ++i) {
      if (want.tie[i]) {
        if (ties) ++*ties;
        continue;
      }
      n += ids.pixels()[i] != want.ids.pixels()[i] || (colour && !(color.pixels()[i] == want.color.pixels()[i]));
    }
    return n;
  }

  void culled(GpuCuller& culler, const Camera& camera, RenderMode mode) {
    target_.bind();
    target_.clear(mode == RenderMode::ItemBuffer ? Vec4(0.0f, 0.0f, 0.0f, 1.0f) : renderer_->light().sky_color);
    culler.draw(camera, target_, mode, renderer_->light());
  }

  scene::Scene scene_;
  std::unique_ptr<GpuScene> gpu_scene_;
  std::unique_ptr<SceneArena> arena_;
  std::unique_ptr<Renderer> renderer_;  // made in SetUp, once the context is current
  RenderTarget target_;
};

// The frames of a walk equal, pixel for pixel (colour and ids), the frames of every cluster in view, with and without
// compaction, shaded and as item buffers; and the tests are not vacuous: clusters are culled by each of them.
TEST_F(GpuCullerTest, FramesEqualFrustumCulledFramesAlongAWalk) {
  const std::vector<Camera> cameras = walk(3, 48);
  for (const bool compact : {true, false}) {
    for (const RenderMode mode : {RenderMode::Shaded, RenderMode::ItemBuffer}) {
      GpuCullOptions options;
      options.compact = compact;
      GpuCuller culler(*arena_, options);
      uint64_t occluded = 0, coned = 0, outside = 0, early = 0;
      size_t ties = 0;
      for (size_t f = 0; f < cameras.size(); ++f) {
        const Reference want = reference(cameras[f], mode);
        culled(culler, cameras[f], mode);
        ASSERT_EQ(differences(want, true, &ties), 0u) << "frame " << f << " compact " << compact << " mode " << int(mode);
        for (const GpuCullStats& s : culler.finishedStats()) {
          occluded += s.occlusion_culled, coned += s.cone_culled, outside += s.frustum_culled;
          early += s.drawn_early;
        }
      }
      EXPECT_GT(occluded, 500u);
      EXPECT_GT(coned, 200u);
      EXPECT_LT(ties, 20 * cameras.size());
      EXPECT_GT(outside, 1000u);
      EXPECT_GT(early, 1000u);  // the history is used
      EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
    }
  }
}

// A still camera: from its third frame on, everything drawn is drawn early (the history of the frame before holds
// every cluster visible in its final depth, however many it drew: the history pass's dispatch covers its whole list),
// and the frames stay equal to the frame of every cluster in view.
TEST_F(GpuCullerTest, AStillCameraDrawsEverythingEarlyFromItsThirdFrame) {
  const std::vector<Camera> cameras = walk(3, 48);
  GpuCuller culler(*arena_);
  std::vector<GpuCullStats> stats;
  for (const size_t pick : {size_t(29), size_t(33)}) {  // views of 200 visible clusters and more
    const Reference want = reference(cameras[pick], RenderMode::ItemBuffer);
    for (int f = 0; f < 8; ++f) {
      culled(culler, cameras[pick], RenderMode::ItemBuffer);
      ASSERT_EQ(differences(want, false), 0u) << "view " << pick << " frame " << f;
      for (const GpuCullStats& s : culler.finishedStats()) stats.push_back(s);
    }
  }
  for (const GpuCullStats& s : culler.finishedStats()) stats.push_back(s);
  size_t checked = 0;
  for (const GpuCullStats& s : stats) {
    const uint64_t in_run = s.frame % 8;
    if (in_run < 2) continue;
    EXPECT_EQ(s.drawn_late, 0u) << "frame " << s.frame;
    EXPECT_GT(s.drawn_early, 3u * 64u) << "frame " << s.frame;  // more than a few work groups' worth
    ++checked;
  }
  EXPECT_GE(checked, 8u);
}

// Occlusion culling turned on and off between frames (GpuCuller::setOcclusion, what gpu_occlusion=auto does) changes
// no frame: each equals the frame of every cluster in view, and the frames with it on do occlusion-cull while those
// with it off cull nothing by depth.
TEST_F(GpuCullerTest, OcclusionTurnedOnAndOffBetweenFramesChangesNoFrame) {
  const std::vector<Camera> cameras = walk(11, 48);
  GpuCuller culler(*arena_);
  std::mt19937 rng(17);
  std::vector<bool> on_in_frame;
  uint64_t occluded_on = 0, occluded_off = 0, switches_on = 0;
  for (size_t f = 0; f < cameras.size(); ++f) {
    // Runs of a few frames each way, as the chooser's probes make them.
    const bool on = f < 4 ? true : (rng() % 3 == 0 ? !on_in_frame.back() : bool(on_in_frame.back()));
    switches_on += f > 0 && on && !on_in_frame.back();
    on_in_frame.push_back(on);
    culler.setOcclusion(on);
    const Reference want = reference(cameras[f], RenderMode::ItemBuffer);
    culled(culler, cameras[f], RenderMode::ItemBuffer);
    ASSERT_EQ(differences(want, false), 0u) << "frame " << f << " occlusion " << on;
    for (const GpuCullStats& s : culler.finishedStats())
      (on_in_frame[s.frame] ? occluded_on : occluded_off) += s.occlusion_culled;
  }
  EXPECT_GT(switches_on, 3u);
  EXPECT_GT(occluded_on, 200u);
  EXPECT_EQ(occluded_off, 0u);
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

// The same check fails when the pyramid test hides boxes that lie in front of the depth (a negative margin): the
// comparison above can see a dropped visible cluster.
TEST_F(GpuCullerTest, ABrokenPyramidTestIsCaught) {
  GpuCullOptions options;
  options.occlusion_margin = -0.5f;
  GpuCuller culler(*arena_, options);
  size_t differing = 0;
  for (const Camera& camera : walk(3, 48)) {
    const Reference want = reference(camera, RenderMode::ItemBuffer);
    culled(culler, camera, RenderMode::ItemBuffer);
    differing += differences(want, false) > 0;
  }
  EXPECT_GT(differing, 3u);
}

// Objects moved after the arena was made (SceneArena::updateTransforms) are culled and drawn where they now stand:
// the frames equal the moved scene's, and differ from the unmoved scene's (the move shows).
TEST_F(GpuCullerTest, MovedObjectsAreDrawnWhereTheyNowStand) {
  const std::vector<Camera> cameras = walk(5, 8);
  std::vector<Reference> before;
  for (const Camera& camera : cameras) before.push_back(reference(camera, RenderMode::Shaded));
  std::vector<uint32_t> moved;
  for (scene::Object& object : scene_.objects)
    if (object.id % 3 == 0) {
      object.transform = glm::translate(Mat4(1.0f), Vec3(1.5f, -2.0f, 0.75f)) * object.transform;
      moved.push_back(object.id);
    }
  ASSERT_FALSE(moved.empty());
  arena_->updateTransforms(moved);
  gpu_scene_ = std::make_unique<GpuScene>(scene_);
  GpuCuller culler(*arena_);
  size_t changed = 0;
  for (size_t f = 0; f < cameras.size(); ++f) {
    const Reference want = reference(cameras[f], RenderMode::Shaded);
    culled(culler, cameras[f], RenderMode::Shaded);
    EXPECT_EQ(differences(want, true), 0u) << "frame " << f;
    changed += differences(before[f], false) > 0;
  }
  EXPECT_GT(changed, cameras.size() / 2);
}

// Only the plan's objects are drawn, and changing the plan changes the frame. The part stage runs over the plan's
// parts alone, and takes every one of them: its count of instances in the plan is the sum over the plan's objects.
TEST_F(GpuCullerTest, OnlyThePlansObjectsAreDrawn) {
  GpuCuller culler(*arena_);
  const std::vector<Camera> cameras = walk(8, 16);
  std::mt19937 rng(2);
  std::vector<uint64_t> in_plan;  // per frame, the arena's count
  std::vector<GpuCullStats> stats;
  for (size_t f = 0; f < cameras.size(); ++f) {
    std::vector<uint32_t> ids;
    for (uint32_t id = 1; id <= scene_.objects.size(); ++id)
      if (rng() % 3 != 0 || f % 5 == 4) ids.push_back(id);
    if (f % 5 == 4) culler.setAllObjects();
    else culler.setObjects(ids);
    uint64_t instances = 0;
    for (const uint32_t id : ids) {
      const auto [first, end] = arena_->objectParts(id - 1);
      for (uint32_t p = first; p < end; ++p) instances += arena_->parts()[p].instance_count;
    }
    in_plan.push_back(instances);
    const Reference want = reference(cameras[f], RenderMode::ItemBuffer, ids);
    culled(culler, cameras[f], RenderMode::ItemBuffer);
    ASSERT_EQ(differences(want, false), 0u) << "frame " << f;
    for (const GpuCullStats& s : culler.finishedStats()) stats.push_back(s);
  }
  for (const GpuCullStats& s : culler.finishedStats()) stats.push_back(s);
  EXPECT_GT(stats.size(), cameras.size() / 2);
  for (const GpuCullStats& s : stats) EXPECT_EQ(s.instances_in_plan, in_plan.at(s.frame)) << "frame " << s.frame;
  const std::vector<uint32_t> bad{uint32_t(scene_.objects.size() + 1)};
  EXPECT_THROW(culler.setObjects(bad), Error);
}

// A frame waits for nothing, draws once per material group and phase, and sends only its uniforms.
TEST_F(GpuCullerTest, AFrameWaitsForNothingAndDrawsOncePerMaterialGroupAndPhase) {
  if (!installGlCounters()) GTEST_SKIP() << "GL counters unavailable (FF_GL_COUNTERS=0 or no EGL context)";
  GpuCuller culler(*arena_);
  size_t groups = 0;
  for (const MaterialGroup& g : arena_->groups()) groups += g.instance_count > 0;
  for (const Camera& camera : walk(4, 6)) {
    target_.bind();
    target_.clear(renderer_->light().sky_color);
    const GlCounters before = glCounters();
    const FrameStats stats = culler.draw(camera, target_, RenderMode::Shaded, renderer_->light());
    const GlCounters frame = glCounters() - before;
    EXPECT_EQ(frame.syncs, 0u);
    EXPECT_EQ(frame.draw_calls, 2 * groups);
    EXPECT_EQ(stats.draw_calls, 2 * groups);
    EXPECT_GE(frame.dispatches, 3u);  // two culling phases and the pyramid's levels
    EXPECT_LT(frame.upload_bytes, 2048u);
    GlMeasurement wait;
    target_.readIds();  // the test's own readback is not the frame's
  }
  EXPECT_EQ((glCounters() - glCounters()).syncs, 0u);
}

// Every write of the culling stages is followed by the barrier its readers need (gpu/gl_barrier_check.h): the next
// stages' storage reads, the indirect dispatches and draws, the clears of the next phase and frame, and the late
// readback of the statistics; with each option that changes the frame's stages. (llvmpipe finishes all work at any
// barrier, so a missing bit changes no frame here; the check follows the calls instead.)
TEST_F(GpuCullerTest, EveryStageWriteIsFollowedByTheBarrierItsReadersNeed) {
  if (!installGlCounters() || !setGlBarrierCheck(true))
    GTEST_SKIP() << "GL counters unavailable (FF_GL_COUNTERS=0 or no EGL context)";
  const SceneArena arena(scene_);  // made with the check on: its buffers' sizes are known to it
  for (const bool occlusion : {true, false})
    for (const bool compact : {true, false})
      for (const bool history : {true, false}) {
        SCOPED_TRACE(std::string(occlusion ? "occlusion" : "no occlusion") + (compact ? ", compact" : ", every slot") +
                     (history ? ", history" : ""));
        glMemoryBarrier(GL_ALL_BARRIER_BITS);
        clearGlBarrierHazards();
        GpuCullOptions options;
        options.occlusion = occlusion;
        options.compact = compact;
        options.refine_history = history;
        GpuCuller culler(arena, options);  // its programs compiled with the check on: known to it
        for (const Camera& camera : walk(4, 5)) culled(culler, camera, RenderMode::Shaded);
        culler.setOcclusion(!occlusion);
        culled(culler, walk(4, 5).back(), RenderMode::ItemBuffer);
        glFinish();
        EXPECT_FALSE(culler.finishedStats().empty());
        const GlBarrierCheckCounts counts = glBarrierCheckCounts();
        EXPECT_GE(counts.checked, 5u * 4u);  // dispatches and draws of five frames
        EXPECT_EQ(counts.unknown_program, 0u);
        EXPECT_GT(counts.indirect_commands, 0u);  // the multi-draws' commands checked against the arena's indices
        for (const GlBarrierHazard& h : glBarrierHazards()) ADD_FAILURE() << h.message << " (" << h.count << " calls)";
      }
}

// With stage times, the frames are the same, and each frame's GPU time comes back split into its stages: the
// multi-draws of a frame that draws take time, and so do the culling passes; without occlusion the pyramid, the
// second phase and the history take none.
TEST_F(GpuCullerTest, StageTimesSplitTheFramesWorkWithoutChangingIt) {
  for (const bool occlusion : {true, false}) {
    SCOPED_TRACE(occlusion ? "occlusion" : "no occlusion");
    GpuCullOptions options;
    options.occlusion = occlusion;
    GpuCuller plain(*arena_, options);
    options.stage_times = true;
    GpuCuller timed(*arena_, options);
    EXPECT_TRUE(plain.finishedStageTimes().empty());
    std::array<double, kGpuCullStages.size()> sum{};
    size_t frames = 0;
    for (const Camera& camera : walk(4, 6)) {
      culled(plain, camera, RenderMode::Shaded);
      const image::ColorImage want = target_.readColor();
      culled(timed, camera, RenderMode::Shaded);
      EXPECT_TRUE(target_.readColor().pixels() == want.pixels());
      glFinish();
      for (const GpuStageTimes& t : timed.finishedStageTimes()) {
        for (size_t i = 0; i < t.ms.size(); ++i) sum[i] += t.ms[i];
        ++frames;
      }
    }
    EXPECT_EQ(frames, 6u);
    EXPECT_GT(sum[0], 0.0);  // the first (or only) phase's culling
    EXPECT_GT(sum[1], 0.0);  // its multi-draws
    if (occlusion) {
      EXPECT_GT(sum[2], 0.0);  // the pyramid
      EXPECT_GT(sum[4], 0.0);
    } else {
      for (size_t i = 2; i < sum.size(); ++i) EXPECT_LT(sum[i], 0.05 * (sum[0] + sum[1])) << kGpuCullStages[i];
    }
  }
}

// With occlusion off, the clusters drawn are those a CPU brute force over the same sphere, box and cone tests finds.
TEST_F(GpuCullerTest, StatisticsMatchABruteForceCountOfClustersInView) {
  GpuCullOptions options;
  options.occlusion = false;
  GpuCuller culler(*arena_, options);
  std::vector<uint64_t> want;
  std::vector<GpuCullStats> stats;
  size_t in_plan = 0;
  const std::vector<Camera> cameras = walk(6, 10);
  for (const Camera& camera : cameras) {
    culled(culler, camera, RenderMode::Shaded);
    const Frustum frustum = Frustum::fromMatrix(camera.viewProjection());
    uint64_t drawn = 0;
    std::vector<ArenaInstance> full_level;  // the parts' full levels: lod_error_px is 0
    for (const ArenaPart& part : arena_->parts())
      for (uint32_t k = 0; k < part.instance_count; ++k) full_level.push_back(arena_->instances()[part.first_instance + k]);
    in_plan = full_level.size();
    for (const ArenaInstance& in : full_level) {
      const scene::Object& object = scene_.objects[in.object];
      const ArenaCluster& c = arena_->clusters()[in.cluster];
      const Mat3 linear(object.transform);
      const float scale = std::max({glm::length(linear[0]), glm::length(linear[1]), glm::length(linear[2])});
      const Vec3 centre = Vec3(object.transform * Vec4(c.center, 1.0f));
      bool in_view = true;
      for (const Vec4& p : frustum.planes)
        if (glm::dot(Vec3(p), centre) + p.w < -c.radius * scale) in_view = false;
      Frustum local;
      for (size_t k = 0; k < 6; ++k) local.planes[k] = frustum.planes[k] * object.transform;
      if (!local.intersects(c.bounds)) in_view = false;
      if (in_view && in.cone_test) {
        ArenaCluster world = c;
        world.cone_apex = Vec3(object.transform * Vec4(c.cone_apex, 1.0f));
        world.cone_axis = glm::normalize(linear * c.cone_axis);
        in_view = !coneRejects(world, camera.eye);
      }
      drawn += in_view;
    }
    want.push_back(drawn);
    target_.readIds();  // waits: the frame's statistics are now finished
    for (const GpuCullStats& s : culler.finishedStats()) stats.push_back(s);
  }
  ASSERT_EQ(stats.size(), cameras.size());
  for (size_t f = 0; f < stats.size(); ++f) {
    EXPECT_EQ(stats[f].frame, f);
    EXPECT_EQ(stats[f].drawn_early, 0u);
    EXPECT_NEAR(double(stats[f].drawn_late), double(want[f]), 2.0) << "frame " << f;
    EXPECT_EQ(stats[f].instances_in_plan, in_plan);
  }
  EXPECT_TRUE(culler.finishedStats().empty());  // each once
}

}  // namespace
}  // namespace farfield::gpu
