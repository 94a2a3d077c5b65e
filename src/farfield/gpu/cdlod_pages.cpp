#include "farfield/gpu/cdlod_pages.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <string>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::gpu {
namespace {

int mipLevels(int size) {
  int levels = 1;
  while (size > 1) size /= 2, ++levels;
  return levels;
}

// The next mip level of an RGBA8 image: each texel the mean of the (up to) 2 x 2 texels it covers.
image::ColorImage halve(const image::ColorImage& src) {
  const int w = std::max(1, src.width() / 2), h = std::max(1, src.height() / 2);
  image::ColorImage out(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      int sum[4] = {0, 0, 0, 0}, n = 0;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const int sx = std::min(2 * x + dx, src.width() - 1), sy = std::min(2 * y + dy, src.height() - 1);
          const image::Rgba8 c = src.at(sx, sy);
          sum[0] += c.r, sum[1] += c.g, sum[2] += c.b, sum[3] += c.a, ++n;
        }
      out.at(x, y) = image::Rgba8{uint8_t(sum[0] / n), uint8_t(sum[1] / n), uint8_t(sum[2] / n), uint8_t(sum[3] / n)};
    }
  return out;
}

}  // namespace

CdlodPages::CdlodPages(int page_cells, int layers)
    : page_cells_(page_cells), layers_(layers), levels_(mipLevels(page_cells + 1)) {
  GLint max_size = 0, max_layers = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
  if (page_cells < 1 || page_cells + 1 > max_size)
    throw Error("CDLOD pages", "pages of " + std::to_string(page_cells) + " cells exceed this driver's textures");
  if (layers < 1 || layers > max_layers)
    throw Error("CDLOD pages", std::to_string(layers) + " pages: the driver holds 1.." + std::to_string(max_layers));
  const int n = page_cells + 1;
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &heights_);
  glTextureStorage3D(heights_, 1, GL_R32F, n, n, layers);
  glTextureParameteri(heights_, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(heights_, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &colours_);
  glTextureStorage3D(colours_, levels_, GL_RGBA8, n, n, layers);
  glTextureParameteri(colours_, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(colours_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(colours_, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(colours_, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

CdlodPages::~CdlodPages() {
  if (heights_) glDeleteTextures(1, &heights_);
  if (colours_) glDeleteTextures(1, &colours_);
}

std::vector<image::ColorImage> CdlodPages::colourMips(image::ColorImage level0) {
  std::vector<image::ColorImage> levels;
  levels.push_back(std::move(level0));
  while (levels.back().width() > 1 || levels.back().height() > 1) levels.push_back(halve(levels.back()));
  return levels;
}

void CdlodPages::upload(int layer, std::span<const float> heights, std::span<const image::ColorImage> colour) {
  const int n = page_cells_ + 1;
  if (layer < 0 || layer >= layers_) throw Error("CDLOD pages", "no layer " + std::to_string(layer));
  if (heights.size() != size_t(n) * size_t(n) || colour.size() != size_t(levels_) || colour[0].width() != n ||
      colour[0].height() != n)
    throw Error("CDLOD pages", "a page is " + std::to_string(n) + " x " + std::to_string(n) + " points with " +
                                   std::to_string(levels_) + " colour levels");
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glTextureSubImage3D(heights_, 0, 0, 0, layer, n, n, 1, GL_RED, GL_FLOAT, heights.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  for (int l = 0; l < levels_; ++l)
    glTextureSubImage3D(colours_, l, 0, 0, layer, colour[size_t(l)].width(), colour[size_t(l)].height(), 1, GL_RGBA,
                        GL_UNSIGNED_BYTE, colour[size_t(l)].data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
}

void CdlodPages::bind(int height_unit, int colour_unit) const {
  glBindTextureUnit(GLuint(height_unit), heights_);
  glBindTextureUnit(GLuint(colour_unit), colours_);
}

size_t CdlodPages::layerBytes() const {
  const size_t n = size_t(page_cells_) + 1;
  size_t bytes = n * n * sizeof(float);
  for (size_t w = n, h = n, l = 0; l < size_t(levels_); ++l, w = std::max<size_t>(1, w / 2), h = std::max<size_t>(1, h / 2))
    bytes += w * h * 4;
  return bytes;
}

}  // namespace farfield::gpu
