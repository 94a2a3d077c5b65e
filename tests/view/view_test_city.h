// A small generated city with a pipeline store baked over a short drive, shared by the viewer's tests (built once per
// process, a few seconds on llvmpipe), and the display check of the tests that open a window.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "farfield/bake/bake.h"
#include "farfield/bake/pipeline.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/urban/cells.h"
#include "support/test_support.h"

namespace farfield::view::test {

struct ViewCity {
  gen::City city;
  gen::CameraPath path;
  std::string path_file;
  std::string store;
};

inline const ViewCity& viewCity() {
  static const ViewCity* s = [] {
    auto* c = new ViewCity;
    gen::CityOptions o;
    o.blocks = 16;
    o.detail = 0;
    o.seed = 5;
    c->city = gen::generateCity(o);
    const urban::CellMap cells(c->city.streets, c->city.scene);
    gen::StreetWalkOptions walk;
    walk.frames = 8;
    walk.walker = gen::Walker::Car;
    walk.fps = 2.0f;
    walk.seed = 4;
    c->path = gen::streetWalk(c->city.streets, walk);
    const std::filesystem::path dir = farfield::test::scratchDir("view_city");
    c->path_file = (dir / "path.json").string();
    gen::saveCameraPath(c->path, c->path_file);
    extract::PipelineOptions options;
    options.base.resolution = 192;
    options.base.progress = false;
    options.pvs.spacing = 8.0f;
    options.pvs.face_size = 64;
    c->store = (dir / "city.imp").string();
    bake::bakePipeline(gpu::sharedHeadlessContext(), c->city.scene, cells, bake::cellsOnPath(cells, c->path),
                       extract::parsePipeline("pvs,near-far,single,mmi"), options, c->store);
    return c;
  }();
  return *s;
}

// Tests that open a window need a display (ctest runs under xvfb-run, see the Makefile).
#define FF_REQUIRE_DISPLAY()                                                   \
  do {                                                                         \
    if (!std::getenv("DISPLAY")) GTEST_SKIP() << "DISPLAY not set (run under xvfb-run)"; \
  } while (0)

}  // namespace farfield::view::test
