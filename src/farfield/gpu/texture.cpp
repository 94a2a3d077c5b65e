#include "farfield/gpu/texture.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <utility>

#include "farfield/core/error.h"

namespace farfield::gpu {
namespace {

GLenum internalFormat(TextureFormat format) {
  switch (format) {
    case TextureFormat::Rgba8: return GL_RGBA8;
    case TextureFormat::R32F: return GL_R32F;
    case TextureFormat::Depth32F: return GL_DEPTH_COMPONENT32F;
    case TextureFormat::R32UI: return GL_R32UI;
  }
  return GL_RGBA8;
}

int levelCount(int width, int height) {
  int levels = 1;
  for (int size = std::max(width, height); size > 1; size /= 2) ++levels;
  return levels;
}

// Anisotropy for mipmapped colour textures: FF_ANISOTROPY=N in the environment (1 = off) sets it; otherwise the
// largest the driver offers (GL 4.6 or the EXT/ARB extension), capped at 8, on hardware, and none on software
// rasterisers: llvmpipe's anisotropic filter is so slow that a single textured ground quad seen at grazing angles
// took 2.8 s of a 640x360 frame, hiding every other cost the benchmarks measure. 0 when unsupported.
float maxAnisotropy() {
  static const float value = [] {
    if (epoxy_gl_version() < 46 && !epoxy_has_gl_extension("GL_EXT_texture_filter_anisotropic") &&
        !epoxy_has_gl_extension("GL_ARB_texture_filter_anisotropic"))
      return 0.0f;
    GLfloat max = 0.0f;
    glGetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY, &max);
    float wanted = 8.0f;
    if (const char* env = std::getenv("FF_ANISOTROPY")) {
      wanted = float(std::atof(env));
    } else {
      const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
      const std::string name = renderer ? renderer : "";
      if (name.find("llvmpipe") != std::string::npos || name.find("softpipe") != std::string::npos) wanted = 1.0f;
    }
    return std::clamp(std::min(max, wanted), 0.0f, 16.0f);
  }();
  return value;
}

}  // namespace

Texture::Texture(int width, int height, TextureFormat format, bool mipmaps) : format_(format) {
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (width <= 0 || height <= 0 || width > max_size || height > max_size)
    throw Error("texture", "size " + std::to_string(width) + "x" + std::to_string(height) + " outside 1.." +
                               std::to_string(max_size));
  // Mipmaps only make sense for filtered colour; integer and depth textures are read texel by texel.
  mipmaps_ = mipmaps && (format == TextureFormat::Rgba8 || format == TextureFormat::R32F);
  width_ = width;
  height_ = height;
  glCreateTextures(GL_TEXTURE_2D, 1, &handle_);
  glTextureStorage2D(handle_, mipmaps_ ? levelCount(width, height) : 1, internalFormat(format), width, height);
  const bool filtered = format == TextureFormat::Rgba8 || format == TextureFormat::R32F;
  glTextureParameteri(handle_, GL_TEXTURE_MIN_FILTER,
                      filtered ? (mipmaps_ ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR) : GL_NEAREST);
  glTextureParameteri(handle_, GL_TEXTURE_MAG_FILTER, filtered ? GL_LINEAR : GL_NEAREST);
  if (mipmaps_ && maxAnisotropy() > 1.0f) glTextureParameterf(handle_, GL_TEXTURE_MAX_ANISOTROPY, maxAnisotropy());
  if (!filtered) setClampToEdge();
}

Texture Texture::fromImage(const image::ColorImage& image, bool mipmaps) {
  if (image.empty()) throw Error("texture", "image is empty");
  Texture texture(image.width(), image.height(), TextureFormat::Rgba8, mipmaps);
  glTextureParameteri(texture.handle_, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(texture.handle_, GL_TEXTURE_WRAP_T, GL_REPEAT);
  texture.upload(image);
  return texture;
}

Texture Texture::fromIds(const image::IdImage& ids) {
  if (ids.empty()) throw Error("texture", "id image is empty");
  Texture texture(ids.width(), ids.height(), TextureFormat::R32UI, false);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(texture.handle_, 0, 0, 0, ids.width(), ids.height(), GL_RED_INTEGER, GL_UNSIGNED_INT,
                      ids.pixels().data());
  return texture;
}

Texture::~Texture() {
  if (handle_) glDeleteTextures(1, &handle_);
}

Texture::Texture(Texture&& other) noexcept
    : handle_(std::exchange(other.handle_, 0)),
      width_(other.width_),
      height_(other.height_),
      format_(other.format_),
      mipmaps_(other.mipmaps_) {}

Texture& Texture::operator=(Texture&& other) noexcept {
  if (this != &other) {
    if (handle_) glDeleteTextures(1, &handle_);
    handle_ = std::exchange(other.handle_, 0);
    width_ = other.width_;
    height_ = other.height_;
    format_ = other.format_;
    mipmaps_ = other.mipmaps_;
  }
  return *this;
}

void Texture::upload(const image::ColorImage& image) {
  FF_CHECK_MSG(handle_ && format_ == TextureFormat::Rgba8, "upload() needs an RGBA8 texture");
  FF_CHECK_MSG(image.width() == width_ && image.height() == height_, "upload() needs an image of the texture's size");
  // Rows go up in image order: row 0 (the image's top) is texel row 0, at v = 0 (see texture.h).
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  glTextureSubImage2D(handle_, 0, 0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, image.data());
  if (mipmaps_) glGenerateTextureMipmap(handle_);
}

void Texture::setClampToEdge() {
  glTextureParameteri(handle_, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(handle_, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

void Texture::bind(int unit) const { glBindTextureUnit(GLuint(unit), handle_); }

size_t Texture::byteSize() const {
  if (!handle_) return 0;
  const size_t base = size_t(width_) * size_t(height_) * 4;  // every format here has 4 bytes per texel
  return mipmaps_ ? base * 4 / 3 : base;
}

uint32_t makeColorTextureArray(std::span<const image::ColorImage* const> layers) {
  if (layers.empty()) throw Error("texture array", "no images");
  const int width = layers[0]->width(), height = layers[0]->height();
  for (const image::ColorImage* image : layers)
    if (image->empty() || image->width() != width || image->height() != height)
      throw Error("texture array", "images of " + std::to_string(width) + "x" + std::to_string(height) +
                                       " and " + std::to_string(image->width()) + "x" +
                                       std::to_string(image->height()) + " mixed");
  GLint max_size = 0, max_layers = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
  if (width > max_size || height > max_size || int(layers.size()) > max_layers)
    throw Error("texture array", std::to_string(layers.size()) + " layers of " + std::to_string(width) + "x" +
                                     std::to_string(height) + " exceed the driver's limits");
  GLuint handle = 0;
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &handle);
  glTextureStorage3D(handle, levelCount(width, height), GL_RGBA8, width, height, GLsizei(layers.size()));
  glTextureParameteri(handle, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(handle, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(handle, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(handle, GL_TEXTURE_WRAP_T, GL_REPEAT);
  if (maxAnisotropy() > 1.0f) glTextureParameterf(handle, GL_TEXTURE_MAX_ANISOTROPY, maxAnisotropy());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  for (size_t i = 0; i < layers.size(); ++i)
    glTextureSubImage3D(handle, 0, 0, 0, GLint(i), width, height, 1, GL_RGBA, GL_UNSIGNED_BYTE, layers[i]->data());
  glGenerateTextureMipmap(handle);
  return handle;
}

size_t colorTextureArrayBytes(int width, int height, int layers) {
  size_t bytes = 0;
  for (int w = width, h = height;; w = std::max(w / 2, 1), h = std::max(h / 2, 1)) {
    bytes += size_t(w) * size_t(h) * 4 * size_t(layers);
    if (w == 1 && h == 1) break;
  }
  return bytes;
}

}  // namespace farfield::gpu
