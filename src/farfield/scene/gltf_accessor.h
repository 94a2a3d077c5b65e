// Reading a glTF accessor's elements safely: every offset, stride and count checked against its buffer view and
// buffer, so that a corrupt or truncated file gives a farfield::Error naming the file and the accessor instead of a
// read outside its data. Shared by the static importer (import_gltf.cpp) and the skinned-model reader (gltf_skin.cpp).
#pragma once

#include <cstddef>
#include <span>
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

// The bytes of image `index` when it lives in a buffer view (Image::bufferView >= 0), checked against the view and
// its buffer. Empty, with *why saying what is wrong, for an image index, view or buffer out of range, or a view that
// does not fit in its buffer. tinygltf 2.7 hands its image callback &buffer.data[byteOffset] and byteLength without
// that check (a corrupt file made the callback read past the buffer), so the callbacks of import_gltf.cpp and
// gltf_skin.cpp leave such images alone and the readers take their bytes from here once the model is loaded.
std::span<const unsigned char> gltfImageBytes(const tinygltf::Model& model, int index, std::string* why);

// Component `c` of element `i` as a number (normalized integers mapped to [0, 1] or [-1, 1]); NaN for a component
// type glTF does not define. The caller keeps i < count and c < components.
double gltfComponent(const GltfView& v, size_t i, int c);

}  // namespace farfield::scene
