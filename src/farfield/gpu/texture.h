// 2D textures: RGBA8 (with mipmaps), R32F, depth 32F, R32UI.
// Texture coordinates: an image's row 0 (its top) is uploaded first and lies at v = 0, so uv (0, 0) is the image's
// top-left corner and v grows downwards (the glTF convention; OBJ-style uvs with v up need v' = 1 - v).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "farfield/image/image.h"

namespace farfield::gpu {

enum class TextureFormat { Rgba8, R32F, Depth32F, R32UI };

class Texture {
 public:
  Texture() = default;
  Texture(int width, int height, TextureFormat format, bool mipmaps = false);
  // RGBA8 texture with mipmaps and trilinear, anisotropic filtering, repeat wrapping.
  static Texture fromImage(const image::ColorImage& image, bool mipmaps = true);
  ~Texture();
  Texture(Texture&& other) noexcept;
  Texture& operator=(Texture&& other) noexcept;
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;

  // R32UI texture of object ids (nearest, clamped): per-texel ids of an impostor (GpuMaterial::id_texture).
  static Texture fromIds(const image::IdImage& ids);
  void upload(const image::ColorImage& image);  // RGBA8 textures; regenerates mipmaps if it has them
  void setClampToEdge();
  void bind(int unit) const;
  uint32_t handle() const { return handle_; }
  int width() const { return width_; }
  int height() const { return height_; }
  TextureFormat format() const { return format_; }
  size_t byteSize() const;

 private:
  uint32_t handle_ = 0;
  int width_ = 0;
  int height_ = 0;
  TextureFormat format_ = TextureFormat::Rgba8;
  bool mipmaps_ = false;
};

// A GL_TEXTURE_2D_ARRAY of equally sized colour images, one layer each, sampled as Texture::fromImage's textures are
// (mipmaps, trilinear filtering, the same anisotropy, repeat wrapping). Returns the GL name, which the caller deletes.
// Throws farfield::Error for no images, an empty one or mixed sizes.
uint32_t makeColorTextureArray(std::span<const image::ColorImage* const> layers);
// The GPU bytes of such an array (all mip levels).
size_t colorTextureArrayBytes(int width, int height, int layers);

}  // namespace farfield::gpu
