// On-disk store of baked cell impostors: a simple, documented directory format, checksummed and written atomically
// (what `farfield bake` writes and the impostor bench modes read).
//
// Layout of a store directory DIR (generation G, below, as six or more digits):
//   DIR/index.json                 the index (below); the only file ever replaced in place (atomically)
//   DIR/gG.streets.json            copy of the street graph the cells refer to (StreetGraph::toJson; version 1 and 2
//                                  stores: DIR/streets.json)
//   DIR/cells/gG.eNNNNNN.png       per baked cell: the impostor texture (RGBA8; alpha 0 = background), shared by the
//                                  cell's techniques (they are built from one capture)
//   DIR/cells/gG.eNNNNNN.TECHNIQUE.ffmesh   per baked cell and technique: the impostor mesh (binary, below)
//   DIR/cells/gG.eNNNNNN.KIND.LL.V.{png,ffmesh,ids.png}   layer views of pipeline records (below)
//   (stores of versions 1 and 2 name them without the "gG." prefix)
//
// index.json:
//   {"format": "farfield-impostor-store", "version": 3, "generation": 3, "checksum": 1234567,
//    "techniques": ["depth-mesh", "grid-mesh"],        // built for every baked cell
//    "streets": "g000003.streets.json", "streets_crc32": 99, "streets_bytes": 4567,  // relative to DIR
//    "scene": "city.glb",                               // informative
//    "scene_objects": 1234,                             // object count of the scene baked (checked on load)
//    "local_model": "edge", "cell_lookup": "street",    // segmentation (urban/cells.h); cell_lookup optional
//    "options": {...},                                  // bake options, informative
//    "cells": [{"half_edge": 12,
//               "camera": {"eye": [x,y,z], "at": [x,y,z], "up": [x,y,z], "fov_y": rad, "width": 512,
//                          "height": 512, "near": 0.5, "far": 20000},
//               "local_objects": [1, 17, 18],          // object ids drawn as geometry with this cell
//               "distant_objects": 1200, "data_pixels": 123456, "render_ms": 35.2,
//               "texture": "cells/g000003.e000012.png", "texture_crc32": 77, "texture_bytes": 81234,
//                                                      // "" (and no crc32/bytes) when every impostor is empty
//               "impostors": {"depth-mesh": {"mesh": "cells/g000003.e000012.depth-mesh.ffmesh", "mesh_crc32": 5,
//                                            "mesh_bytes": 6024, "triangles": 1034, "vertices": 560,
//                                            "build_ms": 40.1}, ...}}, ...]}
//   Version 2 adds, for stores written by `farfield bake --pipeline` (extract/pipeline_options.h): top-level "pipeline" (the
//   stages, e.g. ["pvs", "near-far", "mmi"]), "online" (the stages left to the runtime) and "storage" (section 5.1's
//   estimate next to the bytes written); "techniques" may then be empty. Each cell gets
//     "pipeline": {"pvs": {"ids": [...], "samples": 31, "ms": 4000},
//                  "split": {"near": [...], "far": [...]},
//                  "mmi": {"threshold_rad": 0.0205, "event_edges": 120, "max_weight_rad": 0.9, "weights_ms": 0.4,
//                          "layers": [{"objects": [...], "views": [VIEW, ...]}, ...],   // nearest layer first
//                          "single": {"objects": [...], "views": [VIEW, ...]}}}          // the single mesh
//   with VIEW = {"camera": {...}, "texture": "cells/g000003.e000012.mmi.00.0.png", "texture_crc32": ...,
//                "texture_bytes": ..., "mesh": "cells/g000003.e000012.mmi.00.0.ffmesh", "mesh_crc32": ...,
//                "mesh_bytes": ..., "ids": "cells/g000003.e000012.mmi.00.0.ids.png", "ids_crc32": ..., "ids_bytes": ...
//                (ids optional), "triangles": 540, "vertices": 300, "data_pixels": 81234, "render_ms": 20.1,
//                "build_ms": 3.2, "station": 0}
//   (each part present when its stage was baked).
//   Version 3 captures each layer (and the single mesh) from one or more stations along the cell (the cell's start
//   first), gives every VIEW its "station" index, and adds to every layer and to "single" (when it has views) the
//   validity region of each station's views (impostor/validity.h), computed at bake time:
//     "validity": [{"origin": [x,y,z], "end": [x,y,z], "half_width": 5.4, "below": 0.6, "above": 0.3, "back": 2,
//                   "step": 1, "laterals": 9, "envelope": [0, 0.0004, ...]}, ...]   // radians, one per station
//   and requires the pipeline options in "options.pipeline" whole (extract/pipeline_options.h).
//   Version 3 also makes the store trustworthy (SQLite's rules: a checksum per record, a write is atomic or did not
//   happen) and requires:
//   - next to every non-empty file name KEY ("streets", "texture", "mesh", "ids"): "KEY_crc32" (zlib's CRC-32 of the
//     file's bytes) and "KEY_bytes" (its size); every reader of a file named by the index checks both before parsing
//     and throws farfield::Error naming the file and the record (cell, technique or layer and view) and what is
//     wrong ("truncated: 1200 of 4096 bytes", "checksum mismatch"). readIndex checks the streets file;
//   - "generation": the number G in the names of the data files (a rewrite of a store writes generation G + 1 next
//     to the files of G, replaces index.json last, then removes what the new index does not name);
//   - "checksum": the CRC-32 of the index's compact dump (nlohmann::json::dump(), keys sorted) without "checksum";
//     the file must be exactly the writer's form (indexFileText: dump(1) and a newline), so every truncation and
//     byte flip of index.json is an error.
//   Version 4 makes the single mesh a stage of its own (extract/pipeline_options.h, "single"; `farfield bake
//   --technique depth-mesh|grid-mesh` is the pipeline near-far,single): the index's "pipeline" and "online" may name
//   "single", each cell's pipeline record holds it beside "mmi" (present when the stage was baked),
//     "pipeline": {..., "single": {"objects": [...], "views": [VIEW, ...], "validity": [...]}, "mmi": {...}}
//   and "mmi" no longer holds "single"; options.pipeline has no "single_mesh".
//   Versions 1 (Sillion only), 2 (pipeline, no validity regions, no checksums) and 3 are still read; any "checksum" or
//   "KEY_crc32"/"KEY_bytes" they carry is checked too. A version 2 or 3 index is read as version 4 holds it: when its
//   pipeline has "mmi", options.pipeline.single_mesh (required, a boolean) says whether that stage built the single
//   mesh; if so, "single" joins "pipeline" (and "online", when mmi ran online) before "mmi", and each cell's
//   "mmi.single" becomes its single stage's record (has_single). Written back as version 2 or 3 (tests of the old
//   formats), the old layout is written. The Sillion records of versions 1-3 ("techniques", a cell's "texture" and
//   "impostors") are still read and checked, but nothing writes them any more but writeCell (kept for the tests of
//   the format) and nothing draws them: re-bake such a store with `farfield bake --technique`.
//   A shard of a sharded bake (`farfield bake --shard K/N`, bake/shard.h) carries, in any version, what
//   `farfield merge` checks before joining the shards into one database:
//     "shard": {"index": K, "count": N, "scene_crc32": C,        // C: bake/shard.h's digest of the scene baked
//               "view_space": [...],                              // every cell of the whole bake, ascending
//               "cells": [...]}                                   // this shard's part of it, ascending
//   and its "cells" records hold only cells of its part. A database without "shard" is whole.
//   Cells are sorted by half-edge id, each at most once. Numbers are JSON numbers (floats written with enough digits
//   to read back exactly).
//
// Writes: every file goes to "NAME.tmp" in its directory, is fsync'ed and renamed over NAME. Data files (cells/,
// streets) are made durable as a batch: writeIndex fsyncs their directories before it renames the new index into
// place, then fsyncs DIR (one directory sync per store instead of one per file: a bake writes thousands of files).
// A bake killed at any point leaves the previous index and every file it names untouched, so the old store stays
// readable; after the new index is in place, files of older generations and leftover temporaries are removed.
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
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/camera.h"
#include "farfield/impostor/impostor_mesh.h"
#include "farfield/impostor/validity.h"

namespace farfield::store {

inline constexpr int kIndexVersion = 4;  // 1 (Sillion only), 2 (pipeline, no validity regions, no checksums) and
                                         // 3 (the single mesh inside mmi) are still read
inline constexpr uint32_t kMeshVersion = 1;
inline constexpr char kIndexFormat[] = "farfield-impostor-store";
inline constexpr char kIndexFile[] = "index.json";
inline constexpr char kStreetsFile[] = "streets.json";  // the street graph of version 1 and 2 stores

// Size and CRC-32 (zlib) of a file named by the index. `known` is false for files of version 1 and 2 indexes, which
// are read without the check.
struct FileCheck {
  uint64_t bytes = 0;
  uint32_t crc32 = 0;
  bool known = false;
};

struct StoredImpostor {
  std::string mesh;        // mesh file, relative to the store directory
  FileCheck mesh_check;
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
  FileCheck texture_check, mesh_check, ids_check;  // of the files above (version 3)
  // Where the view is in the index ("cell 12: mmi layer 1 view 2"), set by indexFromJson and not stored: readers
  // name it in their errors.
  std::string record;
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

// What the extractor pipeline (farfield/extract/pipeline_runner.h) found for a cell. Each part is present when its stage ran
// in the bake; stages run online (index "online") leave theirs for the runtime.
struct CellPipeline {
  bool has_pvs = false;
  std::vector<uint32_t> pvs;      // potentially visible object ids, ascending
  size_t pvs_samples = 0;         // sample points along the cell
  double pvs_ms = 0.0;
  bool has_split = false;
  std::vector<uint32_t> near;     // drawn as geometry (ascending)
  std::vector<uint32_t> far;      // replaced by image-based representations (ascending)
  bool has_single = false;
  StoredLayer single;             // the single-mesh impostor (SMI) of the far objects in view (the single stage)
  bool has_mmi = false;
  double threshold_rad = 0.0;     // T of the layering
  size_t event_edges = 0;         // edges of the visibility-event graph (w_ij > 0)
  double max_weight_rad = 0.0;
  double weights_ms = 0.0;        // event graph + layering
  std::vector<StoredLayer> layers;  // the multi-mesh impostor (MMI), nearest layer first
};

struct CellEntry {
  uint32_t half_edge = 0;
  Camera camera;                         // creation camera
  std::vector<uint32_t> local_objects;   // ascending object ids
  size_t distant_objects = 0;
  size_t data_pixels = 0;
  double render_ms = 0.0;
  std::string texture;                   // relative to the store directory; "" when no impostor has data
  FileCheck texture_check;
  std::map<std::string, StoredImpostor> impostors;  // technique -> impostor
  std::optional<CellPipeline> pipeline;              // stores written by `farfield bake --pipeline`
};

// The part of a sharded bake a database holds (see the format above).
struct ShardRecord {
  uint32_t index = 0;
  uint32_t count = 1;
  uint32_t scene_crc32 = 0;
  std::vector<uint32_t> view_space;  // ascending
  std::vector<uint32_t> cells;       // ascending, a subset of view_space
};

struct StoreIndex {
  int version = kIndexVersion;
  uint64_t generation = 0;               // number in the data file names (version 3; see the format above)
  std::vector<std::string> techniques;
  std::string streets = kStreetsFile;
  FileCheck streets_check;
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
  std::optional<ShardRecord> shard;  // a shard of a sharded bake; none for a whole database

  // The entry of a half-edge, or null when the cell was not baked.
  const CellEntry* find(uint32_t half_edge) const;
  bool hasTechnique(const std::string& technique) const;
};

// Index I/O. indexFromJson validates the shape (format, version, types, sorted unique cells, every cell has every
// listed technique, relative file names without "..", file checks of version 3) and throws farfield::Error naming
// the source and the element. indexToJson writes the file checks, "generation" and (indexFileText) "checksum" for
// version 3 only, so a version 2 index can still be written for tests of the old format.
nlohmann::json indexToJson(const StoreIndex& index);
StoreIndex indexFromJson(const nlohmann::json& json, const std::string& source);
// CRC-32 of the compact dump of `index_json` without its "checksum" member.
uint32_t indexChecksum(const nlohmann::json& index_json);
// The exact text writeIndex writes for `index_json`: "checksum" set (version 3 and later), dump(1), a newline.
std::string indexFileText(nlohmann::json index_json);
// Commits a store: checks that every file a version 3 index names has its FileCheck, makes the data files durable,
// replaces DIR/index.json atomically, then removes the files with store names (cells/eNNNNNN.*, cells/gG.*,
// streets.json, gG.streets.json, *.tmp of those) that the new index does not name. Creates DIR.
void writeIndex(const std::string& dir, const StoreIndex& index);
// Reads and validates DIR/index.json: checksum and form (when present; required by version 3), shape, and the
// streets file's size and CRC-32.
StoreIndex readIndex(const std::string& dir);

// The generation a rewrite of DIR writes: one more than the current index's and than any generation found in the
// names of files there (a killed bake may have left some); 1 for a new store.
uint64_t nextGeneration(const std::string& dir);
std::string streetsFileName(uint64_t generation);
// Writes the street graph text (StreetGraph::toJson) as the store's streets file of index.generation, atomically,
// and sets index.streets and index.streets_check.
void writeStreets(const std::string& dir, StoreIndex& index, std::string_view text);

// Integrity primitives (used by the writers and readers above; public for the bake and the tests).
FileCheck fileCheck(std::string_view bytes);
// Writes `bytes` to path.tmp, fsyncs it and renames it over `path`; with sync_directory also fsyncs the directory.
FileCheck writeFileAtomic(const std::string& path, std::string_view bytes, bool sync_directory = true);
// fsyncs DIR/cells (and DIR): the data files renamed there so far become durable (what a journal line that names
// them needs first: store/bake_journal.h).
void syncCellFiles(const std::string& dir);
// Reads a file named by the index and, when check.known, checks its size and CRC-32; throws farfield::Error
// "PATH: RECORD: truncated: N of M bytes" / "... checksum mismatch ..." / "... cannot open ...".
std::string readCheckedFile(const std::string& path, const FileCheck& check, const std::string& record);
// Test hook: called before every file operation of the writers ("create", "write" (half of the bytes are written),
// "fsync", "rename", "sync-dir", "remove") with the path it acts on; a test may throw or end the process there to
// simulate a crash. Set it only while no write is in flight; an empty function removes it.
void setFileOperationHook(std::function<void(const char* operation, const std::string& path)> hook);

// Mesh file I/O (format above). writeMesh writes mesh.positions, mesh.uvs (must have one per position: zeros are
// written when missing), indices and triangle_ids, atomically (the directory is synced by writeIndex), and returns
// the file's check. readMesh fills mesh (positions, uvs, indices, bounds) and triangle_ids of the returned impostor;
// texture and camera are left empty.
FileCheck writeMesh(const std::string& file, const impostor::DepthMeshImpostor& impostor);
impostor::DepthMeshImpostor readMesh(const std::string& file);

// File names used by the bake for a half-edge (relative to the store directory); generation 0 gives the names of
// version 1 and 2 stores (no "gG." prefix).
std::string textureFileName(uint32_t half_edge, uint64_t generation = 0);
std::string meshFileName(uint32_t half_edge, const std::string& technique, uint64_t generation = 0);

// Writes a cell's impostors (technique -> impostor, all from the same capture) into `dir` with the names of
// `generation` and fills the entry's texture and impostors (file names, checks, counts; build_ms is left to the
// caller). Every impostor gets a mesh file, an empty one too; the one texture is written once (the techniques of a
// cell come from one capture: a technique with a different texture throws farfield::Error). Creates DIR/cells.
// Thread-safe for different cells.
void writeCell(const std::string& dir, CellEntry& entry,
               const std::map<std::string, const impostor::DepthMeshImpostor*>& impostors, uint64_t generation = 0);

// File names of a layer view: cells/gG.eNNNNNN.KIND.LL.V.png and .ffmesh (KIND "mmi" or "smi"; no "gG." for
// generation 0).
std::string layerFileStem(uint32_t half_edge, const std::string& kind, size_t layer, size_t view,
                          uint64_t generation = 0);
// Writes one layer view (texture when it has data, mesh always) under `dir` and returns its entry (camera, files and
// their checks, counts; render_ms and build_ms left to the caller). Creates DIR/cells. Thread-safe for different
// stems.
StoredView writeLayerView(const std::string& dir, const std::string& stem, const impostor::DepthMeshImpostor& view);
// Loads a layer view (mesh, texture, ids, camera): checks each file's size and CRC-32 (when the index has them),
// then the counts and the image sizes against the entry. Errors name the file and view.record.
impostor::DepthMeshImpostor loadLayerView(const std::string& dir, const StoredView& view);

// Loads one impostor of a cell: mesh, texture (shared, RGBA8) and creation camera. Empty impostors have a mesh file
// too (with zero counts) and no texture. Throws farfield::Error (file, cell and technique, problem), also when a
// file's size or CRC-32 or its counts disagree with the index or the texture size with the camera.
impostor::DepthMeshImpostor loadImpostor(const std::string& dir, const CellEntry& entry,
                                         const std::string& technique);

}  // namespace farfield::store
