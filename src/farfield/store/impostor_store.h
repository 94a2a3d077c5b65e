// On-disk store of baked cell impostors: a simple, documented directory format (a later issue defines the full,
// paged and checksummed database; this one is what `farfield bake` writes and the impostor bench modes read).
//
// Layout of a store directory DIR:
//   DIR/index.json          the index (below)
//   DIR/streets.json        copy of the street graph the cells refer to (StreetGraph::save format)
//   DIR/cells/eNNNNNN.png   per baked cell: the impostor texture (RGBA8; alpha 0 = background), shared by the
//                           cell's techniques (they are built from one capture)
//   DIR/cells/eNNNNNN.TECHNIQUE.ffmesh   per baked cell and technique: the impostor mesh (binary, below)
//
// index.json:
//   {"format": "farfield-impostor-store", "version": 1,
//    "techniques": ["depth-mesh", "grid-mesh"],        // built for every baked cell
//    "streets": "streets.json", "scene": "city.glb",  // streets relative to DIR; scene only informative
//    "scene_objects": 1234,                             // object count of the scene baked (checked on load)
//    "local_model": "edge", "cell_lookup": "street",    // segmentation (urban/cells.h); cell_lookup optional
//    "options": {...},                                  // bake options, informative
//    "cells": [{"half_edge": 12,
//               "camera": {"eye": [x,y,z], "at": [x,y,z], "up": [x,y,z], "fov_y": rad, "width": 512,
//                          "height": 512, "near": 0.5, "far": 20000},
//               "local_objects": [1, 17, 18],          // object ids drawn as geometry with this cell
//               "distant_objects": 1200, "data_pixels": 123456, "render_ms": 35.2,
//               "texture": "cells/e000012.png",        // "" when every impostor of the cell is empty
//               "impostors": {"depth-mesh": {"mesh": "cells/e000012.depth-mesh.ffmesh", "triangles": 1034,
//                                            "vertices": 560, "build_ms": 40.1}, ...}}, ...]}
//   Cells are sorted by half-edge id, each at most once. Numbers are JSON numbers (floats written with enough digits
//   to read back exactly).
//
// Mesh file (*.ffmesh), little-endian:
//   offset 0  char[8]  magic "FFIMESH\0"
//          8  uint32   version (1)
//         12  uint32   vertex count V
//         16  uint32   index count I (a multiple of 3)
//         20  uint32   triangle id count T (0, or I / 3)
//         24  float32  positions [V][3] (world metres), then uvs [V][2], then uint32 indices [I], then uint32
//                      triangle object ids [T]
//   The file size must be exactly 24 + 20 V + 4 I + 4 T bytes; every index < V; positions and uvs finite.
//
// Every reader throws farfield::Error naming the file and what is wrong (missing, truncated, bad magic, unsupported
// version, inconsistent counts, index out of range, ...).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/camera.h"
#include "farfield/impostor/impostor_mesh.h"

namespace farfield::store {

inline constexpr int kIndexVersion = 1;
inline constexpr uint32_t kMeshVersion = 1;
inline constexpr char kIndexFormat[] = "farfield-impostor-store";
inline constexpr char kIndexFile[] = "index.json";
inline constexpr char kStreetsFile[] = "streets.json";

struct StoredImpostor {
  std::string mesh;        // mesh file, relative to the store directory
  size_t triangles = 0;
  size_t vertices = 0;
  double build_ms = 0.0;   // CPU time of the construction (contour, discrepancy, triangulation, reprojection)
};

struct CellEntry {
  uint32_t half_edge = 0;
  Camera camera;                         // creation camera
  std::vector<uint32_t> local_objects;   // ascending object ids
  size_t distant_objects = 0;
  size_t data_pixels = 0;
  double render_ms = 0.0;
  std::string texture;                   // relative to the store directory; "" when no impostor has data
  std::map<std::string, StoredImpostor> impostors;  // technique -> impostor
};

struct StoreIndex {
  int version = kIndexVersion;
  std::vector<std::string> techniques;
  std::string streets = kStreetsFile;
  std::string scene;
  size_t scene_objects = 0;
  std::string local_model = "edge";
  std::string cell_lookup = "street";  // how the viewer's cell is found (urban::CellLookup): runtime default
  nlohmann::json options = nlohmann::json::object();
  std::vector<CellEntry> cells;  // sorted by half_edge

  // The entry of a half-edge, or null when the cell was not baked.
  const CellEntry* find(uint32_t half_edge) const;
  bool hasTechnique(const std::string& technique) const;
};

// Index I/O. readIndex validates the shape (format, version, types, sorted unique cells, every cell has every
// listed technique, relative file names without "..") and throws farfield::Error naming the file and the element.
nlohmann::json indexToJson(const StoreIndex& index);
StoreIndex indexFromJson(const nlohmann::json& json, const std::string& source);
void writeIndex(const std::string& dir, const StoreIndex& index);
StoreIndex readIndex(const std::string& dir);

// Mesh file I/O (format above). writeMesh writes mesh.positions, mesh.uvs (must have one per position: zeros are
// written when missing), indices and triangle_ids. readMesh fills mesh (positions, uvs, indices, bounds) and
// triangle_ids of the returned impostor; texture and camera are left empty.
void writeMesh(const std::string& file, const impostor::DepthMeshImpostor& impostor);
impostor::DepthMeshImpostor readMesh(const std::string& file);

// File names used by the bake for a half-edge (relative to the store directory).
std::string textureFileName(uint32_t half_edge);
std::string meshFileName(uint32_t half_edge, const std::string& technique);

// Writes a cell's impostors (technique -> impostor, all from the same capture) into `dir` and fills the entry's
// texture and impostors (file names, counts; build_ms is left to the caller). Every impostor gets a mesh file, an
// empty one too; the one texture is written once (the techniques of a cell come from one capture: a technique with a
// different texture throws farfield::Error). Creates DIR/cells. Thread-safe for different cells.
void writeCell(const std::string& dir, CellEntry& entry,
               const std::map<std::string, const impostor::DepthMeshImpostor*>& impostors);

// Loads one impostor of a cell: mesh, texture (shared, RGBA8) and creation camera. Empty impostors have a mesh file
// too (with zero counts) and no texture. Throws farfield::Error (file and problem), also when the
// file's counts disagree with the index or the texture size with the camera.
impostor::DepthMeshImpostor loadImpostor(const std::string& dir, const CellEntry& entry,
                                         const std::string& technique);

}  // namespace farfield::store
