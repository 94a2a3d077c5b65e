// Cost profiles (gpu/cost_profile.h, what `farfield calibrate` writes and `place` reads).
#include "farfield/gpu/cost_profile.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  const std::string path = fuzz::writeInput("profile.json", data, size);
  fuzz::expectFarfieldErrors([&] {
    const gpu::CostProfile p = gpu::loadCostProfile(path);
    // Placement's use of it: bounds of a few workloads.
    volatile double sink = p.boundMs(1e6, 100.0, double(p.width) * double(p.height));
    sink = p.boundMs(0.0, 0.0, 0.0);
    (void)sink;
  });
  return 0;
}
