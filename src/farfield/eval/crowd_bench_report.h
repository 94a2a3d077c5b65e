// The crowd bench's report (runCrowdBench writes it; crowd_bench_report.cpp).
#pragma once

#include <string>
#include <vector>

#include "farfield/eval/crowd_bench.h"

namespace farfield::eval {

// Issue 45's goals for one mixed mode of a run, against the impostor mode of its own path (crowd-mixed against
// crowd-impostor, crowd-mixed-gpu against crowd-impostor-gpu): PSNR on the crowd's pixels, the crowd pass's median
// wall and GPU times over the impostor mode's, and its own CPU time (median).
struct MixedAgainstImpostor {
  std::string mixed, impostor;
  double psnr_mean = 0.0, psnr_min = 0.0;
  double crowd_ratio = 0.0, crowd_gpu_ratio = 0.0;
  double own_cpu_ms = 0.0;
  bool psnr_met() const { return psnr_mean >= 30.0; }
  bool pass_met() const { return crowd_ratio > 0.0 && crowd_ratio <= 1.2; }
  bool cpu_met() const { return own_cpu_ms <= 0.5; }
};
std::vector<MixedAgainstImpostor> mixedAgainstImpostor(const CrowdRun& run);

// The run as a Markdown table with the city, models, atlases and bake time above it.
std::string crowdMarkdown(const CrowdBenchResult& result, const CrowdBenchOptions& options);

// crowd.json and crowd.md (result.markdown) in options.out_dir.
void writeCrowdReport(const CrowdBenchResult& result, const CrowdBenchOptions& options);

}  // namespace farfield::eval
