// What streaming the impostor database cost a walkthrough, frame by frame: the cell entered, whether its data was
// read ahead in time ("ready") or the frame waited for it ("waited": its background read was unfinished; "cold":
// never read ahead) -- a stall --, the time spent loading it, and the bytes held: impostors resident on the GPU and
// decoded cells read ahead (store/cell_reader.h), against the memory budget.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace farfield::runtime {

struct StreamingFrame {
  uint32_t cell = 0xffffffffu;
  std::string read;                 // "", "ready", "waited", "cold"
  double load_ms = 0.0;             // reading (when not ready), decoding and uploading the cell entered
  uint64_t gpu_bytes = 0;           // resident impostors after the frame's loads and evictions
  uint64_t read_ahead_bytes = 0;    // decoded cells read ahead and not yet entered
  double ahead_ms = 0.0;            // after the frame: uploading cells ahead (Walkthrough::loadAhead)
  bool stall() const { return read == "waited" || read == "cold"; }
  uint64_t residentBytes() const { return gpu_bytes + read_ahead_bytes; }
};

class StreamingLog {
 public:
  explicit StreamingLog(uint64_t memory_budget_bytes = 0) : budget_(memory_budget_bytes) {}
  void add(const StreamingFrame& frame) { frames_.push_back(frame); }
  // Time the last frame's host gave to uploading cells ahead (none before a first frame).
  void addAheadMs(double ms) {
    if (!frames_.empty()) frames_.back().ahead_ms += ms;
  }
  const std::vector<StreamingFrame>& frames() const { return frames_; }
  // stall_frames, stall_ms_total, stall_ms_max, cell_entries, resident_bytes_max, resident_bytes_mean,
  // read_ahead_bytes_max, memory_budget_bytes, frames_over_memory_budget, load_ahead_ms_max.
  std::map<std::string, double> summary() const;
  // frame,cell,read,load_ms,stall,gpu_bytes,read_ahead_bytes,resident_bytes,ahead_ms; throws farfield::Error naming
  // the file.
  void writeCsv(const std::string& file) const;

 private:
  uint64_t budget_ = 0;
  std::vector<StreamingFrame> frames_;
};

}  // namespace farfield::runtime
