// The report of `farfield bake` (see bake_report.cpp).
#pragma once

#include <cstddef>
#include <string>

#include "farfield/bake/pipeline.h"
#include "farfield/extract/pipeline_options.h"

namespace farfield::app {

// The stages baked and run online, and the layers' error, frame, mesh and image sizes.
void printPipelineSetup(const extract::PipelineSpec& spec, const extract::PipelineOptions& options);

// After the bake: shard, resumption, cells, the per-cell table (`list`) and summary, storage and wall time.
void printPipelineReport(const bake::PipelineReport& report, size_t scene_objects, bool list, bool resume,
                         const std::string& out_dir);

}  // namespace farfield::app
