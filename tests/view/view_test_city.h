// A small generated city with a pipeline store baked over a short drive, shared by the viewer's tests (built once per
// process, a few seconds on llvmpipe), and the display check of the tests that open a window.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>

#include "farfield/bake/bake.h"
#include "farfield/bake/pipeline.h"
#include "farfield/bake/place.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/store/placement_store.h"
#include "farfield/urban/cells.h"
#include "support/small_placement.h"
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

// A placement database (farfield place) over a 12-block city with one object per building, under a hand-made cost
// profile whose t_max (9 ms) only impostors can keep from some views, with its report (built once per process).
struct ViewPlacement {
  gen::City city;
  gen::CameraPath path;
  std::string path_file;
  std::string database;
  bake::PlaceReport report;
};

inline const ViewPlacement& viewPlacement() {
  static const ViewPlacement* s = [] {
    auto* c = new ViewPlacement;
    c->city = farfield::test::smallPlacementCity();
    const bake::PlaceOptions p = farfield::test::smallPlaceOptions(c->city.scene);
    const std::filesystem::path dir = farfield::test::scratchDir("view_placement");
    c->database = (dir / "city.place").string();
    c->report = bake::placeImpostors(gpu::sharedHeadlessContext(), c->city.scene, farfield::test::handProfile(), p,
                                     c->database);
    // Random level views of the view space (seeded), like the placement's own tests: a street walk this short
    // may meet no problem view.
    const Box3 space = store::readPlacementIndex(c->database).view_space;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int k = 0; k < 24; ++k) {
      gen::PathFrame f;
      f.eye = space.lo + (space.hi - space.lo) * Vec3(u(rng), u(rng), u(rng));
      const float yaw = float(2.0 * kPi) * u(rng);
      f.at = f.eye + Vec3(std::cos(yaw), std::sin(yaw), 0.0f);
      f.up = Vec3(0.0f, 0.0f, 1.0f);
      f.fov_y = float(degToRad(45.0));
      c->path.frames.push_back(f);
    }
    c->path_file = (dir / "walk.json").string();
    gen::saveCameraPath(c->path, c->path_file);
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
