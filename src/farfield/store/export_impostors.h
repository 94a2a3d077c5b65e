// Baked impostors as glTF 2.0: the representations an impostor database holds, written next to the scene's objects
// in one .glb so that any glTF viewer shows what Farfield draws far away, where it stands, and for which viewpoints.
//
// Under one root group node ("impostors", its matrix the Z-up to Y-up turn of scene::worldToGltf(), so the
// impostors' world-space vertices land on the scene's objects) come one group node per view region, each with the
// impostors drawn there:
//   - a pipeline store (`farfield bake`, DIR/index.json): per street cell ("cell E", E the half-edge) the single-mesh
//     impostor's views and each MMI layer's views, and in stores of the Sillion layout each technique's mesh, as
//     textured triangle meshes (the textured depth or grid mesh: world-space triangles, the captured colour as
//     texture);
//   - a placement database (`farfield place`, DIR/placement.json): per conservative problem view ("cpv K") that draws
//     impostors, one node per layered impostor drawn there, a mesh of one alpha-tested textured quad per layer (far to
//     near, a primitive each). An impostor drawn in several CPVs is one glTF mesh shared by their nodes (its texels
//     are written once); its first node's extras describe it, the others name it.
// Impostor materials are unlit (KHR_materials_unlit: the captures hold lit colour), double-sided, alphaMode MASK
// with cutoff 0.5 (the renderer's alpha test: alpha 0 is background) and sample their texture clamped to its edge.
// Every node's extras hold {"farfield_impostor": {...}}: what it is ("kind": "street cell", "textured depth mesh",
// "layered impostor", ...), the objects it stands for, the creation camera or the layered plan's error angle, and
// the view region's extent (a cell's half-edge and validity regions; a CPV's box, view directions and estimated
// times). The key differs from the scene objects' "farfield" so importScene keeps reading the scene's part.
#pragma once

#include <cstddef>
#include <string>

#include "farfield/scene/export_gltf.h"
#include "farfield/scene/scene.h"

namespace farfield::store {

struct ImpostorExportStats {
  std::string database;        // "pipeline store" or "placement"
  size_t regions = 0;          // view-region group nodes written
  size_t impostors = 0;        // impostors written (cell views, techniques' meshes, layered impostors)
  size_t meshes = 0;           // glTF meshes of impostors
  size_t layers = 0;           // quads of layered impostors
  size_t triangles = 0;        // impostor triangles written (a shared mesh counted once)
  size_t empty = 0;            // views without data (no mesh written)
};

// Adds the impostors of the database in `database_dir` (either kind, found by its index file) to `builder`, as
// above. `scene_objects` is the object count of the scene exported beside them: a database baked for another scene
// is refused. Shows progress per cell or impostor on stderr (core/progress.h). Every file is read through the
// store's checked readers. Throws farfield::Error naming the directory when it holds no database, the scene does
// not match, or a file is damaged (the reader's message: file and record).
ImpostorExportStats addImpostors(scene::GltfBuilder& builder, const std::string& database_dir, size_t scene_objects);

// The scene (scene::GltfBuilder::addObjects) and, when `database_dir` is not empty, its impostors, as one .glb at
// `glb_path`. Returns the impostors' counts (zero without a database) and sets *bytes to the file's size when given.
ImpostorExportStats exportSceneAndImpostors(const scene::Scene& scene, const std::string& database_dir,
                                            const std::string& glb_path, size_t* bytes = nullptr);

}  // namespace farfield::store
