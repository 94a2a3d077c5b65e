// Camera paths (gen/camera_path.h, the JSON `farfield path` writes and `walk`, `bench`, `view --path` read).
#include "farfield/gen/camera_path.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  const std::string path = fuzz::writeInput("path.json", data, size);
  fuzz::expectFarfieldErrors([&] {
    const gen::CameraPath p = gen::loadCameraPath(path);
    // What every reader of a path does next: a camera per frame, and the view space around it.
    for (size_t i = 0; i < p.frames.size() && i < 64; ++i) p.camera(i, 640, 360).validate("fuzz camera");
    gen::eyeBounds(p, 30.0f, "fuzz");
  });
  return 0;
}
