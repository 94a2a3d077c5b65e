// Which EGL device a process renders on when a batch scheduler gave it a GPU (a Slurm task of a sharded bake:
// scripts/slurm/bake-array.sh). EGL lists every GPU of the node whatever CUDA_VISIBLE_DEVICES says, so the device is
// found by its CUDA device number (EGL_NV_device_cuda's EGL_CUDA_DEVICE_NV) and tried first.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace farfield::gpu {

// The GPU the scheduler assigned: the first id of SLURM_STEP_GPUS, else SLURM_JOB_GPUS, else CUDA_VISIBLE_DEVICES
// (each a comma-separated list of GPU numbers; null or empty = not set); none when no list is set or its first
// entry is not a number (CUDA_VISIBLE_DEVICES may hold GPU UUIDs: those are not matched).
std::optional<int> assignedGpu(const char* slurm_step_gpus, const char* slurm_job_gpus, const char* cuda_visible);

// The order to try EGL devices in: the one whose CUDA device number (cuda_ids[i], -1 for a device without one) is
// `assigned` first, then the others in their order. Without an assignment, or when no device has that number, the
// devices' own order.
std::vector<size_t> eglDeviceOrder(const std::vector<int>& cuda_ids, std::optional<int> assigned);

}  // namespace farfield::gpu
