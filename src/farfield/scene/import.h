// Scene import: glTF 2.0, OBJ, PLY, AC3D and every other format assimp reads (textures included), plus .glb
// files written by Farfield. Farfield's world is Z up; files are read as Y up (the glTF convention and the common
// one for OBJ) and rotated to Z up unless ImportOptions::up_axis says 'z'.
#pragma once

#include <string>

#include "farfield/scene/scene.h"

namespace farfield::scene {

struct ImportOptions {
  char up_axis = 'y';         // up axis of the file: 'y' (rotated to Z up) or 'z' (kept)
  bool one_object_per_node = true;  // else one object per assimp mesh
};

// Throws farfield::Error naming the file for: a missing file, an unknown extension, truncated or corrupt data,
// non-finite vertex data, a texture file that cannot be read.
Scene importScene(const std::string& path, const ImportOptions& options = {});

// Opens SCENE arguments of the CLI: a file path as importScene, or "builtin:NAME" for a built-in scene
// (see builtinSceneNames()).
Scene loadScene(const std::string& spec, const ImportOptions& options = {});

}  // namespace farfield::scene
