// Writes the seed inputs of the fuzz targets that read Farfield's own formats and DEMs, small and valid, with
// Farfield's own writers (so a seed is what the reader is made for): impostor stores of every layout, a placement
// database, a cost profile, camera paths, a street graph, DEMs in each format the DEM target names, and an OSM PBF made
// from the project's test OSM file. fuzz/seed_corpus.sh runs it and adds the project's test files.
//
// make_seeds OUT_DIR TEST_DATA_DIR   (files go to OUT_DIR/<target>/)
#include <cpl_conv.h>
#include <cpl_string.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <osmium/io/any_input.hpp>
#include <osmium/io/any_output.hpp>
#include <osmium/io/reader.hpp>
#include <osmium/io/writer.hpp>

#include "farfield/core/error.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/cost_profile.h"
#include "farfield/impostor/layered.h"
#include "farfield/store/impostor_store.h"
#include "farfield/store/placement_store.h"
#include "farfield/urban/street_graph.h"
#include "store_container.h"

namespace fs = std::filesystem;
using namespace farfield;

namespace {

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

void writeSeed(const fs::path& dir, const std::string& name, const std::string& bytes) {
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary | std::ios::trunc) << bytes;
}

// A database directory as the store targets' input (store_container.h): the index, then the files it names.
std::string containerOf(const fs::path& dir, const char* index_file, uint8_t mode) {
  const std::string index = readFile(dir / index_file);
  std::vector<std::string> names, files;
  fuzz::fileNames(nlohmann::json::parse(index), names);
  for (const std::string& n : names) files.push_back(readFile(dir / n));
  return fuzz::joinStoreInput(mode, index, files);
}

// A 3 x 3 grid of junctions 60 m apart with its 12 streets.
urban::StreetGraph gridGraph() {
  std::vector<Vec2> junctions;
  std::vector<urban::Street> streets;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) junctions.emplace_back(60.0f * float(x), 60.0f * float(y));
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 3; ++x) {
      const uint32_t k = 3 * y + x;
      if (x < 2) streets.push_back({k, k + 1, 12.0f, urban::kStreet});
      if (y < 2) streets.push_back({k, k + 3, 8.0f, urban::kLane});
    }
  return urban::StreetGraph::build(junctions, streets, "seed grid");
}

Camera smallCamera(float x) {
  Camera c;
  c.eye = Vec3(x, 1.0f, 1.7f);
  c.at = Vec3(x + 50.0f, 1.5f, 1.6f);
  c.up = Vec3(0.0f, 0.0f, 1.0f);
  c.fov_y = 1.0f;
  c.width = 8;
  c.height = 6;
  return c;
}

// A view of 4 vertices and 2 triangles over an 8 x 6 texture, with object ids when `ids`.
impostor::DepthMeshImpostor smallView(float x, bool ids) {
  impostor::DepthMeshImpostor v;
  v.camera = smallCamera(x);
  v.mesh.positions = {{x + 40, -5, 0}, {x + 40, 5, 0}, {x + 40, 5, 8}, {x + 40, -5, 8}};
  v.mesh.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  v.mesh.indices = {0, 1, 2, 0, 2, 3};
  v.mesh.computeBounds();
  auto texture = std::make_shared<image::ColorImage>(8, 6);
  for (size_t i = 0; i < texture->pixelCount(); ++i)
    texture->pixels()[i] = image::Rgba8(uint8_t(30 * i), 100, 200, i % 5 == 0 ? 0 : 255);
  v.texture = texture;
  if (ids) {
    v.triangle_ids = {3, 4};
    auto id_image = std::make_shared<image::IdImage>(8, 6, 0u);
    for (size_t i = 0; i < id_image->pixelCount(); ++i) id_image->pixels()[i] = i % 5 == 0 ? 0u : 3u + uint32_t(i % 2);
    v.ids = id_image;
  }
  return v;
}

impostor::ValidityRegion smallRegion(float x) {
  impostor::ValidityRegion r;
  r.origin = Vec3(x, 1.0f, 1.7f);
  r.end = Vec3(x + 60.0f, 1.0f, 1.7f);
  r.half_width = 4.0f;
  r.below = 0.5f;
  r.above = 0.5f;
  r.back = 1.0f;
  r.step = 20.0f;
  r.laterals = 3;
  r.envelope = {0.0f, 0.001f, 0.002f, 0.0f, 0.0005f, 0.003f, 0.0f, 0.001f, 0.01f};
  return r;
}

// Impostor stores: a version 4 pipeline store (pvs, near-far, single, mmi; two cells, one layer of two stations),
// and a Sillion store (techniques depth-mesh and grid-mesh).
void impostorStoreSeeds(const fs::path& work, const fs::path& out) {
  const std::string text = gridGraph().toJson().dump();
  {
    const fs::path dir = work / "pipeline";
    fs::remove_all(dir);
    store::StoreIndex index;
    index.generation = 1;
    index.scene = "seed.glb";
    index.scene_objects = 6;
    index.pipeline = {"pvs", "near-far", "single", "mmi"};
    index.options = {{"pipeline", {{"error_px", 10}}}};
    store::writeStreets(dir.string(), index, text);
    for (uint32_t he : {2u, 5u}) {
      store::CellEntry e;
      e.half_edge = he;
      e.camera = smallCamera(float(he));
      e.local_objects = {1, 2};
      store::CellPipeline p;
      p.has_pvs = true;
      p.pvs = {1, 2, 3, 4, 5};
      p.pvs_samples = 3;
      p.has_split = true;
      p.near = {1, 2};
      p.far = {3, 4, 5};
      p.has_single = true;
      p.single.objects = {3, 4, 5};
      p.single.views.push_back(store::writeLayerView(
          dir.string(), store::layerFileStem(he, "smi", 0, 0, 1), smallView(float(he), he == 2)));
      p.single.validity = {smallRegion(float(he))};
      p.has_mmi = true;
      p.threshold_rad = 0.02;
      p.event_edges = 1;
      p.max_weight_rad = 0.1;
      store::StoredLayer layer;
      layer.objects = {3, 4};
      for (size_t station = 0; station < 2; ++station) {
        store::StoredView v = store::writeLayerView(dir.string(), store::layerFileStem(he, "mmi", 0, station, 1),
                                                    smallView(float(he) + 30.0f * float(station), station == 0));
        v.station = uint32_t(station);
        layer.views.push_back(v);
        layer.validity.push_back(smallRegion(float(he) + 30.0f * float(station)));
      }
      p.layers = {layer};
      e.pipeline = p;
      index.cells.push_back(e);
    }
    store::writeIndex(dir.string(), index);
    writeSeed(out, "pipeline_v4_direct", containerOf(dir, store::kIndexFile, 0x44));
    writeSeed(out, "pipeline_v4_threaded", containerOf(dir, store::kIndexFile, 0x46));
  }
  {
    const fs::path dir = work / "sillion";
    fs::remove_all(dir);
    store::StoreIndex index;
    index.version = 3;
    index.generation = 1;
    index.techniques = {"depth-mesh", "grid-mesh"};
    index.scene_objects = 6;
    store::writeStreets(dir.string(), index, text);
    store::CellEntry e;
    e.half_edge = 7;
    e.camera = smallCamera(0.0f);
    e.local_objects = {1};
    const impostor::DepthMeshImpostor view = smallView(0.0f, false);
    store::writeCell(dir.string(), e, {{"depth-mesh", &view}, {"grid-mesh", &view}}, 1);
    index.cells.push_back(e);
    store::writeIndex(dir.string(), index);
    writeSeed(out, "sillion_v3", containerOf(dir, store::kIndexFile, 0x44));
  }
  // The mesh file alone, as the first file of an index that names one mesh: a reader of a damaged binary record.
}

// A placement database: two impostors (one with ids images), a view space split once, three CPVs.
void placementSeeds(const fs::path& work, const fs::path& out) {
  const fs::path dir = work / "placement";
  fs::remove_all(dir);
  store::PlacementIndex index;
  index.generation = 1;
  index.scene = "seed.glb";
  index.scene_objects = 6;
  index.options = {{"tmax", 25}, {"error_px", 2}};
  index.summary = {{"cpvs", 3}};
  index.view_space = Box3::fromPoints(Vec3(-50, -50, 1), Vec3(50, 50, 3));
  store::StoredViewSpaceNode root{index.view_space, {1, 2}, 0, 3, false, {}};
  Box3 lower = index.view_space, upper = index.view_space;
  lower.hi.x = 0.0f;
  upper.lo.x = 0.0f;
  index.nodes = {root, {lower, {-1, -1}, 0, 2, true, {1, 2, 3}}, {upper, {-1, -1}, 2, 1, false, {}}};
  std::mt19937 rng(7);
  for (uint32_t id : {1u, 2u}) {
    const Box3 box = Box3::fromPoints(Vec3(80.0f * float(id), -5, 0), Vec3(80.0f * float(id) + 10, 5, 12));
    const Shaft shaft = Shaft::make(box.center(), Vec3(-1, 0, 0), 0.8f, 60.0f, "seed shaft");
    ErrorBound bound;
    bound.pixels = 2.0;
    impostor::LayeredOptions o;
    o.max_texture_size = 6;
    o.layer_count = 2;
    o.id_textures = id == 1;
    impostor::LayeredImpostor imp;
    imp.plan = impostor::planLayered(box, shaft, bound, o);
    for (const impostor::LayerPlan& p : imp.plan.layers) {
      impostor::Layer layer;
      layer.color = image::ColorImage(p.width, p.height);
      for (image::Rgba8& c : layer.color.pixels()) {
        const bool covered = rng() % 3 != 0;
        c = image::Rgba8(uint8_t(rng()), uint8_t(rng()), uint8_t(rng()), covered ? 255 : 0);
        layer.data_texels += covered ? 1 : 0;
      }
      if (o.id_textures) {
        layer.ids = image::IdImage(p.width, p.height);
        for (uint32_t& v : layer.ids.pixels()) v = rng() % 2 ? 0u : 3u;
      }
      imp.layers.push_back(std::move(layer));
    }
    index.impostors.push_back(
        store::writePlacedImpostor(dir.string(), 1, id, id, {id + 2, id + 3}, imp, box, shaft, bound, o));
  }
  for (int k = 0; k < 3; ++k) {
    store::StoredCpv cpv;
    cpv.region = index.nodes[k < 2 ? 1 : 2].box;
    cpv.vdi = Vdi::fullFace(k);
    cpv.t_enc = 30.0 + k;
    cpv.t_after = 20.0;
    cpv.impostors = k == 1 ? std::vector<uint32_t>{1, 2} : std::vector<uint32_t>{uint32_t(1 + k % 2)};
    index.cpvs.push_back(cpv);
  }
  store::writePlacementIndex(dir.string(), index);
  writeSeed(out, "placement", containerOf(dir, store::kPlacementIndexFile, 0x44));
}

void jsonSeeds(const fs::path& out) {
  gpu::CostProfile profile;
  profile.model.base_ms = 1.5;
  profile.model.ms_per_mtriangle = 3.25;
  profile.model.ms_per_draw = 0.004;
  profile.model.ms_per_mpixel = 0.5;
  profile.model.samples = 120;
  profile.model.rms_error_ms = 0.3;
  profile.model.r2 = 0.97;
  profile.safety_factor = 1.3;
  profile.renderer = "seed";
  profile.validation = {{"views", 100}, {"quantiles", {0.9, 1.1, 1.25}}};
  fs::create_directories(out / "cost_profile");
  gpu::saveCostProfile(profile, (out / "cost_profile" / "profile.json").string());

  fs::create_directories(out / "camera_path");
  const Box3 bounds = Box3::fromPoints(Vec3(-100, -100, 0), Vec3(100, 100, 30));
  gen::FlyoverOptions fly;
  fly.frames = 4;
  gen::saveCameraPath(gen::flyover(bounds, fly), (out / "camera_path" / "flyover.json").string());
  gen::OrbitOptions orbit;
  orbit.frames = 3;
  gen::saveCameraPath(gen::orbit(bounds, orbit), (out / "camera_path" / "orbit.json").string());

  fs::create_directories(out / "street_graph");
  gridGraph().save((out / "street_graph" / "grid.streets.json").string());
}

// DEMs through GDAL: the first byte of the DEM target's input chooses the extension (fuzz_dem.cpp: 0 .tif, 1 .png,
// 2 .nc, 3 .asc, 4 .hgt; 0x80 also builds the LOD).
void demSeeds(const fs::path& work, const fs::path& out) {
  GDALAllRegister();
  fs::create_directories(work);
  const int w = 9, h = 7;
  std::vector<float> heights(size_t(w) * h);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) heights[size_t(j) * w + i] = float(100 + 3 * i + 5 * j + (i * j) % 4);
  heights[10] = -9999.0f;  // one nodata point
  const auto create = [&](const char* driver, const fs::path& path, GDALDataType type, bool geo, bool geographic,
                          char** options) {
    GDALDriverH d = GDALGetDriverByName(driver);
    if (!d) return false;
    // Drivers without Create write through a memory dataset and CreateCopy.
    GDALDriverH mem = GDALGetDriverByName("MEM");
    GDALDatasetH src = GDALCreate(mem, "", w, h, 1, type, nullptr);
    if (geo) {
      double gt[6] = {350000.0, 30.0, 0.0, 3800000.0, 0.0, -30.0};
      if (geographic) {
        gt[0] = 7.4;
        gt[1] = 0.001;
        gt[3] = 43.75;
        gt[5] = -0.001;
      }
      GDALSetGeoTransform(src, gt);
      OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
      OSRImportFromEPSG(srs, geographic ? 4326 : 32611);
      char* wkt = nullptr;
      OSRExportToWkt(srs, &wkt);
      GDALSetProjection(src, wkt);
      CPLFree(wkt);
      OSRDestroySpatialReference(srs);
    }
    GDALRasterBandH band = GDALGetRasterBand(src, 1);
    if (type != GDT_UInt16) GDALSetRasterNoDataValue(band, -9999.0);
    std::vector<float> values = heights;
    if (type == GDT_UInt16)
      for (float& v : values) v = v < 0 ? 0 : v;
    if (GDALRasterIO(band, GF_Write, 0, 0, w, h, values.data(), w, h, GDT_Float32, 0, 0) != CE_None) return false;
    GDALDatasetH dst = GDALCreateCopy(d, path.c_str(), src, FALSE, options, nullptr, nullptr);
    GDALClose(src);
    if (!dst) return false;
    GDALClose(dst);
    return true;
  };
  const auto seed = [&](const fs::path& file, uint8_t mode, const std::string& name) {
    if (!fs::exists(file)) return;
    writeSeed(out, name, std::string(1, char(mode)) + readFile(file));
  };
  if (create("GTiff", work / "a.tif", GDT_Int16, true, false, nullptr)) seed(work / "a.tif", 0x00, "int16_utm.tif");
  char** deflate = CSLSetNameValue(nullptr, "COMPRESS", "DEFLATE");
  if (create("GTiff", work / "b.tif", GDT_Float32, true, true, deflate)) seed(work / "b.tif", 0x80, "float_geo_lod.tif");
  CSLDestroy(deflate);
  if (create("PNG", work / "c.png", GDT_UInt16, false, false, nullptr)) seed(work / "c.png", 0x01, "uint16.png");
  if (create("netCDF", work / "d.nc", GDT_Float32, true, false, nullptr)) seed(work / "d.nc", 0x02, "float.nc");
  if (create("AAIGrid", work / "e.asc", GDT_Float32, true, false, nullptr)) seed(work / "e.asc", 0x03, "grid.asc");
}

// The project's test OSM file as PBF (the OSM target's byte 0: bit 0 clear = PBF; 0x02 runs the whole import).
void osmSeeds(const fs::path& work, const fs::path& out, const fs::path& test_data) {
  const fs::path xml = test_data / "geodata" / "small_city.osm";
  const fs::path pbf = work / "small_city.osm.pbf";
  fs::create_directories(work);
  fs::remove(pbf);
  {
    osmium::io::Reader reader(xml.string());
    osmium::io::Header header = reader.header();
    osmium::io::Writer writer(pbf.string(), header, osmium::io::overwrite::allow);
    while (osmium::memory::Buffer buffer = reader.read()) writer(std::move(buffer));
    writer.close();
    reader.close();
  }
  const std::string bytes = readFile(pbf);
  writeSeed(out, "small_city_read.pbf", std::string(1, '\x00') + bytes);
  writeSeed(out, "small_city_import.pbf", std::string(1, '\x02') + bytes);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_seeds OUT_DIR TEST_DATA_DIR\n");
    return 2;
  }
  const fs::path out = argv[1], test_data = argv[2], work = out / ".work";
  try {
    impostorStoreSeeds(work, out / "impostor_store");
    placementSeeds(work, out / "placement_store");
    jsonSeeds(out);
    demSeeds(work / "dem", out / "dem");
    osmSeeds(work / "osm", out / "osm", test_data);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_seeds: %s\n", e.what());
    return 1;
  }
  fs::remove_all(work);
  return 0;
}
