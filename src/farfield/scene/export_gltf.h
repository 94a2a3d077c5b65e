// Scene export to binary glTF (.glb): meshes, materials with embedded PNG textures, one node per object
// (footprints go into the node's extras). Farfield's Z-up world is written as glTF's Y up.
#pragma once

#include <string>

#include "farfield/scene/scene.h"

namespace farfield::scene {

// Throws farfield::Error naming the file when it cannot be written.
void exportGlb(const Scene& scene, const std::string& path);

}  // namespace farfield::scene
