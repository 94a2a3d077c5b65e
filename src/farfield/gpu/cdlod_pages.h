// Height and colour pages of a paged CDLOD terrain (gpu/cdlod_renderer.h, terrain/paged_gpu_lod.h): texture arrays
// whose layers each hold one tile of the grid at full resolution, (S + 1) x (S + 1) grid points (the tile's own
// points, its borders included, so that neighbouring pages agree on their shared edge) and the original texture's
// texels at those points, with mipmaps made on the CPU (a layer's upload touches no other layer).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "farfield/image/image.h"

namespace farfield::gpu {

class CdlodPages {
 public:
  // Needs a current context. page_cells: S; layers: pages held at once. Throws farfield::Error for sizes the driver
  // cannot hold.
  CdlodPages(int page_cells, int layers);
  ~CdlodPages();
  CdlodPages(const CdlodPages&) = delete;
  CdlodPages& operator=(const CdlodPages&) = delete;

  // Fills a layer: heights, (S + 1)^2 row-major from the tile's first point; colour, its mip chain (colourMips: level
  // 0 is (S + 1)^2 texels likewise). Throws farfield::Error for a layer out of range or data of another size.
  void upload(int layer, std::span<const float> heights, std::span<const image::ColorImage> colour);
  // The mip chain of a page's colour, made on the CPU (by a loading thread: no GL).
  static std::vector<image::ColorImage> colourMips(image::ColorImage level0);
  // Binds the height array to a texture unit and the colour array to another.
  void bind(int height_unit, int colour_unit) const;

  int pageCells() const { return page_cells_; }
  int layers() const { return layers_; }
  // GPU bytes of one layer (heights and colour with its mipmaps).
  size_t layerBytes() const;
  size_t bytes() const { return layerBytes() * size_t(layers_); }

 private:
  int page_cells_, layers_, levels_;
  uint32_t heights_ = 0, colours_ = 0;
};

}  // namespace farfield::gpu
