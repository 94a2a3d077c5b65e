// The viewer's frame statistics: the last frames' CPU and GPU times for the graph, and the two promises counted over
// the frames shown in the current mode (t_max: frames whose time exceeded it; the error bound: frames whose reference
// check measured a parallax over the bound, and frames whose walkthrough could not check the bound at all).
#pragma once

#include <cstddef>
#include <vector>

namespace farfield::view {

inline constexpr size_t kHistoryFrames = 240;

struct PromiseCounts {
  size_t frames = 0;            // frames shown
  size_t over_t_max = 0;        // CPU frame time over t_max
  size_t checked = 0;           // frames with a reference check
  size_t over_bound = 0;        // checked frames whose parallax exceeded the bound
  size_t unchecked_frames = 0;  // frames with layers the bound could not be checked for (layers_unchecked)
  size_t boundBroken() const { return over_bound + unchecked_frames; }
};

class FrameHistory {
 public:
  FrameHistory();
  // A shown frame: its times, whether it had unchecked layers; t_max_ms 0 = none.
  void add(double cpu_ms, double gpu_ms, double t_max_ms, bool unchecked);
  // A reference check of a shown frame.
  void addCheck(bool over_bound);
  // Forget everything (a new mode).
  void reset();

  const PromiseCounts& promises() const { return promises_; }
  // The last kHistoryFrames times, oldest first, as ImGui::PlotLines takes them (offset = index of the oldest).
  const std::vector<float>& cpuMs() const { return cpu_; }
  const std::vector<float>& gpuMs() const { return gpu_; }
  size_t offset() const { return next_; }
  float maxMs() const;

 private:
  std::vector<float> cpu_, gpu_;
  size_t next_ = 0;
  PromiseCounts promises_;
};

}  // namespace farfield::view
