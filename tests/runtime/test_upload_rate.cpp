// The expected upload time of a view (runtime/upload_rate.h): one preempted upload among many does not move it (the
// slowest-so-far rule it replaced would have taken 20x), a slowdown of more than a tenth of the recent uploads does,
// and it scales with the bytes.
#include "farfield/runtime/upload_rate.h"

#include <gtest/gtest.h>

namespace farfield::runtime {
namespace {

TEST(UploadRateTest, IgnoresASinglePreemptedUploadAndFollowsASlowdown) {
  UploadRate rate;
  EXPECT_FALSE(rate.known());
  EXPECT_EQ(rate.predictMs(1 << 20), 0.0);
  const uint64_t mb = 1 << 20;
  for (int k = 0; k < 31; ++k) rate.add(0.25 + 0.001 * k, mb);  // 0.25-0.28 ms per MiB
  rate.add(5.0, mb);                                             // preempted
  EXPECT_TRUE(rate.known());
  const double one = rate.predictMs(mb);
  EXPECT_GE(one, 0.25);
  EXPECT_LE(one, 0.281);
  EXPECT_NEAR(rate.predictMs(4 * mb), 4.0 * one, 1e-9);
  rate.add(1.0, 0);  // no bytes: no rate
  EXPECT_EQ(rate.predictMs(mb), one);
  // A slowdown: the last 8 of 32 uploads at 2 ms per MiB (a quarter, more than the tenth the quantile leaves out).
  for (int k = 0; k < 8; ++k) rate.add(2.0, mb);
  EXPECT_NEAR(rate.predictMs(mb), 2.0, 1e-9);
}

}  // namespace
}  // namespace farfield::runtime
