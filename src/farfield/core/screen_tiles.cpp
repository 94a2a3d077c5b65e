#include "farfield/core/screen_tiles.h"

#include <algorithm>

#include "farfield/core/error.h"

namespace farfield {

std::vector<glm::ivec4> tileCover(std::span<const glm::ivec4> regions, int width, int height, int tile_px) {
  if (width < 1 || height < 1 || tile_px < 1) throw Error("screen tiles", "frame and tile sizes must be positive");
  const int cols = (width + tile_px - 1) / tile_px, rows = (height + tile_px - 1) / tile_px;
  std::vector<unsigned char> covered(size_t(cols) * size_t(rows), 0);
  for (const glm::ivec4& r : regions) {
    const int x0 = std::max(r.x, 0), y0 = std::max(r.y, 0), x1 = std::min(r.z, width), y1 = std::min(r.w, height);
    if (x1 <= x0 || y1 <= y0) continue;
    for (int ty = y0 / tile_px; ty <= (y1 - 1) / tile_px; ++ty)
      for (int tx = x0 / tile_px; tx <= (x1 - 1) / tile_px; ++tx) covered[size_t(ty) * size_t(cols) + size_t(tx)] = 1;
  }
  std::vector<glm::ivec4> out;
  for (int ty = 0; ty < rows; ++ty)
    for (int tx = 0; tx < cols;) {
      if (!covered[size_t(ty) * size_t(cols) + size_t(tx)]) {
        ++tx;
        continue;
      }
      const int start = tx;
      while (tx < cols && covered[size_t(ty) * size_t(cols) + size_t(tx)]) ++tx;
      out.emplace_back(start * tile_px, ty * tile_px, std::min(tx * tile_px, width),
                       std::min((ty + 1) * tile_px, height));
    }
  return out;
}

}  // namespace farfield
