// Skinned, animated glTF models (scene/gltf_skin.h, the crowd's models): joints, inverse bind matrices, weights and
// animation channels from any .glb (binary when the input starts with the "glTF" magic, else the JSON form .gltf).
#include <cstring>

#include "farfield/scene/gltf_skin.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const std::string path = fuzz::writeInput(binary ? "model.glb" : "model.gltf", data, size);
  fuzz::expectFarfieldErrors([&] {
    const scene::SkinnedModel m = scene::importSkinnedModel(path);
    (void)m;
  });
  return 0;
}
