// The impostor mesh file (*.ffmesh, format in impostor_store.h): writeMesh, readMesh, and the parser they share with
// the loader of layer views (meshFromBytes).
//
// Why a raw binary mesh instead of glTF: the runtime loads an impostor inside a frame when the viewer enters a new
// cell, so the load must be a few reads and a validation pass, and the format must be trivial to check for
// truncation (the size is fixed by the counts in the header). glTF export of impostors is a later issue's.
#include "farfield/store/impostor_store.h"

#include <bit>
#include <cstring>
#include <string>

#include "farfield/core/error.h"
#include "farfield/store/store_files.h"

namespace farfield::store {

static_assert(std::endian::native == std::endian::little, "the mesh format is little-endian");

namespace {

constexpr char kMeshMagic[8] = {'F', 'F', 'I', 'M', 'E', 'S', 'H', '\0'};
constexpr size_t kMeshHeaderBytes = 24;

std::string meshBytes(const impostor::DepthMeshImpostor& impostor, const std::string& file) {
  const scene::Mesh& m = impostor.mesh;
  const uint32_t v = uint32_t(m.positions.size()), i = uint32_t(m.indices.size());
  const uint32_t t = uint32_t(impostor.triangle_ids.size());
  if (m.positions.size() >= 0xffffffffu || m.indices.size() >= 0xffffffffu)
    throw Error(file, "mesh too large for the format");
  if (i % 3 != 0) throw Error(file, "index count is not a multiple of 3");
  if (t != 0 && t != i / 3) throw Error(file, "triangle id count must be 0 or one per triangle");
  if (!m.uvs.empty() && m.uvs.size() != m.positions.size()) throw Error(file, "uv count differs from vertex count");
  std::string out;
  out.reserve(kMeshHeaderBytes + 20 * size_t(v) + 4 * size_t(i) + 4 * size_t(t));
  const auto put = [&](const void* data, size_t bytes) { out.append(static_cast<const char*>(data), bytes); };
  const uint32_t header[4] = {kMeshVersion, v, i, t};
  put(kMeshMagic, sizeof(kMeshMagic));
  put(header, sizeof(header));
  put(m.positions.data(), sizeof(Vec3) * v);
  if (m.uvs.empty())
    out.append(sizeof(Vec2) * v, '\0');
  else
    put(m.uvs.data(), sizeof(Vec2) * v);
  put(m.indices.data(), sizeof(uint32_t) * i);
  put(impostor.triangle_ids.data(), sizeof(uint32_t) * t);
  return out;
}

}  // namespace

impostor::DepthMeshImpostor meshFromBytes(const std::string& bytes, const std::string& file,
                                          const std::string& record) {
  static_assert(sizeof(Vec3) == 12 && sizeof(Vec2) == 8);
  const std::string at = record.empty() ? "" : record + ": ";
  const uint64_t size = bytes.size();
  if (size < kMeshHeaderBytes)
    throw Error(file, at + "truncated: " + std::to_string(size) + " bytes, shorter than the 24-byte header");
  char magic[8];
  uint32_t header[4];
  std::memcpy(magic, bytes.data(), sizeof(magic));
  std::memcpy(header, bytes.data() + sizeof(magic), sizeof(header));
  if (std::memcmp(magic, kMeshMagic, sizeof(magic)) != 0)
    throw Error(file, at + "bad magic: not a Farfield impostor mesh (expected \"FFIMESH\")");
  if (header[0] != kMeshVersion)
    throw Error(file, at + "unsupported mesh version " + std::to_string(header[0]) + " (this build reads version " +
                          std::to_string(kMeshVersion) + ")");
  const uint64_t v = header[1], i = header[2], t = header[3];
  if (i % 3 != 0) throw Error(file, at + "index count " + std::to_string(i) + " is not a multiple of 3");
  if (t != 0 && t != i / 3)
    throw Error(file, at + "triangle id count " + std::to_string(t) + " must be 0 or " + std::to_string(i / 3));
  const uint64_t expected = kMeshHeaderBytes + 20 * v + 4 * i + 4 * t;
  if (size < expected)
    throw Error(file, at + "truncated: " + std::to_string(size) + " bytes, the header's counts need " +
                          std::to_string(expected));
  if (size > expected)
    throw Error(file, at + "trailing data: " + std::to_string(size) + " bytes, the header's counts need " +
                          std::to_string(expected));
  impostor::DepthMeshImpostor out;
  scene::Mesh& m = out.mesh;
  m.positions.resize(v);
  m.uvs.resize(v);
  m.indices.resize(i);
  out.triangle_ids.resize(t);
  const char* p = bytes.data() + kMeshHeaderBytes;
  const auto take = [&](void* dst, size_t n) {
    if (n > 0) std::memcpy(dst, p, n);  // an empty vector's data() may be null: memcpy must not see it
    p += n;
  };
  take(m.positions.data(), 12 * v);
  take(m.uvs.data(), 8 * v);
  take(m.indices.data(), 4 * i);
  take(out.triangle_ids.data(), 4 * t);
  for (uint64_t k = 0; k < v; ++k)
    if (!isFinite(m.positions[k]) || !isFinite(m.uvs[k]))
      throw Error(file, at + "vertex " + std::to_string(k) + ": non-finite position or uv");
  for (uint64_t k = 0; k < i; ++k)
    if (m.indices[k] >= v)
      throw Error(file, at + "index " + std::to_string(k) + " is " + std::to_string(m.indices[k]) +
                            ", out of range for " + std::to_string(v) + " vertices");
  m.computeBounds();
  out.stats.triangles = m.triangleCount();
  out.stats.vertices = m.vertexCount();
  return out;
}

FileCheck writeMesh(const std::string& file, const impostor::DepthMeshImpostor& impostor) {
  return writeFileAtomic(file, meshBytes(impostor, file), false);
}

impostor::DepthMeshImpostor readMesh(const std::string& file) {
  return meshFromBytes(readWholeFile(file, ""), file, "");
}

}  // namespace farfield::store
