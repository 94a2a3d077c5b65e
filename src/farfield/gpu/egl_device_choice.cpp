// The EGL device of the GPU a scheduler assigned (EGL_NV_device_cuda).
#include "farfield/gpu/egl_device_choice.h"

#include <string>

namespace farfield::gpu {

namespace {

std::optional<int> firstNumber(const char* list) {
  if (!list || !*list) return std::nullopt;
  std::string first(list);
  first = first.substr(0, first.find(','));
  if (first.empty() || first.size() > 6 || first.find_first_not_of("0123456789") != std::string::npos)
    return std::nullopt;
  return std::stoi(first);
}

}  // namespace

std::optional<int> assignedGpu(const char* slurm_step_gpus, const char* slurm_job_gpus, const char* cuda_visible) {
  for (const char* list : {slurm_step_gpus, slurm_job_gpus, cuda_visible})
    if (list && *list) return firstNumber(list);
  return std::nullopt;
}

std::vector<size_t> eglDeviceOrder(const std::vector<int>& cuda_ids, std::optional<int> assigned) {
  std::vector<size_t> order;
  if (assigned)
    for (size_t i = 0; i < cuda_ids.size(); ++i)
      if (cuda_ids[i] == *assigned) {
        order.push_back(i);
        break;
      }
  for (size_t i = 0; i < cuda_ids.size(); ++i)
    if (order.empty() || order.front() != i) order.push_back(i);
  return order;
}

}  // namespace farfield::gpu
