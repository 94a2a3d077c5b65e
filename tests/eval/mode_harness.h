// Everything a bench mode needs over a scene (builtin:cubes unless given; the scene, its GPU copy and BVH, a renderer, a square target and the
// ModeContext pointing at them), on the shared headless context. For the eval tests that run modes frame by frame.
#pragma once

#include <memory>
#include <string>
#include <utility>

#include "farfield/eval/mode.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/bvh.h"

namespace farfield::test {

struct ModeHarness {
  scene::Scene scene;
  std::unique_ptr<gpu::GpuScene> gpu_scene;
  std::unique_ptr<scene::Bvh> bvh;
  std::unique_ptr<gpu::Renderer> renderer;
  std::unique_ptr<gpu::RenderTarget> target;
  eval::ModeContext context;

  explicit ModeHarness(int size, scene::Scene s = scene::builtinScene("cubes")) : scene(std::move(s)) {
    gpu::sharedHeadlessContext().makeCurrent();
    gpu_scene = std::make_unique<gpu::GpuScene>(scene);
    bvh = std::make_unique<scene::Bvh>(scene);
    renderer = std::make_unique<gpu::Renderer>();
    target = std::make_unique<gpu::RenderTarget>(size, size);
    context.scene = &scene;
    context.gpu_scene = gpu_scene.get();
    context.bvh = bvh.get();
    context.renderer = renderer.get();
    context.width = context.height = size;
  }
  // A mode of the registry, made and prepared.
  std::unique_ptr<eval::Mode> make(const std::string& name) {
    auto mode = eval::createMode(name, context);
    mode->prepare(context);
    return mode;
  }
};

}  // namespace farfield::test
