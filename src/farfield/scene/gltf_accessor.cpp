#include "farfield/scene/gltf_accessor.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>

#include "farfield/core/error.h"

namespace farfield::scene {

namespace {

// The bytes of buffer view `index`, checked against its buffer; empty with *why set when the view or its buffer is
// out of range or the view does not fit in the buffer (*why is left alone otherwise).
std::span<const unsigned char> viewBytes(const tinygltf::Model& model, int index, std::string* why) {
  if (index < 0 || size_t(index) >= model.bufferViews.size()) {
    *why = "buffer view " + std::to_string(index) + " out of range";
    return {};
  }
  const tinygltf::BufferView& bv = model.bufferViews[size_t(index)];
  if (bv.buffer < 0 || size_t(bv.buffer) >= model.buffers.size()) {
    *why = "buffer " + std::to_string(bv.buffer) + " out of range";
    return {};
  }
  const tinygltf::Buffer& buf = model.buffers[size_t(bv.buffer)];
  const uint64_t end = uint64_t(bv.byteOffset) + uint64_t(bv.byteLength);
  if (end > buf.data.size() || end < uint64_t(bv.byteOffset)) {
    *why = "buffer view " + std::to_string(index) + " ends at byte " + std::to_string(end) + " past the buffer's " +
           std::to_string(buf.data.size()) + " bytes (truncated file?)";
    return {};
  }
  return {buf.data.data() + bv.byteOffset, size_t(bv.byteLength)};
}

}  // namespace

GltfView gltfAccessor(const tinygltf::Model& model, int index, const std::string& what, const std::string& path) {
  auto fail = [&](const std::string& message) { throw Error(path, message); };
  if (index < 0 || size_t(index) >= model.accessors.size())
    fail(what + ": accessor " + std::to_string(index) + " out of range");
  const tinygltf::Accessor& a = model.accessors[size_t(index)];
  const std::string where = what + " (accessor " + std::to_string(index) + ")";
  if (a.sparse.isSparse) fail(where + ": sparse accessors are not supported");
  std::string why;
  const std::span<const unsigned char> view = viewBytes(model, a.bufferView, &why);
  if (!why.empty()) fail(where + ": " + why);
  const int comp_size = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
  const int comps = tinygltf::GetNumComponentsInType(uint32_t(a.type));
  if (comp_size <= 0 || comps <= 0) fail(where + ": unknown component or element type");
  const uint64_t elem = uint64_t(comp_size) * uint64_t(comps);
  const int byte_stride = model.bufferViews[size_t(a.bufferView)].byteStride;  // the view is valid (viewBytes)
  const uint64_t stride = byte_stride > 0 ? uint64_t(byte_stride) : elem;
  if (stride < elem) fail(where + ": byte stride smaller than one element");
  const uint64_t start = uint64_t(a.byteOffset);
  if (a.count > 0 && start + stride * (uint64_t(a.count) - 1) + elem > view.size())
    fail(where + ": " + std::to_string(a.count) + " elements do not fit in the buffer view (truncated file?)");
  GltfView v;
  v.data = view.data() + start;
  v.stride = size_t(stride);
  v.count = a.count;
  v.component_type = a.componentType;
  v.components = comps;
  v.normalized = a.normalized;
  return v;
}

std::span<const unsigned char> gltfImageBytes(const tinygltf::Model& model, int index, std::string* why) {
  if (index < 0 || size_t(index) >= model.images.size()) {
    *why = "image " + std::to_string(index) + " out of range";
    return {};
  }
  std::string view_why;
  const std::span<const unsigned char> bytes = viewBytes(model, model.images[size_t(index)].bufferView, &view_why);
  if (!view_why.empty()) *why = "image " + std::to_string(index) + ": " + view_why;
  return bytes;
}

double gltfComponent(const GltfView& v, size_t i, int c) {
  const unsigned char* p = v.data + i * v.stride;
  switch (v.component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p + 4 * c, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return v.normalized ? p[c] / 255.0 : p[c];
    case TINYGLTF_COMPONENT_TYPE_BYTE: return v.normalized ? std::max(int8_t(p[c]) / 127.0, -1.0) : int8_t(p[c]);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t s;
      std::memcpy(&s, p + 2 * c, 2);
      return v.normalized ? s / 65535.0 : s;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t s;
      std::memcpy(&s, p + 2 * c, 2);
      return v.normalized ? std::max(s / 32767.0, -1.0) : s;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t u;
      std::memcpy(&u, p + 4 * c, 4);
      return u;
    }
    default: return std::nan("");
  }
}

}  // namespace farfield::scene
