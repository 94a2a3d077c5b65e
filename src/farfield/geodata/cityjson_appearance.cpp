// Appearances: the document's themes and the ones chosen, its textures (loaded on first use), materials and texture
// vertices, and each surface's texture coordinates or material.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/geodata/cityjson_importer.h"

namespace farfield::geodata::cityjson_import {

// The scene material of texture `t` (loaded on first use; a missing file gives the placeholder).
std::optional<uint32_t> Importer::textureMaterial(int64_t t) {
  if (!app.textures || t < 0 || uint64_t(t) >= app.textures->size()) return std::nullopt;
  if (app.texture_materials.empty()) app.texture_materials.resize(app.textures->size());
  std::optional<uint32_t>& slot = app.texture_materials[size_t(t)];
  if (slot) return slot;
  const Json& tex = (*app.textures)[size_t(t)];
  std::string image = tex.is_object() && tex.contains("image") && tex["image"].is_string()
                          ? tex["image"].get<std::string>()
                          : std::string();
  std::shared_ptr<const image::ColorImage> img;
  std::string file;
  if (image.empty()) {
    img = texture_files->placeholder("texture " + std::to_string(t), "no \"image\" string");
    image = "texture " + std::to_string(t);
  } else if (image.find("://") != std::string::npos) {
    img = texture_files->placeholder(image, "not a local file (URLs are not fetched)");
  } else {
    std::replace(image.begin(), image.end(), '\\', '/');
    const std::filesystem::path p = std::filesystem::path(image).is_absolute()
                                        ? std::filesystem::path(image)
                                        : std::filesystem::path(path).parent_path() / image;
    img = texture_files->load(image, p);
    if (!scene::TextureFiles::isPlaceholder(img)) file = p.string();
  }
  slot = materials->forTexture(image, img, file);
  return slot;
}

std::optional<uint32_t> Importer::appearanceMaterial(int64_t m) {
  if (!app.materials || m < 0 || uint64_t(m) >= app.materials->size()) return std::nullopt;
  const Json& mat = (*app.materials)[size_t(m)];
  if (!mat.is_object()) return std::nullopt;
  Vec4 rgba(0.8f, 0.8f, 0.8f, 1.0f);  // X3D's default diffuse colour
  if (auto d = mat.find("diffuseColor"); d != mat.end() && d->is_array() && d->size() == 3 &&
                                         (*d)[0].is_number() && (*d)[1].is_number() && (*d)[2].is_number())
    rgba = Vec4((*d)[0].get<float>(), (*d)[1].get<float>(), (*d)[2].get<float>(), 1.0f);
  if (auto tr = mat.find("transparency"); tr != mat.end() && tr->is_number())
    rgba.a = 1.0f - tr->get<float>();
  rgba = glm::clamp(rgba, Vec4(0.0f), Vec4(1.0f));
  if (!isFinite(Vec3(rgba)) || !std::isfinite(rgba.a)) return std::nullopt;
  const std::string name = mat.contains("name") && mat["name"].is_string() ? mat["name"].get<std::string>()
                                                                            : "material " + std::to_string(m);
  return materials->forColour("material " + std::to_string(m), name, rgba);
}

// Texture of a surface from its texture values (one [t, uv, uv, ...] per ring, or [null]): the material and the
// uvs of each ring, or nothing when untextured or when the references do not fit the rings (counted).
std::optional<uint32_t> Importer::surfaceTexture(const Json* tex, const std::vector<size_t>& ring_sizes,
                                                 const std::vector<bool>& closing_dropped, CityFace& face) {
  if (!tex || !tex->is_array() || tex->empty()) return std::nullopt;
  const Json& first = (*tex)[0];
  if (!first.is_array() || first.empty() || first[0].is_null()) return std::nullopt;
  auto bad = [&]() -> std::optional<uint32_t> {
    ++st.bad_texture_references;
    face.uvs.clear();
    return std::nullopt;
  };
  if (!first[0].is_number_integer() || tex->size() != ring_sizes.size()) return bad();
  const int64_t t = first[0].get<int64_t>();
  face.uvs.assign(ring_sizes.size(), {});
  for (size_t r = 0; r < ring_sizes.size(); ++r) {
    const Json& ring = (*tex)[r];
    if (!ring.is_array() || ring.empty() || !ring[0].is_number_integer() || ring[0].get<int64_t>() != t) return bad();
    const size_t n = ring.size() - 1 - (closing_dropped[r] ? 1 : 0);
    if (n != ring_sizes[r]) return bad();
    for (size_t i = 0; i < n; ++i) {
      const Json& k = ring[i + 1];
      if (!k.is_number_integer()) return bad();
      const int64_t uv = k.get<int64_t>();
      if (uv < 0 || uint64_t(uv) >= app.uvs.size() || !app.uvs[size_t(uv)]) return bad();
      face.uvs[r].push_back(*app.uvs[size_t(uv)]);
    }
  }
  const std::optional<uint32_t> m = textureMaterial(t);
  if (!m) return bad();
  return m;
}

// The "values" of theme `theme` in a geometry's "texture" or "material" object.
const Json* Importer::themeValues(const Json& g, const char* key, const std::string& theme, const Json** value) {
  auto it = g.find(key);
  if (it == g.end() || !it->is_object() || theme.empty()) return nullptr;
  auto th = it->find(theme);
  if (th == it->end() || !th->is_object()) return nullptr;
  if (value) {
    if (auto v = th->find("value"); v != th->end()) *value = &*v;
  }
  auto v = th->find("values");
  return v != th->end() ? &*v : nullptr;
}

namespace {

// Themes named by the geometries' "texture" or "material" objects (`key`), sorted by name.
std::vector<std::string> themesOf(const Json& objects, const char* key) {
  std::set<std::string> names;
  for (auto it = objects.begin(); it != objects.end(); ++it) {
    const Json& o = it.value();
    if (!o.is_object()) continue;
    auto g = o.find("geometry");
    if (g == o.end() || !g->is_array()) continue;
    for (const Json& geom : *g) {
      if (!geom.is_object()) continue;
      auto a = geom.find(key);
      if (a == geom.end() || !a->is_object()) continue;
      for (auto t = a->begin(); t != a->end(); ++t) names.insert(t.key());
    }
  }
  return {names.begin(), names.end()};
}

// The theme to use: the one asked for, else CityJSON 1.0's "default-theme-*", else the first by name (JSON objects
// have no order a reader must keep, so "the first in the file" is not defined).
std::string chooseTheme(const std::vector<std::string>& themes, const std::string& asked, const Json& appearance,
                        const char* default_key) {
  if (themes.empty()) return {};
  if (!asked.empty() && std::find(themes.begin(), themes.end(), asked) != themes.end()) return asked;
  if (auto d = appearance.find(default_key);
      d != appearance.end() && d->is_string() &&
      std::find(themes.begin(), themes.end(), d->get<std::string>()) != themes.end())
    return d->get<std::string>();
  return themes.front();
}

}  // namespace

void readAppearance(const Json& doc, const Json& objects, const std::string& path,
                    const CityJsonImportOptions& options, Appearance& app, CityJsonStats& st) {
  st.texture_themes = themesOf(objects, "texture");
  st.material_themes = themesOf(objects, "material");
  if (!options.theme.empty() &&
      std::find(st.texture_themes.begin(), st.texture_themes.end(), options.theme) == st.texture_themes.end() &&
      std::find(st.material_themes.begin(), st.material_themes.end(), options.theme) == st.material_themes.end()) {
    std::string known;
    for (const auto* list : {&st.texture_themes, &st.material_themes})
      for (const std::string& t : *list) known += (known.empty() ? "" : ", ") + t;
    throw Error(path, "no appearance theme '" + options.theme + "' (themes: " + (known.empty() ? "none" : known) + ")");
  }
  static const Json kEmpty = Json::object();
  auto ait = doc.find("appearance");
  const Json& a = ait != doc.end() && ait->is_object() ? *ait : kEmpty;
  st.texture_theme = chooseTheme(st.texture_themes, options.theme, a, "default-theme-texture");
  st.material_theme = chooseTheme(st.material_themes, options.theme, a, "default-theme-material");
  app.texture_theme = st.texture_theme;
  app.material_theme = st.material_theme;
  if (auto t = a.find("textures"); t != a.end() && t->is_array()) app.textures = &*t;
  if (auto m = a.find("materials"); m != a.end() && m->is_array()) app.materials = &*m;
  if (auto v = a.find("vertices-texture"); v != a.end() && v->is_array()) {
    app.uvs.reserve(v->size());
    for (const Json& uv : *v) {
      if (uv.is_array() && uv.size() == 2 && uv[0].is_number() && uv[1].is_number()) {
        // CityJSON puts (0, 0) at the bottom left of the image, Farfield at the top left.
        const Vec2 p(uv[0].get<float>(), 1.0f - uv[1].get<float>());
        if (isFinite(p)) {
          app.uvs.emplace_back(p);
          continue;
        }
      }
      app.uvs.emplace_back(std::nullopt);
      ++st.bad_texture_vertices;
    }
  }
}

}  // namespace farfield::geodata::cityjson_import
