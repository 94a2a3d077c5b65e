// Reading a glTF accessor's elements safely: every offset, stride and count checked against its buffer view and
// buffer, so that a corrupt or truncated file gives a farfield::Error naming the file and the accessor instead of a
// read outside its data. Shared by the static importer (import.cpp) and the skinned-model reader (gltf_skin.cpp).
#pragma once

#include <cstddef>
#include <string>

namespace tinygltf {
class Model;
}

namespace farfield::scene {

struct GltfView {
  const unsigned char* data = nullptr;  // the first element
  size_t stride = 0;                    // bytes from one element to the next
  size_t count = 0;
  int component_type = 0;               // TINYGLTF_COMPONENT_TYPE_*
  int components = 0;                   // per element (VEC3: 3)
  bool normalized = false;
};

// The elements of accessor `index` of `model`. Throws Error(path, what + ...) for an index, buffer view or buffer
// out of range, a sparse accessor, an unknown type, or elements that do not fit in the view or the view in the buffer.
GltfView gltfAccessor(const tinygltf::Model& model, int index, const std::string& what, const std::string& path);

// Component `c` of element `i` as a number (normalized integers mapped to [0, 1] or [-1, 1]); NaN for a component
// type glTF does not define. The caller keeps i < count and c < components.
double gltfComponent(const GltfView& v, size_t i, int c);

}  // namespace farfield::scene
