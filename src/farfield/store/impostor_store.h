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
//   {"format": "farfield-impostor-store", "version": 2,
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
//   Version 2 adds, for stores written by `farfield bake --pipeline` (bake/pipeline.h): top-level "pipeline" (the
//   stages, e.g. ["pvs", "near-far", "mmi"]), "online" (the stages left to the runtime) and "storage" (section 5.1's
//   estimate next to the bytes written); "techniques" may then be empty. Each cell gets
//     "pipeline": {"pvs": {"ids": [...], "samples": 31, "ms": 4000},
//                  "split": {"near": [...], "far": [...]},
//                  "mmi": {"threshold_rad": 0.0205, "event_edges": 120, "max_weight_rad": 0.9, "weights_ms": 0.4,
//                          "layers": [{"objects": [...], "views": [VIEW, ...]}, ...],   // nearest layer first
//                          "single": {"objects": [...], "views": [VIEW, ...]}}}          // the single mesh
//   with VIEW = {"camera": {...}, "texture": "cells/e000012.mmi.00.0.png", "mesh": "cells/e000012.mmi.00.0.ffmesh",
//                "ids": "cells/e000012.mmi.00.0.ids.png" (optional),
//                "triangles": 540, "vertices": 300, "data_pixels": 81234, "render_ms": 20.1, "build_ms": 3.2}
//   (each part present when its stage was baked). Version 1 indexes are still read.
//   Version 3 captures each layer (and the single mesh) from one or more stations along the cell (the cell's start
//   first), gives every VIEW its "station" index, and adds to every layer and to "single" (when it has views) the
//   validity region of each station's views (impostor/validity.h), computed at bake time:
//     "validity": [{"origin": [x,y,z], "end": [x,y,z], "half_width": 5.4, "below": 0.6, "above": 0.3, "back": 2,
//                   "step": 1, "laterals": 9, "envelope": [0, 0.0004, ...]}, ...]   // radians, one per station
//   and requires the pipeline options in "options.pipeline" whole (bake/pipeline.h); version 2 is still read.
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
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/camera.h"
#include "farfield/impostor/impostor_mesh.h"
#include "farfield/impostor/validity.h"

namespace farfield::store {

inline constexpr int kIndexVersion = 3;  // 1 (Sillion only) and 2 (pipeline, no validity regions) are still read
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

// One image-based view of a layer (multi-mesh impostors, Decoret et al. 1999): the creation camera, its texture and
// its mesh. A layer has one view along the street, or six (cube faces) for 360 degrees.
struct StoredView {
  Camera camera;
  std::string texture;     // relative to the store directory; "" when the view has no data
  std::string mesh;        // relative to the store directory (an empty view has a mesh file with zero counts)
  std::string ids;         // per-texel object ids, PNG with each id's 4 bytes (little-endian) in R, G, B, A; ""
                           // when none (drawn as an id texture: item buffers then show every pixel's object)
  size_t triangles = 0;
  size_t vertices = 0;
  size_t data_pixels = 0;
  double render_ms = 0.0;  // capture (GL thread)
  double build_ms = 0.0;   // mesh construction (worker thread)
  uint32_t station = 0;    // the capture station along the cell (version 3; 0 = the cell's start)
};

// One layer of a cell's far geometry: objects among which only negligible visibility events occur (w_ij <= T for
// every pair), drawn as one meshed impostor per view.
struct StoredLayer {
  std::vector<uint32_t> objects;  // object ids, ascending
  std::vector<StoredView> views;
  // Per capture station, where its views may be drawn under an error bound (impostor/validity.h): version 3 stores
  // have one per station of every layer with views (views name their station), version 2 stores none (the runtime
  // then counts the layer as unchecked).
  std::vector<impostor::ValidityRegion> validity;
};

// What the extractor pipeline (farfield/bake/pipeline.h) found for a cell. Each part is present when its stage ran
// in the bake; stages run online (index "online") leave theirs for the runtime.
struct CellPipeline {
  bool has_pvs = false;
  std::vector<uint32_t> pvs;      // potentially visible object ids, ascending
  size_t pvs_samples = 0;         // sample points along the cell
  double pvs_ms = 0.0;
  bool has_split = false;
  std::vector<uint32_t> near;     // drawn as geometry (ascending)
  std::vector<uint32_t> far;      // replaced by image-based representations (ascending)
  bool has_mmi = false;
  double threshold_rad = 0.0;     // T of the layering
  size_t event_edges = 0;         // edges of the visibility-event graph (w_ij > 0)
  double max_weight_rad = 0.0;
  double weights_ms = 0.0;        // event graph + layering
  std::vector<StoredLayer> layers;  // the multi-mesh impostor (MMI), nearest layer first
  StoredLayer single;             // the single-mesh impostor (SMI) of the same far objects, for comparison
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
  std::optional<CellPipeline> pipeline;              // stores written by `farfield bake --pipeline`
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
  // Extractor pipeline of the bake (`--pipeline`), empty for a Sillion-only store, and the stages left to run
  // online (a tail of the pipeline).
  std::vector<std::string> pipeline;
  std::vector<std::string> online;
  nlohmann::json storage = nlohmann::json::object();  // the paper's storage estimate next to the bytes written
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

// File names of a layer view: cells/eNNNNNN.KIND.LL.V.png and .ffmesh (KIND "mmi" or "smi").
std::string layerFileStem(uint32_t half_edge, const std::string& kind, size_t layer, size_t view);
// Writes one layer view (texture when it has data, mesh always) under `dir` and returns its entry (camera, files,
// counts; render_ms and build_ms left to the caller). Creates DIR/cells. Thread-safe for different stems.
StoredView writeLayerView(const std::string& dir, const std::string& stem, const impostor::DepthMeshImpostor& view);
// Loads a layer view (mesh, texture, camera) and checks the counts and the texture size against the entry.
impostor::DepthMeshImpostor loadLayerView(const std::string& dir, const StoredView& view);

// Loads one impostor of a cell: mesh, texture (shared, RGBA8) and creation camera. Empty impostors have a mesh file
// too (with zero counts) and no texture. Throws farfield::Error (file and problem), also when the
// file's counts disagree with the index or the texture size with the camera.
impostor::DepthMeshImpostor loadImpostor(const std::string& dir, const CellEntry& entry,
                                         const std::string& technique);

}  // namespace farfield::store
