// The per-frame record of a walkthrough's database streaming: stalls and resident bytes.
#include "farfield/runtime/streaming.h"

#include <algorithm>
#include <cstdio>
#include <fstream>

#include "farfield/core/error.h"

namespace farfield::runtime {

std::map<std::string, double> StreamingLog::summary() const {
  std::map<std::string, double> out;
  double stall_total = 0.0, stall_max = 0.0, resident_sum = 0.0, ahead_max_ms = 0.0;
  uint64_t resident_max = 0, ahead_max = 0;
  size_t stalls = 0, entries = 0, over = 0;
  for (const StreamingFrame& f : frames_) {
    if (!f.read.empty()) ++entries;
    if (f.stall()) {
      ++stalls;
      stall_total += f.load_ms;
      stall_max = std::max(stall_max, f.load_ms);
    }
    resident_max = std::max(resident_max, f.residentBytes());
    ahead_max = std::max(ahead_max, f.read_ahead_bytes);
    ahead_max_ms = std::max(ahead_max_ms, f.ahead_ms);
    resident_sum += double(f.residentBytes());
    if (budget_ > 0 && f.residentBytes() > budget_) ++over;
  }
  out["stall_frames"] = double(stalls);
  out["stall_ms_total"] = stall_total;
  out["stall_ms_max"] = stall_max;
  out["cell_entries"] = double(entries);
  out["resident_bytes_total_max"] = double(resident_max);
  out["resident_bytes_total_mean"] = frames_.empty() ? 0.0 : resident_sum / double(frames_.size());
  out["read_ahead_bytes_max"] = double(ahead_max);
  out["memory_budget_bytes"] = double(budget_);
  out["frames_over_memory_budget"] = double(over);
  out["load_ahead_ms_max"] = ahead_max_ms;
  return out;
}

void StreamingLog::writeCsv(const std::string& file) const {
  std::ofstream out(file, std::ios::trunc);
  if (!out) throw Error(file, "cannot write the streaming log");
  out << "frame,cell,read,load_ms,stall,gpu_bytes,read_ahead_bytes,resident_bytes,ahead_ms\n";
  for (size_t k = 0; k < frames_.size(); ++k) {
    const StreamingFrame& f = frames_[k];
    char load[32], ahead[32];
    std::snprintf(load, sizeof(load), "%.3f", f.load_ms);
    std::snprintf(ahead, sizeof(ahead), "%.3f", f.ahead_ms);
    out << k << ',' << (f.cell == 0xffffffffu ? std::string("") : std::to_string(f.cell)) << ',' << f.read << ','
        << load << ',' << (f.stall() ? 1 : 0) << ',' << f.gpu_bytes << ',' << f.read_ahead_bytes << ','
        << f.residentBytes() << ',' << ahead << '\n';
  }
  if (!out) throw Error(file, "write failed");
}

}  // namespace farfield::runtime
