// farfield import osm FILE.osm.pbf [--bbox minlon,minlat,maxlon,maxlat] [--objects blocks|buildings]
//                     [--highways a,b,c] [--tunnels] [--default-height M] [--merge-tolerance M] -o city.glb
// farfield import cityjson FILE.city.json [--max-lod L] [--no-ground] [--no-other] [--theme T] -o city.glb
// farfield import citygml FILE.gml [--max-lod L] [--no-ground] [--no-other] [--theme T] [--objects blocks|buildings]
//                         -o city.glb
// farfield import FILE -o city.glb   (the format from the extension: .osm.pbf/.osm, .city.json/.json, .gml/.citygml)
// Imports a real city: writes the scene (.glb), the street graph (city.streets.json, when the file has streets) and
// the geographic reference of the local coordinates (city.georef.json); prints what was imported and skipped, per
// reason, and the texture files that were missing (drawn as checkerboards).
#include <memory>
#include <string>

#include "cli_util.h"
#include "command.h"
#include "import_report.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gen/city.h"
#include "farfield/geodata/city_format.h"
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
  double write_s = 0.0;
  writeScene(c.city.scene, c.reference, args.output, write_s);
  const std::string streets_path = gen::streetsPathFor(args.output);
  c.city.streets.save(streets_path);

  printOsmReport({args.input, args.output, streets_path, write_s, total.seconds()}, c, options, args.objects);
}

void runCityJson(const CityJsonArgs& args) {
  geodata::CityJsonImportOptions options;
  if (args.max_lod >= 0.0) options.max_lod = args.max_lod;
  options.ground_objects = !args.no_ground;
  options.other_objects = !args.no_other;
  options.theme = args.theme;
  Stopwatch total;
  const geodata::CityJsonScene c = geodata::importCityJson(args.input, options);
  double write_s = 0.0;
  writeScene(c.scene, c.reference, args.output, write_s);

  printCityJsonReport({args.input, args.output, "", write_s, total.seconds()}, c);
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
  double write_s = 0.0;
  writeScene(c.city.scene, c.reference, args.output, write_s);
  const bool streets = c.city.streets.streetCount() > 0;
  const std::string streets_path = gen::streetsPathFor(args.output);
  if (streets) c.city.streets.save(streets_path);

  printCityGmlReport({args.input, args.output, streets ? streets_path : "", write_s, total.seconds()}, c);
}

// `farfield import FILE -o OUT`: the importer from the file name, with its default options.
void runByExtension(const std::string& input, const std::string& output) {
  if (input.empty()) throw Error("import", "expected a subcommand (osm, cityjson, citygml) or a FILE and -o OUT");
  if (output.empty()) throw Error("import", "-o,--output is required");
  OsmArgs osm;
  CityJsonArgs city;
  osm.input = city.input = input;
  osm.output = city.output = output;
  switch (geodata::cityFormatFromName(input)) {
    case geodata::CityFormat::Osm: return runOsm(osm);
    case geodata::CityFormat::CityJson: return runCityJson(city);
    case geodata::CityFormat::CityGml: return runCityGml(city);
  }
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
