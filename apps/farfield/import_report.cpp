// What `farfield import` prints after an import: counts, skips per reason, warnings, the reference and times.
#include "import_report.h"

#include <cstdio>

#include "farfield/scene/import.h"

namespace farfield::app {
namespace {

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

}  // namespace

void printOsmReport(const ImportRun& run, const geodata::OsmCity& c, const geodata::OsmImportOptions& options,
                    const std::string& objects) {
  const geodata::OsmImportStats& st = c.stats;
  std::printf("input:        %s (%zu nodes, %zu ways, %zu relations)\n", run.input.c_str(), st.nodes, st.ways,
              st.relations);
  if (!st.read_error.empty()) std::printf("warning:      file ends early or is corrupt: %s\n", st.read_error.c_str());
  std::printf("buildings:    %zu imported, %zu building:part areas (%zu outlines drawn as their parts)\n",
              st.buildings, st.parts, st.outlines_replaced);
  std::printf("heights:      %zu with neither height nor levels got the default %.1f m; %zu unreadable tags\n",
              st.default_height_used, double(options.read.heights.default_height), st.bad_height_tags);
  printSkips(st.skipped, st.skippedTotal(), "buildings");
  if (st.dropped_rings) std::printf("  (and %zu degenerate rings dropped from buildings kept)\n", st.dropped_rings);
  if (options.read.bbox) std::printf("outside bbox: %zu buildings\n", st.outside_bbox);
  std::printf("streets:      %zu highway ways -> %zu junctions, %zu streets, %zu components (%zu crossings split, "
              "%zu points merged, %zu snap rounds)\n",
              st.highway_ways, c.city.streets.junctionCount(), c.city.streets.streetCount(),
              c.city.streets.componentCount(), st.streets.crossings, st.streets.merged_points, st.streets.rounds);
  if (st.streets.unresolved) std::printf("  %zu street segments dropped (could not be made planar)\n", st.streets.unresolved);
  std::printf("blocks:       %zu; %zu buildings in no block\n", c.city.streets.blockCount(), st.outside_blocks);
  std::printf("scene:        %zu objects (%s), %llu triangles\n", c.city.scene.objects.size(), objects.c_str(),
              (unsigned long long)c.city.scene.triangleCount());
  printReference(c.reference);
  std::printf("time:         %.2f s (read %.2f, footprints and meshes %.2f, streets %.2f, blocks %.2f, write %.2f)\n",
              run.total_s, st.read_s, st.build_s, st.streets_s, st.assign_s, run.write_s);
  std::printf("wrote %s, %s, %s\n", run.output.c_str(), run.streets_path.c_str(),
              geodata::geoReferencePathFor(run.output).c_str());
}

void printCityJsonReport(const ImportRun& run, const geodata::CityJsonScene& c) {
  const geodata::CityJsonStats& st = c.stats;
  std::printf("input:        %s (CityJSON %s, %zu city objects, %zu vertices%s)\n", run.input.c_str(),
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
  std::printf("time:         %.2f s (read %.2f, triangulate %.2f, write %.2f)\n", run.total_s, st.read_s,
              st.build_s, run.write_s);
  std::printf("wrote %s, %s\n", run.output.c_str(), geodata::geoReferencePathFor(run.output).c_str());
}

void printCityGmlReport(const ImportRun& run, const geodata::CityGmlScene& c) {
  const geodata::CityGmlStats& st = c.stats;
  const bool streets = c.city.streets.streetCount() > 0;
  std::printf("input:        %s (CityGML %s, %zu city objects, CRS %s)\n", run.input.c_str(),
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
  std::printf("time:         %.2f s (read %.2f, triangulate %.2f, streets %.2f, write %.2f)\n", run.total_s,
              st.read_s, st.build_s, st.streets_s, run.write_s);
  std::printf("wrote %s%s%s, %s\n", run.output.c_str(), streets ? ", " : "", streets ? run.streets_path.c_str() : "",
              geodata::geoReferencePathFor(run.output).c_str());
}

}  // namespace farfield::app
