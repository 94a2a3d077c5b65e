// What the importers share: the format dispatch (import.cpp), the glTF reader (import_gltf.cpp), the reader of
// every other format (import_assimp.cpp) and the textures (import_textures.cpp). Internal to the scene module.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "farfield/image/image.h"
#include "farfield/scene/import.h"
#include "farfield/scene/scene.h"

namespace farfield::scene {

using TexturePtr = std::shared_ptr<const image::ColorImage>;

// The file name's extension in lower case, with its dot (".glb"); empty when it has none.
std::string lowerExtension(const std::string& path);
// The transform of a file's root nodes: Y up turned to Farfield's Z up, unless options.up_axis is 'z'.
Mat4 rootTransform(const ImportOptions& options);
// Throws farfield::Error naming `path` when the scene has no triangles.
void checkEmpty(const Scene& scene, const std::string& path);

// Decodes PNG, JPEG, TGA, BMP, ... bytes into RGBA8; null with `why` set on failure.
TexturePtr decodeImage(const unsigned char* bytes, size_t size, std::string* why);

// The readers: glTF (binary .glb or text .gltf) through tinygltf, every other format through assimp.
Scene importGltf(const std::string& path, bool binary, const ImportOptions& options, ImportStats& stats);
Scene importAssimp(const std::string& path, const ImportOptions& options, ImportStats& stats);

}  // namespace farfield::scene
