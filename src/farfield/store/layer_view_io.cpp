// The data files of cells (DIR/cells): the Sillion cell impostors (writeCell, loadImpostor) and the layer views of the
// pipeline records (writeLayerView, loadLayerView), each a mesh file, a PNG texture and a PNG of ids, checked on load.
#include "farfield/store/impostor_store.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "farfield/core/error.h"
#include "farfield/image/png_io.h"
#include "farfield/store/generation_names.h"
#include "farfield/store/store_files.h"

namespace fs = std::filesystem;

namespace farfield::store {

namespace {

// PNG through a temporary name (image::writePng writes to a path); the check is taken from the bytes written.
FileCheck writePngAtomic(const std::string& path, const image::ColorImage& image) {
  const std::string tmp = tempName(path);
  fileOperation("create", tmp);
  image::writePng(tmp, image);
  const FileCheck check = fileCheck(readWholeFile(tmp, ""));
  commitTemp(tmp, path, false);
  return check;
}

// A PNG named by the index: checked, then decoded; errors name the record too.
image::ColorImage readCheckedPng(const std::string& path, const FileCheck& check, const std::string& record) {
  if (check.known) readCheckedFile(path, check, record);
  try {
    return image::readPng(path);
  } catch (const Error& e) {
    throw Error(record + ": " + e.what());
  }
}

void createCellsDirectory(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "cells", ec);
  if (ec) throw Error(dir, "cannot create the cells directory: " + ec.message());
}

}  // namespace

std::string textureFileName(uint32_t half_edge, uint64_t generation) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "e%06u.png", half_edge);
  return "cells/" + generationPrefix(generation) + buf;
}

std::string meshFileName(uint32_t half_edge, const std::string& technique, uint64_t generation) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "e%06u.", half_edge);
  return "cells/" + generationPrefix(generation) + buf + technique + ".ffmesh";
}

void writeCell(const std::string& dir, CellEntry& entry,
               const std::map<std::string, const impostor::DepthMeshImpostor*>& impostors, uint64_t generation) {
  createCellsDirectory(dir);
  entry.texture.clear();
  entry.texture_check = {};
  const image::ColorImage* written = nullptr;
  for (const auto& [technique, imp] : impostors) {
    StoredImpostor& s = entry.impostors[technique];
    s.mesh = meshFileName(entry.half_edge, technique, generation);
    s.triangles = imp->mesh.triangleCount();
    s.vertices = imp->mesh.vertexCount();
    s.mesh_check = writeMesh(joinPath(dir, s.mesh), *imp);
    if (imp->empty() || !imp->texture) continue;
    if (!written) {
      entry.texture = textureFileName(entry.half_edge, generation);
      entry.texture_check = writePngAtomic(joinPath(dir, entry.texture), *imp->texture);
      written = imp->texture.get();
    } else if (written->width() != imp->texture->width() || written->height() != imp->texture->height() ||
               written->pixels() != imp->texture->pixels()) {
      // Different textures for the same cell: the format has one texture per cell, so this is a caller error.
      throw Error(dir, "cell " + std::to_string(entry.half_edge) + ": technique " + technique +
                           " has a texture different from the cell's (impostors of a cell must share one capture)");
    }
  }
}

impostor::DepthMeshImpostor loadImpostor(const std::string& dir, const CellEntry& entry,
                                         const std::string& technique) {
  const auto it = entry.impostors.find(technique);
  if (it == entry.impostors.end())
    throw Error(joinPath(dir, kIndexFile), "cell " + std::to_string(entry.half_edge) + " has no " + technique +
                                               " impostor");
  // A Sillion cell impostor is a one-view layer whose texture is the cell's.
  StoredView view;
  view.camera = entry.camera;
  view.texture = entry.texture;
  view.texture_check = entry.texture_check;
  view.mesh = it->second.mesh;
  view.mesh_check = it->second.mesh_check;
  view.triangles = it->second.triangles;
  view.vertices = it->second.vertices;
  view.record = "cell " + std::to_string(entry.half_edge) + " " + technique;
  return loadLayerView(dir, view);
}

std::string layerFileStem(uint32_t half_edge, const std::string& kind, size_t layer, size_t view,
                          uint64_t generation) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "e%06u.%s.%02zu.%zu", half_edge, kind.c_str(), layer, view);
  return "cells/" + generationPrefix(generation) + buf;
}

StoredView writeLayerView(const std::string& dir, const std::string& stem, const impostor::DepthMeshImpostor& view) {
  createCellsDirectory(dir);
  StoredView out;
  out.camera = view.camera;
  out.mesh = stem + ".ffmesh";
  out.triangles = view.mesh.triangleCount();
  out.vertices = view.mesh.vertexCount();
  out.mesh_check = writeMesh(joinPath(dir, out.mesh), view);
  if (!view.empty() && view.texture) {
    out.texture = stem + ".png";
    out.texture_check = writePngAtomic(joinPath(dir, out.texture), *view.texture);
  }
  if (!view.empty() && view.ids) {
    // 32-bit ids in the four 8-bit channels: PNG keeps them exactly and compresses the large runs of one id.
    image::ColorImage packed(view.ids->width(), view.ids->height());
    for (size_t i = 0; i < packed.pixelCount(); ++i) {
      const uint32_t id = view.ids->pixels()[i];
      packed.pixels()[i] = image::Rgba8(uint8_t(id), uint8_t(id >> 8), uint8_t(id >> 16), uint8_t(id >> 24));
    }
    out.ids = stem + ".ids.png";
    out.ids_check = writePngAtomic(joinPath(dir, out.ids), packed);
  }
  return out;
}

impostor::DepthMeshImpostor loadLayerView(const std::string& dir, const StoredView& view) {
  const std::string record = view.record.empty() ? "layer view" : view.record;
  const std::string mesh_file = joinPath(dir, view.mesh);
  impostor::DepthMeshImpostor out =
      meshFromBytes(readCheckedFile(mesh_file, view.mesh_check, record + " mesh"), mesh_file, record + " mesh");
  if (out.mesh.triangleCount() != view.triangles || out.mesh.vertexCount() != view.vertices)
    throw Error(mesh_file, record + " mesh: holds " + std::to_string(out.mesh.triangleCount()) + " triangles and " +
                               std::to_string(out.mesh.vertexCount()) + " vertices, the index says " +
                               std::to_string(view.triangles) + " and " + std::to_string(view.vertices));
  out.camera = view.camera;
  if (out.empty()) return out;
  const std::string texture_file = joinPath(dir, view.texture);
  auto texture =
      std::make_shared<image::ColorImage>(readCheckedPng(texture_file, view.texture_check, record + " texture"));
  if (texture->width() != view.camera.width || texture->height() != view.camera.height)
    throw Error(texture_file, record + " texture: " + std::to_string(texture->width()) + "x" +
                                  std::to_string(texture->height()) + " but the creation camera is " +
                                  std::to_string(view.camera.width) + "x" + std::to_string(view.camera.height));
  out.texture = std::move(texture);
  if (!view.ids.empty()) {
    const std::string ids_file = joinPath(dir, view.ids);
    const image::ColorImage packed = readCheckedPng(ids_file, view.ids_check, record + " ids");
    if (packed.width() != view.camera.width || packed.height() != view.camera.height)
      throw Error(ids_file, record + " ids: id image is " + std::to_string(packed.width()) + "x" +
                                std::to_string(packed.height()) + " but the creation camera is " +
                                std::to_string(view.camera.width) + "x" + std::to_string(view.camera.height));
    auto ids = std::make_shared<image::IdImage>(packed.width(), packed.height(), 0u);
    for (size_t i = 0; i < packed.pixelCount(); ++i) {
      const image::Rgba8 c = packed.pixels()[i];
      ids->pixels()[i] = uint32_t(c.r) | uint32_t(c.g) << 8 | uint32_t(c.b) << 16 | uint32_t(c.a) << 24;
    }
    out.ids = std::move(ids);
  }
  return out;
}

}  // namespace farfield::store
