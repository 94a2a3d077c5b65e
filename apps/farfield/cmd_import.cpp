// farfield import osm FILE.osm.pbf [--bbox minlon,minlat,maxlon,maxlat] [--objects blocks|buildings]
//                     [--highways a,b,c] [--tunnels] [--default-height M] [--merge-tolerance M] -o city.glb
// farfield import cityjson FILE.city.json [--max-lod L] [--no-ground] [--no-other] [--theme T] -o city.glb
// farfield import citygml FILE.gml [--max-lod L] [--no-ground] [--no-other] [--theme T] [--objects blocks|buildings]
//                         -o city.glb
// farfield import FILE -o city.glb   (the format from the extension: .osm.pbf/.osm, .city.json/.json, .gml/.citygml)
// Imports a real city: writes the scene (.glb), the street graph (city.streets.json, when the file has streets) and
// the geographic reference of the local coordinates (city.georef.json); prints what was imported and skipped, per
// reason, and the texture files that were missing (drawn as checkerboards).
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gen/city.h"
#include "farfield/geodata/cityjson_import.h"
#include "farfield/geodata/citygml_import.h"
#include "farfield/geodata/osm_import.h"
#include "farfield/geodata/projection.h"
#include "farfield/scene/export_gltf.h"

namespace farfield::app {
namespace {

struct OsmArgs {
  std::string input, output, bbox, objects = "blocks", highways;
  bool tunnels = false;
  float default_height = 10.0f;
  double merge_tolerance = 0.5;
};

struct CityJsonArgs {
  std::string input, output, theme, objects = "blocks";
  double max_lod = -1.0;
  bool no_ground = false, no_other = false;
};

void printSkips(const std::map<std::string, size_t>& skipped, size_t total, const char* what) {
  std::printf("skipped:      %zu %s\n", total, what);
  for (const auto& [reason, n] : skipped) std::printf("  %-46s %zu\n", reason.c_str(), n);
}

void printReference(const geodata::GeoReference& r) {
  std::printf("origin:       (%.3f, %.3f, %.3f) in %s%s%s (scene + origin = %s coordinates)\n", r.origin.x, r.origin.y,
              r.origin.z, r.crs.c_str(), r.description.empty() ? "" : ", ", r.description.c_str(), r.crs.c_str());
}

void printWarnings(const scene::ImportStats& st) {
  for (const std::string& w : st.warnings()) std::printf("warning:      %s\n", w.c_str());
}

gen::ObjectGrouping parseGrouping(const std::string& objects) {
  if (objects == "blocks") return gen::ObjectGrouping::Blocks;
  if (objects == "buildings") return gen::ObjectGrouping::Buildings;
  throw Error("--objects", "expected 'blocks' or 'buildings', got '" + objects + "'");
}

void writeScene(const scene::Scene& scene, const geodata::GeoReference& reference, const std::string& output,
                double& write_s) {
  ensureParentDirectory(output);
  Stopwatch clock;
  scene::exportGlb(scene, output);
  geodata::saveGeoReference(reference, geodata::geoReferencePathFor(output));
  write_s = clock.seconds();
}

void runOsm(const OsmArgs& args) {
  geodata::OsmImportOptions options;
  if (!args.bbox.empty()) options.read.bbox = geodata::parseLonLatBox("--bbox", args.bbox);
  options.objects = parseGrouping(args.objects);
  if (!args.highways.empty()) options.read.highways = geodata::parseHighwayList("--highways", args.highways);
  options.read.include_tunnels = args.tunnels;
  options.read.heights.default_height = args.default_height;
  options.planarize.merge_tolerance = args.merge_tolerance;

  Stopwatch total;
  const geodata::OsmCity c = geodata::importOsm(args.input, options);
  const geodata::OsmImportStats& st = c.stats;
  double write_s = 0.0;
  writeScene(c.city.scene, c.reference, args.output, write_s);
  const std::string streets_path = gen::streetsPathFor(args.output);
  c.city.streets.save(streets_path);

  std::printf("input:        %s (%zu nodes, %zu ways, %zu relations)\n", args.input.c_str(), st.nodes, st.ways,
              st.relations);
  if (!st.read_error.empty()) std::printf("warning:      file ends early or is corrupt: %s\n", st.read_error.c_str());
  std::printf("buildings:    %zu imported, %zu building:part areas (%zu outlines drawn as their parts)\n",
              st.buildings, st.parts, st.outlines_replaced);
  std::printf("heights:      %zu with neither height nor levels got the default %.1f m; %zu unreadable tags\n",
              st.default_height_used, double(args.default_height), st.bad_height_tags);
  printSkips(st.skipped, st.skippedTotal(), "buildings");
  if (st.dropped_rings) std::printf("  (and %zu degenerate rings dropped from buildings kept)\n", st.dropped_rings);
  if (options.read.bbox) std::printf("outside bbox: %zu buildings\n", st.outside_bbox);
  std::printf("streets:      %zu highway ways -> %zu junctions, %zu streets, %zu components (%zu crossings split, "
              "%zu points merged, %zu snap rounds)\n",
              st.highway_ways, c.city.streets.junctionCount(), c.city.streets.streetCount(),
              c.city.streets.componentCount(), st.streets.crossings, st.streets.merged_points, st.streets.rounds);
  if (st.streets.unresolved) std::printf("  %zu street segments dropped (could not be made planar)\n", st.streets.unresolved);
  std::printf("blocks:       %zu; %zu buildings in no block\n", c.city.streets.blockCount(), st.outside_blocks);
  std::printf("scene:        %zu objects (%s), %llu triangles\n", c.city.scene.objects.size(), args.objects.c_str(),
              (unsigned long long)c.city.scene.triangleCount());
  printReference(c.reference);
  std::printf("time:         %.2f s (read %.2f, footprints and meshes %.2f, streets %.2f, blocks %.2f, write %.2f)\n",
              total.seconds(), st.read_s, st.build_s, st.streets_s, st.assign_s, write_s);
  std::printf("wrote %s, %s, %s\n", args.output.c_str(), streets_path.c_str(),
              geodata::geoReferencePathFor(args.output).c_str());
}

void runCityJson(const CityJsonArgs& args) {
  geodata::CityJsonImportOptions options;
  if (args.max_lod >= 0.0) options.max_lod = args.max_lod;
  options.ground_objects = !args.no_ground;
  options.other_objects = !args.no_other;
  options.theme = args.theme;
  Stopwatch total;
  const geodata::CityJsonScene c = geodata::importCityJson(args.input, options);
  const geodata::CityJsonStats& st = c.stats;
  double write_s = 0.0;
  writeScene(c.scene, c.reference, args.output, write_s);

  std::printf("input:        %s (CityJSON %s, %zu city objects, %zu vertices%s)\n", args.input.c_str(),
              st.version.c_str(), st.city_objects, st.vertices,
              st.bad_vertices ? (", " + std::to_string(st.bad_vertices) + " malformed").c_str() : "");
  std::printf("imported:     %zu buildings (%zu parts), %zu ground objects, %zu other objects\n", st.buildings,
              st.building_parts, st.ground_objects, st.other_objects);
  for (const auto& [type, n] : st.objects_by_type) std::printf("  %-46s %zu\n", type.c_str(), n);
  std::printf("surfaces:     %zu (%zu with semantics, %zu building surfaces classified by normal, %zu holes)\n",
              st.surfaces, st.semantic_surfaces, st.inferred_surfaces, st.holes);
  std::printf("appearance:   %zu textured surfaces (theme '%s'), %zu in material colours (theme '%s'), %zu bad "
              "texture references\n", st.textured_surfaces, st.texture_theme.c_str(), st.material_surfaces,
              st.material_theme.c_str(), st.bad_texture_references);
  printWarnings(st.import);
  printSkips(st.skipped, st.skippedTotal(), "faces/objects");
  std::printf("scene:        %zu objects, %llu triangles\n", c.scene.objects.size(),
              (unsigned long long)c.scene.triangleCount());
  printReference(c.reference);
  std::printf("time:         %.2f s (read %.2f, triangulate %.2f, write %.2f)\n", total.seconds(), st.read_s,
              st.build_s, write_s);
  std::printf("wrote %s, %s\n", args.output.c_str(), geodata::geoReferencePathFor(args.output).c_str());
}

void runCityGml(const CityJsonArgs& args) {
  geodata::CityGmlImportOptions options;
  if (args.max_lod >= 0.0) options.max_lod = unsigned(args.max_lod);
  options.ground_objects = !args.no_ground;
  options.other_objects = !args.no_other;
  options.theme = args.theme;
  options.objects = parseGrouping(args.objects);
  Stopwatch total;
  const geodata::CityGmlScene c = geodata::importCityGml(args.input, options);
  const geodata::CityGmlStats& st = c.stats;
  double write_s = 0.0;
  writeScene(c.city.scene, c.reference, args.output, write_s);
  const bool streets = c.city.streets.streetCount() > 0;
  const std::string streets_path = gen::streetsPathFor(args.output);
  if (streets) c.city.streets.save(streets_path);

  std::printf("input:        %s (CityGML %s, %zu city objects, CRS %s)\n", args.input.c_str(),
              st.version.empty() ? "?" : st.version.c_str(), st.city_objects, st.crs.empty() ? "unknown" : st.crs.c_str());
  std::printf("imported:     %zu buildings (%zu parts), %zu ground objects, %zu other objects\n", st.buildings,
              st.building_parts, st.ground_objects, st.other_objects);
  for (const auto& [type, n] : st.objects_by_type) std::printf("  %-46s %zu\n", type.c_str(), n);
  for (const auto& [lod, n] : st.lods)
    std::printf("  %-46s %zu\n", ("objects drawn at LoD " + std::to_string(lod)).c_str(), n);
  std::printf("surfaces:     %zu (%zu with semantics, %zu building surfaces classified by normal, %zu holes, %zu "
              "shared)\n", st.surfaces, st.semantic_surfaces, st.inferred_surfaces, st.holes, st.shared_polygons);
  std::printf("appearance:   %zu textured surfaces, %zu in material colours (theme '%s'), %zu bad texture "
              "coordinates\n", st.textured_surfaces, st.material_surfaces, st.theme.c_str(), st.bad_texture_coordinates);
  printWarnings(st.import);
  printSkips(st.skipped, st.skippedTotal(), "polygons/objects");
  if (streets)
    std::printf("streets:      %zu road objects (%zu surfaces) -> %zu centre-line segments -> %zu junctions, %zu "
                "streets, %zu blocks; %zu buildings in no block\n", st.road_objects, st.road_polygons,
                st.centre_line_segments, c.city.streets.junctionCount(), c.city.streets.streetCount(),
                c.city.streets.blockCount(), st.outside_blocks);
  else
    std::printf("streets:      none (no transportation surfaces): one object per city object\n");
  std::printf("scene:        %zu objects, %llu triangles\n", c.city.scene.objects.size(),
              (unsigned long long)c.city.scene.triangleCount());
  printReference(c.reference);
  std::printf("time:         %.2f s (read %.2f, triangulate %.2f, streets %.2f, write %.2f)\n", total.seconds(),
              st.read_s, st.build_s, st.streets_s, write_s);
  std::printf("wrote %s%s%s, %s\n", args.output.c_str(), streets ? ", " : "", streets ? streets_path.c_str() : "",
              geodata::geoReferencePathFor(args.output).c_str());
}

// `farfield import FILE -o OUT`: the importer from the file name, with its default options.
void runByExtension(const std::string& input, const std::string& output) {
  if (input.empty()) throw Error("import", "expected a subcommand (osm, cityjson, citygml) or a FILE and -o OUT");
  if (output.empty()) throw Error("import", "-o,--output is required");
  std::string name = input;
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
  auto ends = [&](const std::string& ext) {
    return name.size() >= ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0;
  };
  if (ends(".gml") || ends(".citygml") || ends(".xml")) {
    CityJsonArgs a;
    a.input = input, a.output = output;
    return runCityGml(a);
  }
  if (ends(".json") || ends(".cityjson")) {
    CityJsonArgs a;
    a.input = input, a.output = output;
    return runCityJson(a);
  }
  if (ends(".pbf") || ends(".osm")) {
    OsmArgs a;
    a.input = input, a.output = output;
    return runOsm(a);
  }
  throw Error(input, "unknown city format (expected .osm.pbf, .osm, .city.json, .gml or .citygml; or name the "
                     "format: farfield import osm|cityjson|citygml)");
}

const RegisterCommand reg("import", [](CLI::App& app) {
  auto* cmd = app.add_subcommand("import", "Import a real city: OpenStreetMap (PBF/XML), CityJSON or CityGML.");
  cmd->require_subcommand(0, 1);
  auto any = std::make_shared<std::pair<std::string, std::string>>();
  cmd->add_option("file", any->first, "City file, its format from the extension (.osm.pbf, .city.json, .gml)");
  cmd->add_option("-o,--output", any->second, "Output scene (.glb)");
  cmd->callback([cmd, any] {
    if (cmd->get_subcommands().empty()) runByExtension(any->first, any->second);
  });

  auto osm = std::make_shared<OsmArgs>();
  auto* o = cmd->add_subcommand("osm", "Buildings and streets from an OpenStreetMap file (.osm.pbf, .osm).");
  o->add_option("file", osm->input, "OpenStreetMap file")->required();
  o->add_option("-o,--output", osm->output, "Output scene (.glb); the street graph goes to .streets.json")->required();
  o->add_option("--bbox", osm->bbox, "Only this box: minlon,minlat,maxlon,maxlat (degrees)");
  o->add_option("--objects", osm->objects, "One object per 'blocks' (default) or per 'buildings'");
  o->add_option("--highways", osm->highways,
                "Highway classes that make streets, comma-separated (default: motorway..living_street, links, "
                "pedestrian)");
  o->add_flag("--tunnels", osm->tunnels, "Keep tunnels in the street graph");
  o->add_option("--default-height", osm->default_height, "Height of buildings without height or levels, metres")
      ->check(CLI::Range(1.0, 500.0));
  o->add_option("--merge-tolerance", osm->merge_tolerance, "Street junctions closer than this merge, metres")
      ->check(CLI::Range(0.01, 20.0));
  o->callback([osm] { runOsm(*osm); });

  auto cj = std::make_shared<CityJsonArgs>();
  auto* c = cmd->add_subcommand("cityjson", "Buildings, roads and land use from a CityJSON file (1.0, 1.1, 2.0).");
  c->add_option("file", cj->input, "CityJSON file")->required();
  c->add_option("-o,--output", cj->output, "Output scene (.glb)")->required();
  c->add_option("--max-lod", cj->max_lod, "Use the highest LoD not above this (default: the highest)")
      ->check(CLI::Range(0.0, 4.0));
  c->add_flag("--no-ground", cj->no_ground, "Leave out roads, land use, vegetation, water and terrain");
  c->add_flag("--no-other", cj->no_other, "Leave out bridges, tunnels, furniture and generic objects");
  c->add_option("--theme", cj->theme, "Appearance theme of textures and materials (default: the first)");
  c->callback([cj] { runCityJson(*cj); });

  auto gml = std::make_shared<CityJsonArgs>();
  auto* g = cmd->add_subcommand("citygml", "Buildings, roads and land use from a CityGML 1.0 or 2.0 file (.gml).");
  g->add_option("file", gml->input, "CityGML file")->required();
  g->add_option("-o,--output", gml->output, "Output scene (.glb); the street graph goes to .streets.json")->required();
  g->add_option("--max-lod", gml->max_lod, "Use the highest LoD not above this (default: the highest)")
      ->check(CLI::Range(0.0, 4.0));
  g->add_flag("--no-ground", gml->no_ground, "Leave out roads, land use, vegetation, water and relief");
  g->add_flag("--no-other", gml->no_other, "Leave out bridges, tunnels, furniture and generic objects");
  g->add_option("--theme", gml->theme, "Appearance theme of textures and materials (default: the first)");
  g->add_option("--objects", gml->objects, "With roads: one object per 'blocks' (default) or per 'buildings'");
  g->callback([gml] { runCityGml(*gml); });
});

}  // namespace
}  // namespace farfield::app
