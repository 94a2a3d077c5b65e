// Layered impostors cut to their data (Jeschke et al. 2005, section 6.2: "only the non-empty parts of a layer are
// stored"): each layer's image cropped to the rectangle of its texels with data, the layers drawn as the tiles that
// hold data, and the cover of each layer (the share of its quad those tiles draw) measured for the fill estimate.
#include <algorithm>
#include <string>

#include "farfield/core/error.h"
#include "farfield/impostor/layered.h"

namespace farfield::impostor {
void cropLayers(LayeredPlan& plan, std::span<const LayerCrop> crops) {
  if (plan.cropped) throw Error("layered impostor plan", "is cropped already");
  if (crops.size() != plan.layers.size())
    throw Error("layered impostor crops", std::to_string(crops.size()) + " crops for " +
                                              std::to_string(plan.layers.size()) + " layers");
  plan.texels = 0;
  for (size_t i = 0; i < crops.size(); ++i) {
    LayerPlan& layer = plan.layers[i];
    const LayerCrop& c = crops[i];
    if (c.width < 1 || c.height < 1 || c.x < 0 || c.y < 0 || c.x + c.width > layer.width ||
        c.y + c.height > layer.height)
      throw Error("layered impostor layer " + std::to_string(i),
                  "crop " + std::to_string(c.width) + "x" + std::to_string(c.height) + " at (" + std::to_string(c.x) +
                      ", " + std::to_string(c.y) + ") leaves its " + std::to_string(layer.width) + "x" +
                      std::to_string(layer.height) + " image");
    // A texel is s metres a side in the quad's plane (half_u = width * s / 2); column x spans [-half_u + x s, ...],
    // row y spans [half_v - (y + 1) s, half_v - y s] (row 0 at the top, towards +up).
    const double s = 2.0 * double(layer.half_u) / double(layer.width);
    // The same area of tiles, now over the smaller quad (the cut drops only texels without data).
    const double kept = double(c.width) * double(c.height) / (double(layer.width) * double(layer.height));
    layer.cover = std::min(1.0f, std::nextafter(float(double(layer.cover) / kept), 2.0f));
    layer.offset_u = float(double(layer.offset_u) - layer.half_u + (c.x + 0.5 * c.width) * s);
    layer.offset_v = float(double(layer.offset_v) + layer.half_v - (c.y + 0.5 * c.height) * s);
    layer.half_u = float(0.5 * c.width * s);
    layer.half_v = float(0.5 * c.height * s);
    layer.crop_x = c.x;
    layer.crop_y = c.y;
    layer.width = c.width;
    layer.height = c.height;
    plan.texels += uint64_t(c.width) * uint64_t(c.height);
  }
  packAtlases(plan);
  plan.texture_bytes = 0;
  for (const IVec2& a : plan.atlas_sizes)
    plan.texture_bytes += size_t(a.x) * size_t(a.y) * 4 * (plan.id_textures ? 2 : 1);
  plan.cropped = true;
}

LayerCrop dataCrop(const Layer& layer) {
  const int w = layer.color.width(), h = layer.color.height();
  const bool ids = !layer.ids.empty();
  int x0 = w, y0 = h, x1 = -1, y1 = -1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const image::Rgba8 c = layer.color.at(x, y);
      const bool data = c != image::Rgba8(0, 0, 0, 0) || (ids && layer.ids.at(x, y) != 0);
      if (!data) continue;
      x0 = std::min(x0, x);
      y0 = std::min(y0, y);
      x1 = std::max(x1, x);
      y1 = std::max(y1, y);
    }
  if (x1 < 0) return {0, 0, 1, 1};
  x0 = std::max(0, x0 - 1);
  y0 = std::max(0, y0 - 1);
  x1 = std::min(w - 1, x1 + 1);
  y1 = std::min(h - 1, y1 + 1);
  return {x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

LayeredImpostor cropLayered(const LayeredImpostor& impostor) {
  if (impostor.layers.size() != impostor.plan.layers.size())
    throw Error("layered impostor", std::to_string(impostor.layers.size()) + " layer images for " +
                                        std::to_string(impostor.plan.layers.size()) + " planned layers");
  std::vector<LayerCrop> crops;
  for (size_t i = 0; i < impostor.layers.size(); ++i) {
    const Layer& layer = impostor.layers[i];
    const LayerPlan& lp = impostor.plan.layers[i];
    if (layer.color.width() != lp.width || layer.color.height() != lp.height ||
        (!layer.ids.empty() && (layer.ids.width() != lp.width || layer.ids.height() != lp.height)))
      throw Error("layered impostor layer " + std::to_string(i), "images do not match the plan's size");
    crops.push_back(dataCrop(layer));
  }
  LayeredImpostor out;
  out.plan = impostor.plan;
  cropLayers(out.plan, crops);
  out.capture_ms = impostor.capture_ms;
  for (size_t i = 0; i < impostor.layers.size(); ++i) {
    const Layer& layer = impostor.layers[i];
    const LayerCrop& c = crops[i];
    Layer cut;
    cut.color = image::ColorImage(c.width, c.height);
    if (!layer.ids.empty()) cut.ids = image::IdImage(c.width, c.height);
    for (int y = 0; y < c.height; ++y)
      for (int x = 0; x < c.width; ++x) {
        cut.color.at(x, y) = layer.color.at(c.x + x, c.y + y);
        if (!layer.ids.empty()) cut.ids.at(x, y) = layer.ids.at(c.x + x, c.y + y);
      }
    cut.data_texels = layer.data_texels;
    cut.render_ms = layer.render_ms;
    out.layers.push_back(std::move(cut));
  }
  measureLayerCover(out);
  return out;
}

std::vector<LayerCrop> layerTiles(const image::ColorImage& color, IVec2 origin) {
  const int w = color.width(), h = color.height();
  std::vector<LayerCrop> out;
  if (w < 1 || h < 1) return out;
  // Texel column x of the image is column x + origin.x of the grid; tile t spans grid columns [t T, (t + 1) T).
  const int t = kLayerTile;
  const int tx0 = origin.x / t, tx1 = (origin.x + w - 1) / t, ty0 = origin.y / t, ty1 = (origin.y + h - 1) / t;
  const int tiles_x = tx1 - tx0 + 1, tiles_y = ty1 - ty0 + 1;
  // A tile is drawn if a texel within one of it has alpha > 0: mark every tile within one texel of such a texel.
  std::vector<uint8_t> drawn(size_t(tiles_x) * size_t(tiles_y), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (color.at(x, y).a == 0) continue;
      const int gx = x + origin.x, gy = y + origin.y;  // >= 0: (gx - 1) / t is gx's own tile at gx = 0
      for (int ty = (gy - 1) / t; ty <= (gy + 1) / t; ++ty)
        for (int tx = (gx - 1) / t; tx <= (gx + 1) / t; ++tx)
          if (tx >= tx0 && tx <= tx1 && ty >= ty0 && ty <= ty1)
            drawn[size_t(ty - ty0) * size_t(tiles_x) + size_t(tx - tx0)] = 1;
    }
  // Runs along each tile row, joined with the rectangle above when it spans the same tiles.
  std::vector<std::pair<int, int>> above;  // (first tile, end tile) of the previous row's runs
  std::vector<size_t> above_rect;          // their rectangles in `out`
  for (int ty = 0; ty < tiles_y; ++ty) {
    std::vector<std::pair<int, int>> runs;
    std::vector<size_t> run_rect;
    for (int tx = 0; tx < tiles_x;) {
      if (!drawn[size_t(ty) * size_t(tiles_x) + size_t(tx)]) {
        ++tx;
        continue;
      }
      const int first = tx;
      while (tx < tiles_x && drawn[size_t(ty) * size_t(tiles_x) + size_t(tx)]) ++tx;
      // The run's texels, clipped to the image.
      const int x0 = std::max(0, (tx0 + first) * t - origin.x), x1 = std::min(w, (tx0 + tx) * t - origin.x);
      const int y0 = std::max(0, (ty0 + ty) * t - origin.y), y1 = std::min(h, (ty0 + ty + 1) * t - origin.y);
      const auto it = std::find(above.begin(), above.end(), std::make_pair(first, tx));
      size_t rect;
      if (it != above.end()) {
        rect = above_rect[size_t(it - above.begin())];
        out[rect].height = y1 - out[rect].y;
      } else {
        rect = out.size();
        out.push_back({x0, y0, x1 - x0, y1 - y0});
      }
      runs.push_back({first, tx});
      run_rect.push_back(rect);
    }
    above = std::move(runs);
    above_rect = std::move(run_rect);
  }
  return out;
}

void measureLayerCover(LayeredImpostor& impostor) {
  if (impostor.layers.size() != impostor.plan.layers.size())
    throw Error("layered impostor", std::to_string(impostor.layers.size()) + " layer images for " +
                                        std::to_string(impostor.plan.layers.size()) + " planned layers");
  size_t rectangles = 0;
  for (size_t i = 0; i < impostor.layers.size(); ++i) {
    LayerPlan& lp = impostor.plan.layers[i];
    const image::ColorImage& color = impostor.layers[i].color;
    if (color.width() != lp.width || color.height() != lp.height)
      throw Error("layered impostor layer " + std::to_string(i), "image does not match the plan's size");
    uint64_t area = 0;
    const std::vector<LayerCrop> tiles = layerTiles(color, IVec2(lp.crop_x, lp.crop_y));
    for (const LayerCrop& r : tiles) area += uint64_t(r.width) * uint64_t(r.height);
    lp.cover = float(double(area) / (double(lp.width) * double(lp.height)));
    rectangles += tiles.size();
  }
  impostor.plan.mesh_bytes = rectangles * kLayerQuadBytes;
}

void coverWholeQuads(LayeredPlan& plan) {
  for (LayerPlan& layer : plan.layers) layer.cover = 1.0f;
}

}  // namespace farfield::impostor
