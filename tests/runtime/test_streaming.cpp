// The streaming log (runtime/streaming.h): stalls, resident bytes and the budget summarised from hand-made frames,
// and its CSV read back.
#include "farfield/runtime/streaming.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "farfield/core/error.h"
#include "support/test_support.h"

namespace farfield::runtime {
namespace {

TEST(StreamingLogTest, SummarisesStallsAndResidentBytesAndWritesOneRowPerFrame) {
  StreamingLog log(1000);
  const auto frame = [](uint32_t cell, const char* read, double ms, uint64_t gpu, uint64_t ahead) {
    StreamingFrame f;
    f.cell = cell;
    f.read = read;
    f.load_ms = ms;
    f.gpu_bytes = gpu;
    f.read_ahead_bytes = ahead;
    return f;
  };
  log.add(frame(3, "cold", 40.0, 300, 0));
  log.addAheadMs(1.5);  // after the first frame: uploads ahead
  log.addAheadMs(0.5);
  log.add(frame(3, "", 0.0, 300, 500));
  log.add(frame(5, "ready", 2.0, 600, 200));
  log.add(frame(7, "waited", 15.0, 900, 300));  // 1200 bytes: over the budget
  const auto s = log.summary();
  EXPECT_EQ(s.at("stall_frames"), 2.0);
  EXPECT_EQ(s.at("stall_ms_total"), 55.0);
  EXPECT_EQ(s.at("stall_ms_max"), 40.0);
  EXPECT_EQ(s.at("cell_entries"), 3.0);
  EXPECT_EQ(s.at("resident_bytes_total_max"), 1200.0);
  EXPECT_EQ(s.at("resident_bytes_total_mean"), (300.0 + 800.0 + 800.0 + 1200.0) / 4.0);
  EXPECT_EQ(s.at("read_ahead_bytes_max"), 500.0);
  EXPECT_EQ(s.at("frames_over_memory_budget"), 1.0);
  EXPECT_EQ(s.at("load_ahead_ms_max"), 2.0);

  const std::string file = (test::scratchDir("streaming_log") / "frames.csv").string();
  log.writeCsv(file);
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "frame,cell,read,load_ms,stall,gpu_bytes,read_ahead_bytes,resident_bytes,ahead_ms");
  std::getline(in, line);
  EXPECT_EQ(line, "0,3,cold,40.000,1,300,0,300,2.000");
  size_t rows = 1;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 4u);
  EXPECT_THROW(log.writeCsv("/nonexistent-dir/frames.csv"), Error);
}

}  // namespace
}  // namespace farfield::runtime
