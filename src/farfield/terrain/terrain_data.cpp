#include "farfield/terrain/terrain_data.h"

#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>
#include <string_view>
#include <vector>

#include "farfield/core/checked_cast.h"
#include "farfield/core/error.h"
#include "farfield/terrain/dem_io.h"
#include "farfield/terrain/fractal.h"

namespace farfield::terrain {

namespace {

// A whole number of decimal digits only (no sign, space or exponent), or none when `text` is not one or does not fit.
std::optional<uint64_t> decimal(std::string_view text) {
  uint64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size()) return {};
  return v;
}

}  // namespace

FractalOptions parseFractalSpec(const std::string& spec) {
  const std::string usage =
      "expected fractal:SIZE or fractal:SIZE:SEED, then optionally :relief=M :roughness=R :cell=M (SIZE = 2^n + 1, "
      "e.g. fractal:513:7 or fractal:8193:3:relief=4000:roughness=0.62)";
  if (!isFractalSpec(spec)) throw Error(spec, usage);
  std::vector<std::string_view> parts;
  std::string_view rest = std::string_view(spec).substr(8);
  for (size_t colon; (colon = rest.find(':')) != std::string_view::npos; rest = rest.substr(colon + 1))
    parts.push_back(rest.substr(0, colon));
  parts.push_back(rest);
  const std::optional<uint64_t> size = decimal(parts[0]);
  if (!size) throw Error(spec, usage);
  FractalOptions f;
  f.size = checkedCast<int>(*size, spec, "SIZE");
  if (parts.size() > 1) {
    const std::optional<uint64_t> seed = decimal(parts[1]);
    if (!seed) throw Error(spec, usage + "; SEED must be a whole number in 0..18446744073709551615");
    f.seed = *seed;
  }
  for (size_t k = 2; k < parts.size(); ++k) {
    const size_t eq = parts[k].find('=');
    if (eq == std::string_view::npos) throw Error(spec, usage);
    const std::string key(parts[k].substr(0, eq)), text(parts[k].substr(eq + 1));
    double value = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size() || text.empty() || !(value > 0.0) ||
        !std::isfinite(value))
      throw Error(spec, key + " must be a positive number, got '" + text + "'");
    if (key == "relief") f.relief = value;
    else if (key == "roughness") f.roughness = value;
    else if (key == "cell") f.cell_size = value;
    else throw Error(spec, "unknown fractal option '" + key + "' (relief, roughness, cell)");
  }
  return f;
}

Heightfield loadHeightfield(const std::string& spec, const DemLoadOptions& dem) {
  return isFractalSpec(spec) ? fractalTerrain(parseFractalSpec(spec)) : loadDem(spec, dem);
}

std::unique_ptr<TerrainData> TerrainData::load(const std::string& spec, const TerrainLoadOptions& options) {
  auto data = std::make_unique<TerrainData>();
  data->source = loadHeightfield(spec, options.dem);
  if (!(options.centred_scale >= 0.0f && std::isfinite(options.centred_scale)))
    throw Error(spec, "the terrain's vertical scale must be a finite number >= 0");
  const double cx = 0.5 * data->source.extentX(), cy = 0.5 * data->source.extentY();
  if (options.centred_scale > 0.0f) {
    // As the city's ground function samples it (apps/farfield/city_terrain.cpp).
    const float base = data->source.sample(cx, cy);
    for (float& h : data->source.heights) h = options.centred_scale * (h - base);
  }
  if (options.block < 2 || (options.block & (options.block - 1)) != 0)
    throw Error("LOD block size", "must be a power of two >= 2");
  // Blocks as large as the grid allows, up to the option: bigger blocks let the low-resolution LOD get coarser.
  int block = options.block;
  while (block > 2 && ((data->source.width - 1) / block < 1 || (data->source.height - 1) / block < 1)) block /= 2;
  data->hf = cropForBlocks(data->source, block);
  data->crop_i0 = (data->source.width - data->hf.width) / 2;
  data->crop_j0 = (data->source.height - data->hf.height) / 2;
  data->source_centre = DVec2(cx - data->crop_i0 * data->source.cell_x, cy - data->crop_j0 * data->source.cell_y);
  data->lod = std::make_unique<QuadtreeLod>(data->hf, block);
  if (options.texture.empty()) {
    TextureOptions t;
    t.scale = options.texture_scale;
    data->texture = terrainTexture(data->hf, t);
  } else {
    data->texture = loadTexture(options.texture);
  }
  return data;
}

std::string TerrainData::describe() const {
  std::ostringstream s;
  s << source.source << ": " << source.width << "x" << source.height << " grid points, cells " << source.cell_x
    << " x " << source.cell_y << " m, heights " << source.minHeight() << ".." << source.maxHeight() << " m, "
    << source.nodata_count << " nodata points filled";
  if (hf.width != source.width || hf.height != source.height)
    s << "; cropped to " << hf.width << "x" << hf.height << " at (" << crop_i0 << ", " << crop_j0
      << ") for LOD blocks of " << lod->block() << " cells";
  for (const std::string& note : source.notes) s << "; " << note;
  return s.str();
}

scene::Scene TerrainData::fullResolutionScene() const {
  scene::Scene scene;
  scene::Mesh mesh;
  mesh.positions = lod->positions();
  mesh.uvs.resize(mesh.positions.size());
  for (size_t k = 0; k < mesh.positions.size(); ++k) mesh.uvs[k] = texCoord(hf, Vec2(mesh.positions[k]));
  mesh.indices = lod->fullResolutionIndices();
  mesh.computeBounds();
  scene::Material material;
  material.name = "terrain";
  material.texture = std::make_shared<const image::ColorImage>(texture);
  material.unlit = true;
  scene::Object object;
  object.name = "terrain";
  object.parts.push_back({scene.addMesh(std::move(mesh)), scene.addMaterial(std::move(material))});
  scene.addObject(std::move(object));
  return scene;
}

}  // namespace farfield::terrain
