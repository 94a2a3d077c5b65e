// Scene import: glTF 2.0, OBJ, PLY, AC3D and every other format assimp reads (textures included), plus .glb
// files written by Farfield. Farfield's world is Z up; files are read as Y up (the glTF convention and the common
// one for OBJ) and rotated to Z up unless ImportOptions::up_axis says 'z'.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "farfield/image/image.h"
#include "farfield/scene/scene.h"

namespace farfield::scene {

struct ImportOptions {
  char up_axis = 'y';         // up axis of the file: 'y' (rotated to Z up) or 'z' (kept)
  bool one_object_per_node = true;  // else one object per assimp mesh
};

// Recoverable defects of real data that an import went on without (DESIGN.md: counted warnings with a visible
// placeholder). Shared by every importer of the scene and geodata modules.
struct ImportStats {
  struct MissingTexture {
    std::string name;    // as the model names it ("wall.png", "ERROR", "embedded texture 0")
    std::string reason;  // "no file /data/wall.png", "cannot decode image (...)"
  };
  // Texture images that are missing or cannot be decoded, each once, in the order met. Every material that names
  // one gets checkerboardTexture() instead.
  std::vector<MissingTexture> missing_textures;
  size_t placeholder_materials = 0;  // materials (or surfaces) that got the checkerboard
  size_t skipped_faces = 0;          // faces that are not triangles (points, lines) dropped
  // AC3D objects listing more than one texture (TORCS's multi-texturing: base, tiled, skids, shad): the first,
  // the base texture, is the one used.
  size_t extra_ac3d_textures = 0;

  // One line per kind of defect, for a user: "3 textures missing (checkerboard placeholders): a.png, b.png,
  // c.png" naming at most `max_names` files ("... and N more"). Empty when the import was clean.
  std::vector<std::string> warnings(size_t max_names = 5) const;
  // Adds `other`'s counts and missing files (a file already listed is not repeated).
  void merge(const ImportStats& other);
};

// The placeholder of a texture that cannot be read: 64 x 64 texels in 8 x 8 squares of magenta and near black,
// opaque, the top-left square magenta. One shared image.
std::shared_ptr<const image::ColorImage> checkerboardTexture();

// Texture files for importers: each file decoded once (PNG, JPEG, TGA, BMP, ... to RGBA8, row 0 at the top). A
// file that is missing or cannot be decoded gives checkerboardTexture() and is recorded, once, in `stats`.
class TextureFiles {
 public:
  explicit TextureFiles(ImportStats& stats) : stats_(stats) {}
  // `name` is how the model names the texture (for the warning), `file` where it is read. Never null; counts a
  // placeholder material for each call that returns the checkerboard.
  std::shared_ptr<const image::ColorImage> load(const std::string& name, const std::filesystem::path& file);
  // Decodes image bytes held in the model (embedded textures); the checkerboard, recorded under `name`, on failure.
  std::shared_ptr<const image::ColorImage> decode(const std::string& name, const unsigned char* bytes, size_t size);
  // Records `name` as missing for `reason` (once per name) and returns the checkerboard.
  std::shared_ptr<const image::ColorImage> placeholder(const std::string& name, const std::string& reason);
  // True when `texture` is the placeholder.
  static bool isPlaceholder(const std::shared_ptr<const image::ColorImage>& texture);

 private:
  ImportStats& stats_;
  std::map<std::string, std::shared_ptr<const image::ColorImage>> files_;  // by path read
};

// Throws farfield::Error naming the file for: a missing file, an unknown extension, truncated or corrupt data,
// non-finite vertex data. A texture that is missing or cannot be decoded is no error: its materials get
// checkerboardTexture() and `stats` counts it (when `stats` is null, the warnings go to the log instead).
Scene importScene(const std::string& path, const ImportOptions& options = {}, ImportStats* stats = nullptr);

// Opens SCENE arguments of the CLI: a file path as importScene, or "builtin:NAME" for a built-in scene
// (see builtinSceneNames()).
Scene loadScene(const std::string& spec, const ImportOptions& options = {}, ImportStats* stats = nullptr);

}  // namespace farfield::scene
