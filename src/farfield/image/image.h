// Image<T>: a 2D array of pixels, row 0 at the top, stored row-major without padding.
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/core/check.h"
#include "farfield/core/math.h"

namespace farfield::image {

using Rgba8 = glm::u8vec4;

template <class T>
class Image {
 public:
  Image() = default;
  Image(int width, int height, const T& fill = T{}) : width_(width), height_(height) {
    FF_CHECK(width >= 0 && height >= 0);
    pixels_.assign(size_t(width) * size_t(height), fill);
  }

  int width() const { return width_; }
  int height() const { return height_; }
  size_t pixelCount() const { return pixels_.size(); }
  bool empty() const { return pixels_.empty(); }

  T& at(int x, int y) {
    FF_CHECK(x >= 0 && y >= 0 && x < width_ && y < height_);
    return pixels_[size_t(y) * size_t(width_) + size_t(x)];
  }
  const T& at(int x, int y) const {
    FF_CHECK(x >= 0 && y >= 0 && x < width_ && y < height_);
    return pixels_[size_t(y) * size_t(width_) + size_t(x)];
  }
  T* data() { return pixels_.data(); }
  const T* data() const { return pixels_.data(); }
  std::vector<T>& pixels() { return pixels_; }
  const std::vector<T>& pixels() const { return pixels_; }

  // Mirror rows (GL readback has row 0 at the bottom).
  void flipVertically() {
    for (int y = 0; y < height_ / 2; ++y)
      for (int x = 0; x < width_; ++x) std::swap(at(x, y), at(x, height_ - 1 - y));
  }

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<T> pixels_;
};

using ColorImage = Image<Rgba8>;    // 8-bit sRGB-encoded RGBA
using DepthImage = Image<float>;    // window depth in [0,1] (reversed Z, see core/camera.h) or linear metres
using IdImage = Image<uint32_t>;    // object ids, 0 = background

}  // namespace farfield::image
