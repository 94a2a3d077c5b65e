// The EGL device of a scheduler's GPU (gpu/egl_device_choice.h): the assigned GPU from Slurm's and CUDA's variables
// in their order of precedence, and that device first with the others after it, against hand-made device lists.
#include <gtest/gtest.h>

#include "farfield/gpu/egl_device_choice.h"

namespace farfield::gpu {
namespace {

TEST(EglDeviceChoiceTest, TheAssignedGpuComesFromSlurmBeforeCuda) {
  EXPECT_EQ(assignedGpu("3", "1,2", "0"), 3);
  EXPECT_EQ(assignedGpu(nullptr, "2,5", "0"), 2);
  EXPECT_EQ(assignedGpu("", "", "7"), 7);
  EXPECT_EQ(assignedGpu(nullptr, nullptr, nullptr), std::nullopt);
  EXPECT_EQ(assignedGpu(nullptr, nullptr, "GPU-8f2c1a3e-0000"), std::nullopt);  // UUIDs are not matched
  EXPECT_EQ(assignedGpu("x1", nullptr, "0"), std::nullopt);                     // the first set list decides
}

TEST(EglDeviceChoiceTest, TheAssignedDeviceIsTriedFirstAndEveryDeviceOnce) {
  using V = std::vector<size_t>;
  // Mesa's software device (no CUDA id) first, then four GPUs listed out of CUDA order.
  const std::vector<int> ids = {-1, 2, 0, 3, 1};
  EXPECT_EQ(eglDeviceOrder(ids, 3), (V{3, 0, 1, 2, 4}));
  EXPECT_EQ(eglDeviceOrder(ids, 0), (V{2, 0, 1, 3, 4}));
  EXPECT_EQ(eglDeviceOrder(ids, 9), (V{0, 1, 2, 3, 4}));  // not on this node: the devices' order
  EXPECT_EQ(eglDeviceOrder(ids, std::nullopt), (V{0, 1, 2, 3, 4}));
  EXPECT_EQ(eglDeviceOrder({}, 1), V{});
  EXPECT_EQ(eglDeviceOrder({1, 1}, 1), (V{0, 1}));
}

}  // namespace
}  // namespace farfield::gpu
