// Scene import. glTF (.glb, .gltf) is read with tinygltf so that the per-node "farfield" extras written by
// exportGlb (object name, footprint, parent) come back; every other format goes through assimp. Both paths
// flatten the node hierarchy into one Object per node with its world transform, decode textures with stb_image
// into RGBA8, and rotate Y-up files to Farfield's Z up. A texture that cannot be read is a counted warning with a
// checkerboard in its place (TextureFiles), never a failed import: real models often lose a texture or two.
// Here: the format dispatch (importScene, loadScene); the readers are in import_gltf.cpp and import_assimp.cpp,
// the textures and counted warnings in import_textures.cpp.
#include "farfield/scene/import.h"

#include <assimp/Importer.hpp>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/import_readers.h"
#include "farfield/scene/off_check.h"

namespace farfield::scene {

namespace {

namespace fs = std::filesystem;

// Y-up file coordinates (x, y, z) become Z-up world coordinates (x, -z, y): a +90 degree turn about x, so
// handedness and winding are kept.
const Mat4 kYUpToZUp(Vec4(1, 0, 0, 0), Vec4(0, 0, 1, 0), Vec4(0, -1, 0, 0), Vec4(0, 0, 0, 1));

std::string acceptedFormats(const Assimp::Importer& importer) {
  std::string list;
  importer.GetExtensionList(list);  // "*.3ds;*.obj;..."
  std::string out = ".glb, .gltf";
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ';')) {
    if (item.rfind("*", 0) == 0) item.erase(0, 1);
    if (item.empty() || item == ".glb" || item == ".gltf") continue;
    out += ", " + item;
  }
  return out;
}

}  // namespace

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

Mat4 rootTransform(const ImportOptions& options) { return options.up_axis == 'z' ? Mat4(1.0f) : kYUpToZUp; }

void checkEmpty(const Scene& scene, const std::string& path) {
  if (scene.triangleCount() == 0) throw Error(path, "empty scene: no triangles");
}

Scene importScene(const std::string& path, const ImportOptions& options, ImportStats* stats) {
  if (options.up_axis != 'y' && options.up_axis != 'z')
    throw Error(path, std::string("up axis must be 'y' or 'z', not '") + options.up_axis + "'");
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path, "file not found");
  if (!fs::is_regular_file(path, ec)) throw Error(path, "not a regular file");
  const std::string ext = lowerExtension(path);
  ImportStats local;
  ImportStats& st = stats ? *stats : local;
  Scene scene;
  if (ext == ".glb" || ext == ".gltf") {
    scene = importGltf(path, ext == ".glb", options, st);
  } else {
    Assimp::Importer probe;
    if (ext.empty() || !probe.IsExtensionSupported(ext))
      throw Error(path, "unknown scene format '" + ext + "' (accepted: " + acceptedFormats(probe) + ")");
    if (ext == ".off") checkOffFile(path);  // assimp's OFF reader crashes on some damaged files
    scene = importAssimp(path, options, st);
  }
  if (!stats)
    for (const std::string& w : local.warnings()) FF_WARN(path << ": " << w);
  return scene;
}

Scene loadScene(const std::string& spec, const ImportOptions& options, ImportStats* stats) {
  constexpr const char* kBuiltin = "builtin:";
  if (spec.rfind(kBuiltin, 0) == 0) return builtinScene(spec.substr(std::strlen(kBuiltin)));
  return importScene(spec, options, stats);
}

}  // namespace farfield::scene
