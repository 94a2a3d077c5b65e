// glTF 2.0 scenes (scene/import.h through tinygltf): binary .glb when the input starts with the "glTF" magic, else
// the JSON form .gltf (buffers and images as data: URIs, or files that are missing).
#include <cstring>

#include "farfield/scene/import.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  farfield::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace farfield;
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const std::string path = fuzz::writeInput(binary ? "scene.glb" : "scene.gltf", data, size);
  fuzz::expectFarfieldErrors([&] {
    const scene::Scene s = scene::importScene(path);
    (void)s;
  });
  return 0;
}
