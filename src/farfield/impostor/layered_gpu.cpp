// A layered impostor on the GPU: its layers packed into atlases on the CPU (packLayeredAtlases, no GL, so that a reader
// thread can make them ahead of the frame that needs them), then uploaded (GpuLayeredImpostor).
#include <algorithm>
#include <memory>

#include "farfield/core/check.h"
#include "farfield/impostor/layered.h"

namespace farfield::impostor {

LayeredAtlases packLayeredAtlases(const LayeredImpostor& impostor, LayerDraw draw) {
  const LayeredPlan& plan = impostor.plan;
  FF_CHECK(impostor.layers.size() == plan.layers.size());
  FF_CHECK(plan.atlas_spots.size() == plan.layers.size());
  const bool ids = plan.id_textures;
  LayeredAtlases out;
  std::vector<image::ColorImage>& colors = out.colors;
  std::vector<image::IdImage>& id_images = out.ids;
  std::vector<scene::Mesh>& meshes = out.meshes;
  meshes.resize(plan.atlas_sizes.size());
  for (const IVec2& a : plan.atlas_sizes) {
    colors.emplace_back(a.x, a.y, image::Rgba8(0, 0, 0, 0));
    if (ids) id_images.emplace_back(a.x, a.y, 0u);
  }
  for (size_t i = 0; i < plan.layers.size(); ++i) {
    const LayerPlan& lp = plan.layers[i];
    const Layer& layer = impostor.layers[i];
    const LayeredPlan::AtlasSpot& spot = plan.atlas_spots[i];
    FF_CHECK(layer.color.width() == lp.width && layer.color.height() == lp.height);
    // The image and its padding, the padding repeating the edge texels (what clamp-to-edge sampling would see).
    image::ColorImage& atlas = colors[spot.atlas];
    for (int y = -kAtlasPadding; y < lp.height + kAtlasPadding; ++y)
      for (int x = -kAtlasPadding; x < lp.width + kAtlasPadding; ++x) {
        const int sx = std::clamp(x, 0, lp.width - 1), sy = std::clamp(y, 0, lp.height - 1);
        atlas.at(spot.x + x, spot.y + y) = layer.color.at(sx, sy);
        if (ids && !layer.ids.empty()) id_images[spot.atlas].at(spot.x + x, spot.y + y) = layer.ids.at(sx, sy);
      }
    const IVec2 size = plan.atlas_sizes[spot.atlas];
    // Texel column x of the layer spans [-half_u + x s, -half_u + (x + 1) s] along right from the quad's centre, row y
    // [half_v - (y + 1) s, half_v - y s] along up (row 0 at the top); uv (0, 0) is the atlas spot's top-left texel.
    const Vec3 centre = plan.shaft.apex + lp.depth * plan.shaft.axis + lp.offset_u * plan.right + lp.offset_v * plan.up;
    const float s = 2.0f * lp.half_u / float(lp.width);
    const std::vector<LayerCrop> rects = draw == LayerDraw::Tiles
                                             ? layerTiles(layer.color, IVec2(lp.crop_x, lp.crop_y))
                                             : std::vector<LayerCrop>{{0, 0, lp.width, lp.height}};
    scene::Mesh& mesh = meshes[spot.atlas];
    for (const LayerCrop& r : rects) {
      const auto corner = [&](int x, int y) {
        return centre + (-lp.half_u + float(x) * s) * plan.right + (lp.half_v - float(y) * s) * plan.up;
      };
      const auto uv = [&](int x, int y) {
        return Vec2(float(spot.x + x) / float(size.x), float(spot.y + y) / float(size.y));
      };
      const int x0 = r.x, y0 = r.y, x1 = r.x + r.width, y1 = r.y + r.height;
      const uint32_t base = uint32_t(mesh.positions.size());
      mesh.positions.insert(mesh.positions.end(), {corner(x0, y0), corner(x1, y0), corner(x1, y1), corner(x0, y1)});
      mesh.uvs.insert(mesh.uvs.end(), {uv(x0, y0), uv(x1, y0), uv(x1, y1), uv(x0, y1)});
      mesh.normals.insert(mesh.normals.end(), 4, plan.shaft.axis);
      // Counter-clockwise seen from the viewers (right x up = axis).
      for (uint32_t k : {3u, 2u, 1u, 3u, 1u, 0u}) mesh.indices.push_back(base + k);
      ++out.rectangles;
    }
    ++out.quads;
  }
  for (scene::Mesh& mesh : meshes) mesh.computeBounds();
  return out;
}

uint64_t LayeredAtlases::cpuBytes() const {
  uint64_t bytes = 0;
  for (const image::ColorImage& c : colors) bytes += 4 * uint64_t(c.pixelCount());
  for (const image::IdImage& i : ids) bytes += 4 * uint64_t(i.pixelCount());
  for (const scene::Mesh& m : meshes) bytes += m.positions.size() * kLayerQuadBytes / 4;
  return bytes;
}

GpuLayeredImpostor::GpuLayeredImpostor(const LayeredImpostor& impostor, LayerDraw draw)
    : GpuLayeredImpostor(packLayeredAtlases(impostor, draw)) {}

GpuLayeredImpostor::GpuLayeredImpostor(const LayeredAtlases& atlases)
    : quads_(atlases.quads), rectangles_(atlases.rectangles) {
  FF_CHECK(atlases.colors.size() == atlases.meshes.size());
  FF_CHECK(atlases.ids.empty() || atlases.ids.size() == atlases.colors.size());
  for (size_t a = 0; a < atlases.meshes.size(); ++a) {
    meshes_.emplace_back(atlases.meshes[a]);
    auto texture = std::make_unique<gpu::Texture>(gpu::Texture::fromImage(atlases.colors[a], /*mipmaps=*/false));
    texture->setClampToEdge();
    auto material = std::make_unique<gpu::GpuMaterial>();
    material->unlit = true;
    material->double_sided = true;
    material->texture = texture.get();
    std::unique_ptr<gpu::Texture> id_texture;
    if (!atlases.ids.empty()) {
      id_texture = std::make_unique<gpu::Texture>(gpu::Texture::fromIds(atlases.ids[a]));
      material->id_texture = id_texture.get();
    }
    textures_.push_back(std::move(texture));
    id_textures_.push_back(std::move(id_texture));
    materials_.push_back(std::move(material));
  }
}

void GpuLayeredImpostor::appendDrawItems(std::vector<gpu::DrawItem>& out, uint32_t object_id) const {
  for (size_t i = 0; i < meshes_.size(); ++i) out.push_back({&meshes_[i], materials_[i].get(), Mat4(1.0f), object_id});
}

size_t GpuLayeredImpostor::gpuBytes() const {
  size_t bytes = 0;
  for (const gpu::GpuMesh& m : meshes_) bytes += m.byteSize();
  for (const auto& t : textures_) bytes += t->byteSize();
  for (const auto& t : id_textures_)
    if (t) bytes += t->byteSize();
  return bytes;
}

}  // namespace farfield::impostor
