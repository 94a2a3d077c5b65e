// Textures of imported scenes: images decoded to RGBA8 with stb_image, the checkerboard placeholder of a texture
// that cannot be read (TextureFiles), and the counted warnings (ImportStats).
#include <stb_image.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "farfield/scene/import_readers.h"

namespace farfield::scene {

namespace {

// stb_image's RGBA8 pixels as an image; the pixels are freed.
TexturePtr takeStbPixels(unsigned char* pixels, int w, int h) {
  auto img = std::make_shared<image::ColorImage>(w, h);
  std::memcpy(img->data(), pixels, size_t(w) * size_t(h) * 4);
  stbi_image_free(pixels);
  return img;
}

}  // namespace

TexturePtr decodeImage(const unsigned char* bytes, size_t size, std::string* why) {
  if (size == 0 || size > size_t(std::numeric_limits<int>::max())) {
    *why = "empty or oversized image data";
    return nullptr;
  }
  int w = 0, h = 0, n = 0;
  unsigned char* pixels = stbi_load_from_memory(bytes, int(size), &w, &h, &n, 4);
  if (!pixels) {
    const char* reason = stbi_failure_reason();
    *why = std::string("cannot decode image (") + (reason ? reason : "unknown reason") + ")";
    return nullptr;
  }
  return takeStbPixels(pixels, w, h);
}

namespace {

namespace fs = std::filesystem;

// Reads an image file into RGBA8; null with `why` set on failure.
TexturePtr readImageFile(const fs::path& file, std::string* why) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    *why = "no file " + file.string();
    return nullptr;
  }
  int w = 0, h = 0, n = 0;
  unsigned char* pixels = stbi_load(file.string().c_str(), &w, &h, &n, 4);
  if (!pixels) {
    const char* reason = stbi_failure_reason();
    *why = file.string() + ": cannot decode image (" + (reason ? reason : "unknown reason") + ")";
    return nullptr;
  }
  return takeStbPixels(pixels, w, h);
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// Counted warnings and the placeholder

std::vector<std::string> ImportStats::warnings(size_t max_names) const {
  std::vector<std::string> out;
  if (!missing_textures.empty()) {
    const size_t n = missing_textures.size();
    std::string line = std::to_string(n) + (n == 1 ? " texture" : " textures") +
                       " missing or unreadable (checkerboard placeholders on " + std::to_string(placeholder_materials) +
                       (placeholder_materials == 1 ? " material" : " materials") + "): ";
    for (size_t i = 0; i < n && i < max_names; ++i) line += (i ? ", " : "") + missing_textures[i].name;
    if (n > max_names) line += ", ... and " + std::to_string(n - max_names) + " more";
    out.push_back(line);
    // The first reason says why in the words of the file system or the decoder.
    out.push_back("  (" + missing_textures[0].name + ": " + missing_textures[0].reason + ")");
  }
  if (skipped_faces > 0)
    out.push_back(std::to_string(skipped_faces) + " face(s) that are not triangles skipped (points, lines)");
  if (extra_ac3d_textures > 0)
    out.push_back(std::to_string(extra_ac3d_textures) +
                  " AC3D objects list several textures (multi-texturing extension): the first of each is used");
  return out;
}

void ImportStats::merge(const ImportStats& other) {
  for (const MissingTexture& m : other.missing_textures)
    if (std::none_of(missing_textures.begin(), missing_textures.end(),
                     [&](const MissingTexture& k) { return k.name == m.name; }))
      missing_textures.push_back(m);
  placeholder_materials += other.placeholder_materials;
  skipped_faces += other.skipped_faces;
  extra_ac3d_textures += other.extra_ac3d_textures;
}

std::shared_ptr<const image::ColorImage> checkerboardTexture() {
  static const std::shared_ptr<const image::ColorImage> board = [] {
    constexpr int kSize = 64, kSquare = 8;
    auto img = std::make_shared<image::ColorImage>(kSize, kSize);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        img->at(x, y) = ((x / kSquare + y / kSquare) % 2 == 0) ? image::Rgba8(255, 0, 255, 255)
                                                                : image::Rgba8(24, 24, 24, 255);
    return img;
  }();
  return board;
}

bool TextureFiles::isPlaceholder(const std::shared_ptr<const image::ColorImage>& texture) {
  return texture && texture == checkerboardTexture();
}

std::shared_ptr<const image::ColorImage> TextureFiles::placeholder(const std::string& name, const std::string& reason) {
  if (std::none_of(stats_.missing_textures.begin(), stats_.missing_textures.end(),
                   [&](const ImportStats::MissingTexture& m) { return m.name == name; }))
    stats_.missing_textures.push_back({name, reason});
  ++stats_.placeholder_materials;
  return checkerboardTexture();
}

std::shared_ptr<const image::ColorImage> TextureFiles::load(const std::string& name, const fs::path& file) {
  const std::string key = file.lexically_normal().string();
  if (auto it = files_.find(key); it != files_.end()) {
    if (isPlaceholder(it->second)) ++stats_.placeholder_materials;
    return it->second;
  }
  std::string why;
  TexturePtr img = readImageFile(file, &why);
  if (!img) img = placeholder(name, why);
  return files_[key] = img;
}

std::shared_ptr<const image::ColorImage> TextureFiles::decode(const std::string& name, const unsigned char* bytes,
                                                              size_t size) {
  std::string why;
  TexturePtr img = decodeImage(bytes, size, &why);
  return img ? img : placeholder(name, why);
}

}  // namespace farfield::scene
