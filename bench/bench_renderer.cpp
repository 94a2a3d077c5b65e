// Renderer throughput: frames of a grid of small boxes at 512 x 512, from 10k to 2M triangles, on the shared
// headless context (llvmpipe on machines without a GPU). Counters: triangles per second, wall and GPU milliseconds
// per frame (wall time includes glFinish), draw calls per frame. BM_RenderManyDraws measures the per-draw CPU cost
// with one draw item per box (a city's many small objects).
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/builtin.h"

namespace {

using namespace farfield;

constexpr int kSize = 512;
constexpr int kBoxesPerDraw = 1024;  // 12k triangles per draw call: the size of a city block's mesh

struct BoxGrid {
  std::vector<gpu::GpuMesh> meshes;
  std::vector<gpu::DrawItem> items;
  gpu::GpuMaterial material;
  Camera camera;
  uint64_t triangles = 0;
};

// A square grid of boxes (1 m apart, 0.6 m wide, heights varying) with at least `triangles` triangles, chunked into
// draw items of kBoxesPerDraw boxes, and a camera above it that sees the whole grid.
std::unique_ptr<BoxGrid> makeGrid(uint64_t triangles) {
  auto grid = std::make_unique<BoxGrid>();
  const int boxes = int((triangles + 11) / 12);
  const int side = int(std::ceil(std::sqrt(double(boxes))));
  const float half = float(side) * 0.5f;
  grid->material.base_color = Vec4(0.8f, 0.75f, 0.7f, 1.0f);
  scene::Mesh chunk;
  auto flush = [&] {
    if (chunk.indices.empty()) return;
    grid->meshes.emplace_back(chunk);
    chunk = scene::Mesh{};
  };
  for (int b = 0; b < boxes; ++b) {
    const float x = float(b % side) - half, y = float(b / side) - half;
    const float h = 0.3f + 0.1f * float((b * 7) % 11);
    const scene::Mesh box = scene::makeBox(Vec3(x, y, 0.0f), Vec3(x + 0.6f, y + 0.6f, h));
    const uint32_t base = uint32_t(chunk.positions.size());
    chunk.positions.insert(chunk.positions.end(), box.positions.begin(), box.positions.end());
    chunk.normals.insert(chunk.normals.end(), box.normals.begin(), box.normals.end());
    chunk.uvs.insert(chunk.uvs.end(), box.uvs.begin(), box.uvs.end());
    for (uint32_t i : box.indices) chunk.indices.push_back(base + i);
    if ((b + 1) % kBoxesPerDraw == 0) flush();
  }
  flush();
  uint32_t id = 1;
  for (const auto& mesh : grid->meshes) {
    grid->items.push_back({&mesh, &grid->material, Mat4(1.0f), id++});
    grid->triangles += mesh.triangleCount();
  }
  grid->camera.width = grid->camera.height = kSize;
  grid->camera.fov_y = float(degToRad(60.0));
  grid->camera.at = Vec3(0.0f);
  grid->camera.eye = Vec3(0.0f, -0.35f * float(side), 1.05f * float(side));
  grid->camera.near_plane = 0.5f;
  grid->camera.far_plane = 4.0f * float(side) + 10.0f;
  return grid;
}

// Grids are built once per size: Google Benchmark calls the function several times while choosing iterations.
BoxGrid& grid(uint64_t triangles) {
  static std::map<uint64_t, std::unique_ptr<BoxGrid>> grids;
  auto& g = grids[triangles];
  if (!g) g = makeGrid(triangles);
  return *g;
}

void BM_RenderBoxGrid(benchmark::State& state) {
  gpu::sharedHeadlessContext();
  BoxGrid& g = grid(uint64_t(state.range(0)));
  static gpu::Renderer* renderer = new gpu::Renderer();  // programs compiled once for all sizes
  gpu::RenderTarget target(kSize, kSize);
  renderer->render(g.camera, g.items, target);  // warm-up: first use of the buffers
  double wall_ms = 0.0, gpu_ms = 0.0;
  uint64_t triangles = 0;
  uint32_t draw_calls = 0;
  for (auto _ : state) {
    const gpu::FrameStats stats = renderer->render(g.camera, g.items, target);
    wall_ms += stats.wall_ms;
    gpu_ms += stats.gpu_ms;
    triangles += stats.triangles;
    draw_calls = stats.draw_calls;
  }
  const double frames = double(state.iterations());
  state.counters["triangles/s"] = benchmark::Counter(double(triangles), benchmark::Counter::kIsRate);
  state.counters["wall_ms"] = wall_ms / frames;
  state.counters["gpu_ms"] = gpu_ms / frames;
  state.counters["tris/frame"] = double(g.triangles);
  state.counters["draws"] = draw_calls;
}

BENCHMARK(BM_RenderBoxGrid)
    ->Arg(10'000)
    ->Arg(100'000)
    ->Arg(500'000)
    ->Arg(2'000'000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

// One draw item per box: 1k to 20k draws of 12 triangles, materials alternating between 8 colours.
void BM_RenderManyDraws(benchmark::State& state) {
  gpu::sharedHeadlessContext();
  const int draws = int(state.range(0));
  static const gpu::GpuMesh* box = new gpu::GpuMesh(scene::makeBox(Vec3(0.0f), Vec3(0.6f, 0.6f, 1.0f)));
  static const std::vector<gpu::GpuMaterial>* materials = [] {
    auto* m = new std::vector<gpu::GpuMaterial>(8);
    for (size_t i = 0; i < m->size(); ++i) (*m)[i].base_color = Vec4(0.3f + 0.08f * float(i), 0.6f, 0.5f, 1.0f);
    return m;
  }();
  const int side = int(std::ceil(std::sqrt(double(draws))));
  std::vector<gpu::DrawItem> items;
  for (int i = 0; i < draws; ++i) {
    const Vec3 at(float(i % side) - 0.5f * float(side), float(i / side) - 0.5f * float(side), 0.0f);
    items.push_back({box, &(*materials)[size_t(i) % materials->size()], glm::translate(Mat4(1.0f), at),
                     uint32_t(i + 1)});
  }
  Camera camera;
  camera.width = camera.height = kSize;
  camera.at = Vec3(0.0f);
  camera.eye = Vec3(0.0f, -0.35f * float(side), 1.05f * float(side));
  camera.far_plane = 4.0f * float(side) + 10.0f;
  static gpu::Renderer* renderer = new gpu::Renderer();
  gpu::RenderTarget target(kSize, kSize);
  renderer->render(camera, items, target);
  double wall_ms = 0.0;
  for (auto _ : state) wall_ms += renderer->render(camera, items, target).wall_ms;
  state.counters["draws/s"] = benchmark::Counter(double(draws) * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["wall_ms"] = wall_ms / double(state.iterations());
}

BENCHMARK(BM_RenderManyDraws)->Arg(1'000)->Arg(20'000)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();
