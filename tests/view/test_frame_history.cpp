// The panel's counts of the two promises: frames over t_max, frames whose reference check measured parallax over
// the bound, frames with unchecked layers; the graph's ring of the last frames.
#include "farfield/view/frame_history.h"

#include <gtest/gtest.h>

namespace farfield::view {
namespace {

TEST(FrameHistory, CountsTheFramesThatBrokeEachPromise) {
  FrameHistory h;
  h.add(10.0, 8.0, 20.0, false);
  h.add(25.0, 8.0, 20.0, false);  // over t_max
  h.add(19.9, 8.0, 20.0, true);   // unchecked layers
  h.add(50.0, 8.0, 0.0, false);   // no budget: not counted
  h.addCheck(true);
  h.addCheck(false);
  const PromiseCounts& p = h.promises();
  EXPECT_EQ(p.frames, 4u);
  EXPECT_EQ(p.over_t_max, 1u);
  EXPECT_EQ(p.unchecked_frames, 1u);
  EXPECT_EQ(p.checked, 2u);
  EXPECT_EQ(p.over_bound, 1u);
  EXPECT_EQ(p.boundBroken(), 2u);
  EXPECT_FLOAT_EQ(h.maxMs(), 50.0f);
  h.reset();
  EXPECT_EQ(h.promises().frames, 0u);
}

TEST(FrameHistory, KeepsTheLastFramesOldestAtTheOffset) {
  FrameHistory h;
  for (size_t i = 0; i < kHistoryFrames + 5; ++i) h.add(double(i), 0.0, 0.0, false);
  ASSERT_EQ(h.cpuMs().size(), kHistoryFrames);
  EXPECT_FLOAT_EQ(h.cpuMs()[h.offset()], 5.0f);  // the oldest kept
  EXPECT_FLOAT_EQ(h.cpuMs()[(h.offset() + kHistoryFrames - 1) % kHistoryFrames], float(kHistoryFrames + 4));
}

}  // namespace
}  // namespace farfield::view
