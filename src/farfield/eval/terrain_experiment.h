// The stages of the LOD-sprite terrain experiment (terrain_bench.h), one source file each: the path, the cost model
// and the harness (terrain_bench.cpp), the quality pass and Figures 9-11 (terrain_quality.cpp), the sweeps and
// section 5 (terrain_sweeps.cpp), the summary (terrain_summary.cpp). Internal to eval.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "farfield/eval/terrain_bench.h"
#include "farfield/eval/terrain_paths.h"
#include "farfield/gen/camera_path.h"
#include "farfield/image/image.h"
#include "farfield/terrain/flythrough.h"

namespace farfield::eval::terrain_experiment {

namespace fs = std::filesystem;

// Output helpers.
void say(const TerrainBenchOptions& options, const char* format, ...);
void writeText(const fs::path& file, const std::string& text);
std::string num(double v, int decimals = 4);
template <class T>
std::string joined(const std::vector<T>& values) {
  std::ostringstream out;
  for (size_t i = 0; i < values.size(); ++i) out << (i ? "," : "") << values[i];
  return out.str();
}
image::ColorImage absDifference(const image::ColorImage& a, const image::ColorImage& b, int gain = 4);
bool runTerrainPlots(const fs::path& figures, const std::string& script, const std::string& python);

// Frame-time totals over a mode's frames, and the frames left out as stalls.
double totalMs(const ModeResult& m);
std::vector<uint8_t> stalledFrames(const BenchResult& bench);
double filteredMs(const ModeResult& m, const std::vector<uint8_t>& stalled);
double meanWithoutStalls(const std::vector<double>& times, double median);

// Everything the stages share.
struct Experiment {
  const TerrainBenchOptions& options;
  TerrainBenchResult& result;
  std::shared_ptr<TerrainRun> run;
  fs::path out, figures;
  gen::CameraPath path;
  bool generated = false;
  terrain::FlythroughOptions fly;
  ClipPlanes planes;

  const terrain::TerrainData& data() const { return *run->data; }
  Camera cameraAt(const gen::CameraPath& p, size_t i) const {
    return pathCamera(p, i, options.width, options.height, planes.near_plane, planes.far_plane);
  }
  std::vector<Camera> measuredCameras() const {
    std::vector<Camera> cameras;
    for (size_t i : result.bench.frame_indices) cameras.push_back(cameraAt(path, i));
    return cameras;
  }
};

// The stages, in the order runTerrainBench runs them.
void makePath(Experiment& x);
void calibrate(Experiment& x);
void runHarness(Experiment& x);
void runQuality(Experiment& x);
void writePerFrameFigures(const Experiment& x);
void runSweeps(Experiment& x);
void runBackAndForth(Experiment& x);
void writeSummary(Experiment& x);

}  // namespace farfield::eval::terrain_experiment
