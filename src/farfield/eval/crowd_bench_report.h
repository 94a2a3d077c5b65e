// The crowd bench's report (runCrowdBench writes it; crowd_bench_report.cpp).
#pragma once

#include <string>

#include "farfield/eval/crowd_bench.h"

namespace farfield::eval {

// The run as a Markdown table with the city, models, atlases and bake time above it.
std::string crowdMarkdown(const CrowdBenchResult& result, const CrowdBenchOptions& options);

// crowd.json and crowd.md (result.markdown) in options.out_dir.
void writeCrowdReport(const CrowdBenchResult& result, const CrowdBenchOptions& options);

}  // namespace farfield::eval
