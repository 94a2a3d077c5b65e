// The placement database: what automatic impostor placement (Jeschke et al. 2005, sections 3-5) produced for a
// scene, on disk: the problem view space (a BSP of the view box and its CPVs), the times of every CPV before and after
// placement with the impostors drawn there, and the layered impostors themselves (object clusters, each valid in a
// shaft view cell). Written atomically and read strictly like the impostor store (impostor_store.h, version 3 rules).
//
// Layout of a placement directory DIR (generation G as six or more digits):
//   DIR/placement.json                     the index (below); the only file replaced in place (atomically)
//   DIR/impostors/gG.iNNNNNN.LL.png        impostor NNNNNN's layer LL (far to near): colour, RGBA8 (alpha 0 = empty)
//   DIR/impostors/gG.iNNNNNN.LL.ids.png    its object ids (each id's 4 bytes, little-endian, in R, G, B, A); only
//                                          when the impostor's options have id_textures
//
// placement.json (dump(1) of the JSON below with keys sorted, and a newline):
//   {"format": "farfield-placement", "version": 1, "generation": 3, "checksum": 1234567,
//    "scene": "city.glb", "scene_objects": 1234,        // object ids are 1..scene_objects
//    "options": {...}, "summary": {...},                // the caller's (e.g. the place command's), opaque, saved whole
//    "view_space": {"lo": [x,y,z], "hi": [x,y,z]},
//    "nodes": [{"box": BOX, "children": [1, 2], "cpv_first": 0, "cpv_count": 12,
//               "visible": null or [object ids seen from the region, ascending]}, ...],   // node 0: the whole box
//    "cpvs": [{"region": BOX, "vdi": {"face": 0, "u0": -1, "u1": 0, "v0": -1, "v1": 0}, "t_enc": 21.5,
//              "t_after": 15.9, "impostors": [3, 7]}, ...],                                // impostor ids, ascending
//    "impostors": [{"id": 3, "node": 17, "objects": [4, 5, 9], "box": BOX,
//                   "shaft": {"apex": [x,y,z], "axis": [x,y,z], "apex_angle": rad, "min_distance": m},
//                   "bound": {"pixels": 1, "width": 640, "height": 360, "fov_y": rad},
//                   "options": {"texel_pixels": 1, "max_texture_size": 1024, "max_layers": 64, "layer_count": 0,
//                               "bound_cracks": false, "id_textures": true, "solid_slices": true,
//                               "dilate_texels": 2},
//                   "layers": [{"texture": "impostors/g000003.i000003.00.png", "texture_crc32": 5,
//                               "texture_bytes": 812, "ids": "impostors/g000003.i000003.00.ids.png", "ids_crc32": 6,
//                               "ids_bytes": 300, "data_texels": 120, "render_ms": 0.4}, ...],   // "ids": "" when none
//                   "bytes": 123456, "capture_ms": 3.5}, ...]}
//   with BOX = {"lo": [x,y,z], "hi": [x,y,z]}. Every object has exactly these members (an unknown or a missing one is
//   an error). Numbers are JSON numbers written with enough digits to read back bit for bit.
//
// What is not stored: the layered plans. An impostor's record holds the plan's inputs (cluster box, shaft, error
// bound, options) and loadPlacedImpostor re-derives the plan with impostor::planLayered (pure arithmetic,
// deterministic); the layer count and every image size must agree with it.
//
// Rules the reader checks (readPlacementIndex; farfield::Error "DIR/placement.json: ELEMENT: WHAT", ELEMENT e.g.
// "cpvs[3].impostors[1]"):
//   - the file is exactly the writer's text and "checksum" is the CRC-32 of its compact dump without "checksum"
//     (store::indexChecksum), so any truncation or changed byte is an error;
//   - impostor ids ascending without repeats; object ids in 1..scene_objects, ascending without repeats; a CPV names
//     only impostors that exist, ascending without repeats; every impostor's plan inputs are accepted by planLayered
//     and give as many layers as the record lists; "ids" present exactly when options.id_textures;
//   - nodes: at least one; children both -1 (a leaf) or both later nodes, each node the child of exactly one node
//     (node 0 of none), children's boxes inside their parent's; node 0's box is "view_space"; the CPVs of a node are
//     [cpv_first, cpv_first + cpv_count), node 0 holds all of them and the two children split their parent's range
//     in order (first the lower child's); a CPV's region lies in the box of the leaf holding it;
//   - regions and boxes not empty, VDIs on faces 0..5 with -1 <= u0 < u1 <= 1 (v likewise), times finite and >= 0.
//
// Writes (SQLite's rule: a write is atomic or did not happen): each data file goes to NAME.tmp, is fsync'ed and
// renamed over NAME (store::writeFileAtomic: store::setFileOperationHook sees its create, write, fsync and rename, and
// the sync of DIR after the index's rename; the directory syncs before it and the removals are not reported, the
// hook's machinery being private to store_integrity.cpp); writePlacementIndex syncs
// DIR/impostors, then replaces DIR/placement.json atomically, then removes the files under DIR/impostors with
// placement names (gG.* and their .tmp) that the new index does not name, and DIR/placement.json.tmp. A rewrite uses
// generation nextPlacementGeneration(DIR), so the old index and its files stay untouched until the new index is in
// place: a write killed at any point leaves the previous database readable and unchanged.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/bounds.h"
#include "farfield/core/enclosing_frustum.h"
#include "farfield/core/error_bound.h"
#include "farfield/core/math.h"
#include "farfield/core/shaft.h"
#include "farfield/impostor/layered.h"
#include "farfield/store/impostor_store.h"

namespace farfield::store {

// Version 2: each layer holds only the rectangle of its captured image that has data ("crop"). Version 3: texels
// sized per layer (impostor::planLayered), so the plans of version 2 inputs differ.
inline constexpr int kPlacementVersion = 3;
inline constexpr char kPlacementFormat[] = "farfield-placement";
inline constexpr char kPlacementIndexFile[] = "placement.json";

struct StoredImpostorLayer {
  std::string texture;  // relative to the database directory
  FileCheck texture_check;
  std::string ids;      // "" without ids
  FileCheck ids_check;
  size_t data_texels = 0;
  double render_ms = 0.0;
  // The part of the captured layer image that is stored (impostor::cropLayered); the whole image when not cropped.
  impostor::LayerCrop crop;
};

// A layered impostor of an object cluster (impostor/layered.h), valid in a shaft view cell.
struct StoredPlacedImpostor {
  uint32_t id = 0;
  uint32_t node = 0;               // the cluster's object-hierarchy node (placement/object_hierarchy.h)
  std::vector<uint32_t> objects;   // object ids, ascending
  // The inputs of its plan (impostor::planLayered re-derives the plan from them).
  Box3 box;
  Shaft shaft;
  ErrorBound bound;
  impostor::LayeredOptions options;
  std::vector<StoredImpostorLayer> layers;  // as the plan's layers (far to near)
  uint64_t bytes = 0;              // its memory as placement counted it (LayeredPlan::bytes() when written here)
  double capture_ms = 0.0;
  // Where it is in the index ("impostor 12"), set by the writer and the reader, not stored: errors name it.
  std::string record;
};

// A conservative problem view (placement/view_space.h): a region of the view box and a view-direction interval.
struct StoredCpv {
  Box3 region;
  Vdi vdi;
  double t_enc = 0.0;    // estimated rendering time before placement (the unit of the placement's t_max)
  double t_after = 0.0;  // with its impostors drawn
  std::vector<uint32_t> impostors;  // ids of the impostors drawn in this CPV, ascending
};

struct StoredViewSpaceNode {
  Box3 box;
  int children[2] = {-1, -1};  // node indices; -1 for a leaf
  uint32_t cpv_first = 0;      // the CPVs of the subtree: [cpv_first, cpv_first + cpv_count)
  uint32_t cpv_count = 0;
  // The objects seen from the region (from-region visibility), when placement computed them: the runtime draws only
  // these there (the placement's times assumed it). Ascending ids; has_visible false: not computed (draw what the
  // frustum holds).
  bool has_visible = false;
  std::vector<uint32_t> visible;
};

struct PlacementIndex {
  int version = kPlacementVersion;
  uint64_t generation = 0;  // >= 1: the number in the data file names
  std::string scene;        // informative
  size_t scene_objects = 0;
  nlohmann::json options = nlohmann::json::object();  // saved whole, opaque to the store
  nlohmann::json summary = nlohmann::json::object();  // saved whole, opaque to the store
  Box3 view_space;
  std::vector<StoredViewSpaceNode> nodes;  // nodes[0] is the whole view space
  std::vector<StoredCpv> cpvs;
  std::vector<StoredPlacedImpostor> impostors;  // ascending ids

  // The impostor with this id, or null.
  const StoredPlacedImpostor* find(uint32_t id) const;
};

// The generation a (re)write of DIR uses: one more than the current index's and than any found in the names of files
// in DIR/impostors (a killed write may have left some); 1 for a new database.
uint64_t nextPlacementGeneration(const std::string& dir);
// impostors/gG.iNNNNNN.LL.png (and .ids.png)
std::string placedLayerFileName(uint64_t generation, uint32_t id, size_t layer, bool ids);

// Writes the layer images of `impostor` (colour, and ids when options.id_textures) under DIR/impostors with the names
// of `generation`, atomically (the directory is synced by writePlacementIndex), and returns its record (bytes =
// impostor.plan.bytes(), capture_ms and the layers' data_texels and render_ms from the impostor). Throws
// farfield::Error naming the record when the plan re-derived from (box, shaft, bound, options) disagrees with the
// impostor's images (layer count, sizes), when an ids image is missing or present against options.id_textures, or
// when objects are empty or hold 0 or a repeat (any order: the record holds them ascending). Creates DIR/impostors.
// Thread-safe for different ids.
StoredPlacedImpostor writePlacedImpostor(const std::string& dir, uint64_t generation, uint32_t id, uint32_t node,
                                         const std::vector<uint32_t>& objects,
                                         const impostor::LayeredImpostor& impostor, const Box3& box,
                                         const Shaft& shaft, const ErrorBound& bound,
                                         const impostor::LayeredOptions& options);

// The index as JSON (without "checksum") and back. placementFromJson checks every rule above but the checksum and the
// text form, throwing farfield::Error "SOURCE: ELEMENT: WHAT".
nlohmann::json placementToJson(const PlacementIndex& index);
PlacementIndex placementFromJson(const nlohmann::json& json, const std::string& source);
// The exact text writePlacementIndex writes: "checksum" set, dump(1), a newline.
std::string placementFileText(nlohmann::json index_json);

// Commits a database: checks the index against the rules above (a bad index is refused before anything is written:
// farfield::Error naming the element), sets index.version and the records' names, makes DIR/impostors durable,
// replaces DIR/placement.json atomically (the last step that matters), then removes stale files (above). Creates DIR.
void writePlacementIndex(const std::string& dir, PlacementIndex& index);
// Reads and validates DIR/placement.json (checksum, text form, every rule above). Data files are checked when loaded.
PlacementIndex readPlacementIndex(const std::string& dir);

// Loads an impostor: re-derives its plan, reads every layer file, checking its size and CRC-32 against the record
// before decoding it, and each image's size against the plan. Errors name the file and the record ("impostor 12
// layer 3 texture: truncated: 100 of 812 bytes").
impostor::LayeredImpostor loadPlacedImpostor(const std::string& dir, const StoredPlacedImpostor& impostor);

// The impostor's layered plan as the runtime draws it: re-derived from (box, shaft, bound, options) and cut to its
// layers' crops. Throws farfield::Error naming the record when these disagree (readPlacementIndex checked them).
impostor::LayeredPlan storedLayeredPlan(const StoredPlacedImpostor& impostor);

// The leaf of the BSP holding the eye (the lower child when on both), or none outside the view space.
std::optional<uint32_t> lookupLeaf(const PlacementIndex& index, const Vec3& eye);

// The CPV holding the view (eye, direction): walks the BSP from node 0 to the leaf holding the eye (the lower child
// when the eye is on both) and returns the first of the leaf's CPVs whose region contains the eye and whose VDI holds
// `dir` (non-zero; need not be unit); none outside the view space or when no CPV there holds the view.
std::optional<uint32_t> lookupCpv(const PlacementIndex& index, const Vec3& eye, const Vec3& dir);
// The same within a leaf already found by lookupLeaf (a caller that needs both walks the BSP once).
std::optional<uint32_t> cpvInLeaf(const PlacementIndex& index, uint32_t leaf, const Vec3& eye, const Vec3& dir);

// Bytes on disk of DIR/placement.json and of every file the index names (for reports). Throws farfield::Error naming
// a file that is missing.
uint64_t placementBytes(const std::string& dir, const PlacementIndex& index);

}  // namespace farfield::store
