// The small generated city that the pipeline-bake tests share: its cells baked once for the whole executable (all
// stages baked, and with the single and mmi stages left online), the options they were baked with, and the fixture.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "farfield/bake/bake.h"
#include "farfield/bake/pipeline.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/urban/cells.h"
#include "support/test_support.h"

namespace farfield::bake::pipeline_test {

// A 16-block city of plain boxes with one object per building (several objects per block: layers with several
// members, pairs with and without visibility events), a 24-frame drive (5 m per frame), and the cells it visits
// baked twice with the full pipeline: all stages baked, and with the single and mmi stages left online. Built once
// for the suite.
struct BakedCity {
  gen::City city;
  std::unique_ptr<urban::CellMap> cells;
  std::vector<uint32_t> visited;
  extract::PipelineOptions options;
  std::string full_dir, online_dir;
  PipelineReport full_report, online_report;
  double full_s = 0.0, online_s = 0.0;
};

inline extract::PipelineOptions smallOptions() {
  extract::PipelineOptions o;
  o.base.resolution = 128;
  o.base.progress = false;
  o.pvs.spacing = 8.0f;
  o.pvs.face_size = 64;
  o.error_px = 10.0;  // 10 px in 512 x 512 frames at 60 degrees, the paper's setting
  o.frame_width = 512;
  o.frame_height = 512;
  o.grid_cells = 30;
  return o;
}

inline const BakedCity& bakedCity() {
  static const BakedCity* b = [] {
    auto* c = new BakedCity;
    gen::CityOptions o;
    o.blocks = 16;
    o.detail = 0;
    o.seed = 3;
    o.objects = gen::ObjectGrouping::Buildings;
    c->city = gen::generateCity(o);
    c->cells = std::make_unique<urban::CellMap>(c->city.streets, c->city.scene);
    gen::StreetWalkOptions walk;
    walk.frames = 24;
    walk.walker = gen::Walker::Car;
    walk.fps = 2.0f;
    walk.seed = 2;
    c->visited = cellsOnPath(*c->cells, gen::streetWalk(c->city.streets, walk));
    c->options = smallOptions();
    c->full_dir = test::scratchDir("pipeline_full").string();
    c->online_dir = test::scratchDir("pipeline_online").string();
    auto t0 = std::chrono::steady_clock::now();
    c->full_report = bakePipeline(gpu::sharedHeadlessContext(), c->city.scene, *c->cells, c->visited,
                                  extract::parsePipeline("pvs,near-far,single,mmi"), c->options, c->full_dir);
    auto t1 = std::chrono::steady_clock::now();
    c->online_report = bakePipeline(gpu::sharedHeadlessContext(), c->city.scene, *c->cells, c->visited,
                                    extract::parsePipeline("pvs,near-far,single,mmi", "single,mmi"), c->options,
                                    c->online_dir);
    auto t2 = std::chrono::steady_clock::now();
    c->full_s = std::chrono::duration<double>(t1 - t0).count();
    c->online_s = std::chrono::duration<double>(t2 - t1).count();
    return c;
  }();
  return *b;
}

class PipelineBakeTest : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

}  // namespace farfield::bake::pipeline_test
