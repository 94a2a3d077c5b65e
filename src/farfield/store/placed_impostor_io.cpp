// The layer files of placed impostors (DIR/impostors): written by writePlacedImpostor, loaded by loadPlacedImpostor
// and checked against the plan re-derived from the record (storedLayeredPlan).
//
// Why PNG for the layers: the layers are mostly transparent (alpha 0 outside the slab's objects) and compress well;
// ids are packed in RGBA like the impostor store's layer views (PNG keeps them exactly).
#include "farfield/store/placement_store.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/image/png_io.h"
#include "farfield/store/generation_names.h"
#include "farfield/store/store_files.h"

namespace fs = std::filesystem;

namespace farfield::store {

namespace {

// image::writePng writes to a path: the PNG is encoded into NAME.tmp, read back and then written through
// writeFileAtomic, which reuses NAME.tmp (so the file operation hook sees every step that matters and a killed write
// leaves at most a temporary that the next write removes).
FileCheck writePngFile(const std::string& path, const image::ColorImage& image) {
  const std::string tmp = path + ".tmp";
  image::writePng(tmp, image);
  return writeFileAtomic(path, readCheckedFile(tmp, FileCheck{}, ""), false);
}

image::ColorImage packIds(const image::IdImage& ids) {
  image::ColorImage packed(ids.width(), ids.height());
  for (size_t i = 0; i < packed.pixelCount(); ++i) {
    const uint32_t id = ids.pixels()[i];
    packed.pixels()[i] = image::Rgba8(uint8_t(id), uint8_t(id >> 8), uint8_t(id >> 16), uint8_t(id >> 24));
  }
  return packed;
}

image::IdImage unpackIds(const image::ColorImage& packed) {
  image::IdImage ids(packed.width(), packed.height(), 0u);
  for (size_t i = 0; i < packed.pixelCount(); ++i) {
    const image::Rgba8 c = packed.pixels()[i];
    ids.pixels()[i] = uint32_t(c.r) | uint32_t(c.g) << 8 | uint32_t(c.b) << 16 | uint32_t(c.a) << 24;
  }
  return ids;
}

// A layer file named by the index: size and CRC-32 checked before the PNG is decoded; errors name the record.
image::ColorImage readLayerPng(const std::string& path, const FileCheck& check, const std::string& record) {
  readCheckedFile(path, check, record);
  try {
    return image::readPng(path);
  } catch (const Error& e) {
    throw Error(record + ": " + e.what());
  }
}

std::string sizeText(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

// storedLayeredPlan, its errors naming `source` (the index file, when known) and the record.
impostor::LayeredPlan storedPlanIn(const StoredPlacedImpostor& imp, const std::string& source) {
  const std::string record = imp.record.empty() ? recordName(imp.id) : imp.record;
  impostor::LayeredPlan plan;
  try {
    plan = impostor::planLayered(imp.box, imp.shaft, imp.bound, imp.options);
  } catch (const Error& e) {
    throw Error(source, record + ": its box, shaft, bound and options give no layered plan: " + e.what());
  }
  if (plan.layers.size() != imp.layers.size())
    throw Error(source, record + ": lists " + std::to_string(imp.layers.size()) + " layers, its plan has " +
                            std::to_string(plan.layers.size()));
  std::vector<impostor::LayerCrop> crops;
  for (const StoredImpostorLayer& s : imp.layers) crops.push_back(s.crop);
  try {
    impostor::cropLayers(plan, crops);
  } catch (const Error& e) {
    throw Error(source, record + ": " + e.what());
  }
  return plan;
}

}  // namespace

void createDirectory(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir.string(), "cannot create the directory: " + ec.message());
}

std::string recordName(uint32_t id) { return "impostor " + std::to_string(id); }

std::string placedLayerFileName(uint64_t generation, uint32_t id, size_t layer, bool ids) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "i%06u.%02zu%s", id, layer, ids ? ".ids.png" : ".png");
  return std::string(kImpostorDir) + "/" + generationPrefix(generation) + buf;
}

StoredPlacedImpostor writePlacedImpostor(const std::string& dir, uint64_t generation, uint32_t id, uint32_t node,
                                         const std::vector<uint32_t>& objects,
                                         const impostor::LayeredImpostor& impostor, const Box3& box,
                                         const Shaft& shaft, const ErrorBound& bound,
                                         const impostor::LayeredOptions& options) {
  StoredPlacedImpostor out;
  out.id = id;
  out.node = node;
  out.objects = objects;
  std::sort(out.objects.begin(), out.objects.end());  // a set: the caller's order (e.g. a BVH's) carries no meaning
  out.box = box;
  out.shaft = shaft;
  out.bound = bound;
  out.options = options;
  out.bytes = impostor.plan.bytes();
  out.capture_ms = impostor.capture_ms;
  out.record = recordName(id);
  const auto fail = [&](const std::string& what) { throw Error(dir, out.record + ": " + what); };
  if (generation == 0) fail("generation 0 (the data files of a placement database have generations 1, 2, ...)");
  if (out.objects.empty() || out.objects.front() == 0 ||
      std::adjacent_find(out.objects.begin(), out.objects.end()) != out.objects.end())
    fail("objects must be at least one id >= 1, without repeats");
  impostor::LayeredPlan plan;
  try {
    plan = impostor::planLayered(box, shaft, bound, options);
  } catch (const Error& e) {
    fail(std::string("its box, shaft, bound and options give no layered plan: ") + e.what());
  }
  const size_t count = plan.layers.size();
  if (impostor.layers.size() != count || impostor.plan.layers.size() != count)
    fail("the impostor has " + std::to_string(impostor.layers.size()) + " layers (its plan " +
         std::to_string(impostor.plan.layers.size()) + "), the plan of its box, shaft, bound and options " +
         std::to_string(count) + " (was it captured with other inputs?)");
  // The part of each captured image the impostor holds (all of it when not cropped).
  std::vector<impostor::LayerCrop> crops;
  for (size_t l = 0; l < count; ++l) {
    const impostor::LayerPlan& lp = impostor.plan.layers[l];
    crops.push_back(impostor.plan.cropped ? impostor::LayerCrop{lp.crop_x, lp.crop_y, lp.width, lp.height}
                                          : impostor::LayerCrop{0, 0, plan.layers[l].width, plan.layers[l].height});
  }
  try {
    impostor::cropLayers(plan, crops);
  } catch (const Error& e) {
    fail(e.what());
  }
  for (size_t l = 0; l < count; ++l) {
    const impostor::LayerPlan& p = plan.layers[l];
    const impostor::Layer& layer = impostor.layers[l];
    const std::string at = "layer " + std::to_string(l) + ": ";
    if (impostor.plan.layers[l].width != p.width || impostor.plan.layers[l].height != p.height)
      fail(at + "the impostor's plan is " + sizeText(impostor.plan.layers[l].width, impostor.plan.layers[l].height) +
           ", the plan of its box, shaft, bound and options " + sizeText(p.width, p.height));
    if (layer.color.width() != p.width || layer.color.height() != p.height)
      fail(at + "colour image is " + sizeText(layer.color.width(), layer.color.height()) + ", the plan needs " +
           sizeText(p.width, p.height));
    if (options.id_textures && (layer.ids.width() != p.width || layer.ids.height() != p.height))
      fail(at + "id image is " + sizeText(layer.ids.width(), layer.ids.height()) + ", the plan needs " +
           sizeText(p.width, p.height));
    if (!options.id_textures && !layer.ids.empty()) fail(at + "has an id image but the options have no id_textures");
  }
  createDirectory(fs::path(dir) / kImpostorDir);
  for (size_t l = 0; l < count; ++l) {
    const impostor::Layer& layer = impostor.layers[l];
    StoredImpostorLayer s;
    s.texture = placedLayerFileName(generation, id, l, false);
    s.texture_check = writePngFile(joinPath(dir, s.texture), layer.color);
    if (options.id_textures) {
      s.ids = placedLayerFileName(generation, id, l, true);
      s.ids_check = writePngFile(joinPath(dir, s.ids), packIds(layer.ids));
    }
    s.data_texels = layer.data_texels;
    s.render_ms = layer.render_ms;
    s.crop = crops[l];
    out.layers.push_back(std::move(s));
  }
  return out;
}

impostor::LayeredPlan storedLayeredPlan(const StoredPlacedImpostor& imp) {
  return storedPlanIn(imp, "placement database");
}

impostor::LayeredImpostor loadPlacedImpostor(const std::string& dir, const StoredPlacedImpostor& imp) {
  const std::string record = imp.record.empty() ? recordName(imp.id) : imp.record;
  const std::string index_file = joinPath(dir, kPlacementIndexFile);
  impostor::LayeredImpostor out;
  out.plan = storedPlanIn(imp, index_file);
  out.capture_ms = imp.capture_ms;
  for (size_t l = 0; l < imp.layers.size(); ++l) {
    const StoredImpostorLayer& s = imp.layers[l];
    const impostor::LayerPlan& p = out.plan.layers[l];
    const std::string at = record + " layer " + std::to_string(l);
    impostor::Layer layer;
    const std::string texture_file = joinPath(dir, s.texture);
    layer.color = readLayerPng(texture_file, s.texture_check, at + " texture");
    if (layer.color.width() != p.width || layer.color.height() != p.height)
      throw Error(texture_file, at + " texture: " + sizeText(layer.color.width(), layer.color.height()) +
                                    " but the plan needs " + sizeText(p.width, p.height));
    if (s.ids.empty() == imp.options.id_textures)
      throw Error(index_file, at + (imp.options.id_textures ? ": no ids file but the options have id_textures"
                                                            : ": an ids file but the options have no id_textures"));
    if (!s.ids.empty()) {
      const std::string ids_file = joinPath(dir, s.ids);
      const image::ColorImage packed = readLayerPng(ids_file, s.ids_check, at + " ids");
      if (packed.width() != p.width || packed.height() != p.height)
        throw Error(ids_file, at + " ids: " + sizeText(packed.width(), packed.height()) + " but the plan needs " +
                                  sizeText(p.width, p.height));
      layer.ids = unpackIds(packed);
    }
    layer.data_texels = s.data_texels;
    layer.render_ms = s.render_ms;
    out.layers.push_back(std::move(layer));
  }
  impostor::measureLayerCover(out);  // what GpuLayeredImpostor will draw of each layer
  return out;
}

}  // namespace farfield::store
