// Appearances of polygons in the chosen theme: a texture with its coordinates per ring (the image read relative to
// the file; URLs are not fetched), else an X3DMaterial's colour.
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <citygml/georeferencedtexture.h>
#include <citygml/material.h>
#include <citygml/polygon.h>
#include <citygml/texture.h>
#include <citygml/texturecoordinates.h>
#include <citygml/texturetargetdefinition.h>

#include "farfield/geodata/citygml_importer.h"

namespace farfield::geodata::citygml_import {

// The polygon's texture in the theme and its coordinates per kept ring; nullopt (face.uvs empty) when it has
// none or they do not fit.
std::optional<uint32_t> Importer::textureOf(const citygml::Polygon& p,
                                            const std::vector<const citygml::LinearRing*>& rings,
                                            const std::vector<bool>& closed, CityFace& face) {
  if (st_.theme.empty()) return std::nullopt;
  std::shared_ptr<const citygml::TextureTargetDefinition> def = p.getTextureTargetDefinitionForTheme(st_.theme, true);
  if (!def) def = p.getTextureTargetDefinitionForTheme(st_.theme, false);
  if (!def || !def->getAppearance()) return std::nullopt;
  const std::shared_ptr<const citygml::Texture> tex = def->getAppearance();
  face.uvs.assign(rings.size(), {});
  for (size_t r = 0; r < rings.size(); ++r) {
    const auto coords = def->getTextureCoordinatesForID(rings[r]->getId());
    const size_t n = face.rings[r].size();
    if (!coords || (coords->getCoords().size() != n && coords->getCoords().size() != n + (closed[r] ? 1 : 0))) {
      ++st_.bad_texture_coordinates;
      face.uvs.clear();
      return std::nullopt;
    }
    for (size_t i = 0; i < n; ++i) {
      const TVec2f& c = coords->getCoords()[i];
      // CityGML puts (0, 0) at the bottom left of the image, Farfield at the top left.
      const Vec2 uv(c.x, 1.0f - c.y);
      if (!isFinite(uv)) {
        ++st_.bad_texture_coordinates;
        face.uvs.clear();
        return std::nullopt;
      }
      face.uvs[r].push_back(uv);
    }
  }
  std::string url = tex->getUrl();
  std::replace(url.begin(), url.end(), '\\', '/');
  std::shared_ptr<const image::ColorImage> img;
  std::string file;
  if (url.empty()) {
    url = "texture " + tex->getId();
    img = texture_files_.placeholder(url, "no image URI");
  } else if (url.find("://") != std::string::npos) {
    img = texture_files_.placeholder(url, "not a local file (URLs are not fetched)");
  } else {
    const fs::path path = fs::path(url).is_absolute() ? fs::path(url) : fs::path(base_dir_) / url;
    img = texture_files_.load(url, path);
    if (!scene::TextureFiles::isPlaceholder(img)) file = path.string();
  }
  return materials_->forTexture(url, img, file);
}

std::optional<uint32_t> Importer::materialOf(const citygml::Polygon& p) {
  if (st_.theme.empty()) return std::nullopt;
  const std::shared_ptr<const citygml::Material> m = p.getMaterialFor(st_.theme);
  if (!m) return std::nullopt;
  const TVec3f d = m->getDiffuse();
  Vec4 rgba(d.r, d.g, d.b, 1.0f - m->getTransparency());
  if (!isFinite(Vec3(rgba)) || !std::isfinite(rgba.a)) return std::nullopt;
  rgba = glm::clamp(rgba, Vec4(0.0f), Vec4(1.0f));
  const std::string key = m->getId().empty() ? "material" : m->getId();
  return materials_->forColour("material " + key, key, rgba);
}

}  // namespace farfield::geodata::citygml_import
