// OpenStreetMap input through libosmium. Two passes, as osmium's relation managers expect: the first reads the
// building multipolygon relations, the second the nodes (into a location index) and the ways, feeding closed
// building ways and the members of those relations to osmium's area assembler (MultipolygonManager).
//
// Counting skips per reason needs more than the manager gives, because it drops some ways silently (fewer than
// four nodes, open ways, invalid end locations) and swallows assembly failures. So:
//  - a pre-check handler sees every building way first and classifies the ones the manager would drop;
//  - the assembler runs with create_empty_areas, so a failed way still yields an (empty) area and is counted;
//  - a problem reporter records, per object, what the assembler complained about, which names the reason of a
//    failure (missing nodes, ring not closed, self-intersection, overlapping segments);
//  - relations accepted in the first pass but never output are either incomplete (member ways missing from the
//    extract, listed by the manager) or failed with the recorded reason.
#include "farfield/geodata/osm_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

// GCC 12 reports a false -Wstringop-overread inside osmium's AreaBuilder (strlen of an object's user name after
// inlining); the warning is about osmium's header, not this file.
#pragma GCC diagnostic ignored "-Wstringop-overread"
#include <osmium/area/assembler.hpp>
#include <osmium/area/multipolygon_manager.hpp>
#include <osmium/area/problem_reporter.hpp>
#include <osmium/handler.hpp>
#include <osmium/handler/node_locations_for_ways.hpp>
#include <osmium/index/map/flex_mem.hpp>
#include <osmium/io/any_input.hpp>
#include <osmium/osm/area.hpp>
#include <osmium/relations/manager_util.hpp>
#include <osmium/tags/tags_filter.hpp>
#include <osmium/visitor.hpp>

#include "farfield/core/error.h"
#include "farfield/core/progress.h"

namespace farfield::geodata {

namespace {

// Skip reasons (printed as they are).
constexpr const char* kMissingNodes = "missing nodes";
constexpr const char* kUnclosedRing = "unclosed ring";
constexpr const char* kTooFewNodes = "fewer than 3 distinct nodes";
constexpr const char* kSelfIntersecting = "self-intersecting footprint";
constexpr const char* kOverlapping = "overlapping or duplicate segments";
constexpr const char* kMissingMembers = "relation members missing from the file";
constexpr const char* kAssemblyFailed = "area assembly failed (other)";

bool isBuildingValue(const char* v) { return v != nullptr && std::strcmp(v, "no") != 0; }

// building=* (not "no") or building:part=* (not "no").
bool isBuildingTags(const osmium::TagList& tags, bool* is_part = nullptr) {
  const bool building = isBuildingValue(tags.get_value_by_key("building"));
  const bool part = isBuildingValue(tags.get_value_by_key("building:part"));
  if (is_part) *is_part = !building && part;
  return building || part;
}

uint64_t objectKey(bool relation, int64_t id) { return (uint64_t(relation) << 63) ^ uint64_t(id); }

// Records what the assembler reports for each object; the first fatal reason names a failure.
class SkipReporter : public osmium::area::ProblemReporter {
 public:
  std::unordered_map<uint64_t, std::string> reasons;

  void report_invalid_location(osmium::object_id_type, osmium::object_id_type) override { note(kMissingNodes, 0); }
  void report_ring_not_closed(const osmium::NodeRef&, const osmium::Way*) override { note(kUnclosedRing, 1); }
  void report_intersection(osmium::object_id_type, osmium::Location, osmium::Location, osmium::object_id_type,
                           osmium::Location, osmium::Location, osmium::Location) override {
    note(kSelfIntersecting, 2);
  }
  void report_duplicate_segment(const osmium::NodeRef&, const osmium::NodeRef&) override { note(kOverlapping, 3); }
  void report_overlapping_segment(const osmium::NodeRef&, const osmium::NodeRef&) override { note(kOverlapping, 3); }

 private:
  std::unordered_map<uint64_t, int> priority_;
  void note(const char* reason, int priority) {
    const uint64_t key = objectKey(m_object_type == osmium::item_type::relation, m_object_id);
    auto it = priority_.find(key);
    if (it == priority_.end() || priority < it->second) {
      priority_[key] = priority;
      reasons[key] = reason;
    }
  }
};

struct Collector {
  const OsmReadOptions& options;
  OsmData& data;
  std::unordered_map<int64_t, const char*> way_skips;  // building ways the pre-check rejected
  std::unordered_set<uint64_t> output;                 // objects that produced a non-empty area
  std::unordered_map<uint64_t, bool> failed;            // objects that produced an empty area (value: relation)
  std::unordered_set<std::string> highway_kinds;

  // Roof height from roof:height, else roof:levels.
  double roofHeight(const osmium::TagList& tags) const {
    if (const char* v = tags.get_value_by_key("roof:height"))
      if (auto h = parseLength(v)) return *h;
    if (const char* v = tags.get_value_by_key("roof:levels"))
      if (auto l = parseLevels(v)) return *l * options.heights.level_height;
    return 0.0;
  }

  void area(const osmium::Area& a) {
    bool is_part = false;
    if (!isBuildingTags(a.tags(), &is_part)) return;
    const bool relation = !a.from_way();
    const int64_t id = a.orig_id();
    OsmBuilding b;
    b.id = id;
    b.from_relation = relation;
    b.is_part = is_part;
    for (const osmium::OuterRing& outer : a.outer_rings()) {
      LonLatPolygon poly;
      auto add_ring = [&](const osmium::NodeRefList& ring) {
        std::vector<DVec2> pts;
        pts.reserve(ring.size());
        for (const osmium::NodeRef& nr : ring) pts.emplace_back(nr.location().lon(), nr.location().lat());
        if (pts.size() > 1 && pts.front() == pts.back()) pts.pop_back();
        poly.push_back(std::move(pts));
      };
      add_ring(outer);
      for (const osmium::InnerRing& inner : a.inner_rings(outer)) add_ring(inner);
      b.polygons.push_back(std::move(poly));
    }
    if (b.polygons.empty()) {
      failed[objectKey(relation, id)] = relation;
      return;
    }
    output.insert(objectKey(relation, id));
    if (options.bbox) {
      const DVec2 p = b.polygons[0][0][0];
      if (!options.bbox->contains(p.x, p.y)) {
        ++data.outside_bbox;
        return;
      }
    }
    const osmium::TagList& tags = a.tags();
    b.height = buildingHeight([&](const char* key) { return tags.get_value_by_key(key); }, options.heights);
    if (const char* rs = tags.get_value_by_key("roof:shape")) b.roof_shape = rs;
    b.roof_height = roofHeight(tags);
    data.buildings.push_back(std::move(b));
  }
};

// Pass 2 handler in front of the manager: counts, pre-checks building ways, collects highways.
class WayHandler : public osmium::handler::Handler {
 public:
  explicit WayHandler(Collector& c) : c_(c) {}

  void node(const osmium::Node&) { ++c_.data.nodes; }
  void relation(const osmium::Relation&) { ++c_.data.relations; }

  void way(const osmium::Way& way) {
    ++c_.data.ways;
    const osmium::TagList& tags = way.tags();
    if (isBuildingTags(tags)) precheckBuilding(way);
    if (const char* hw = tags.get_value_by_key("highway")) highway(way, hw);
  }

 private:
  Collector& c_;

  void precheckBuilding(const osmium::Way& way) {
    const osmium::WayNodeList& nodes = way.nodes();
    // Ways that are members of a building relation only carry their own building tag rarely; a way's own tag
    // makes it a building of its own, so it is checked like any other.
    const char* reason = nullptr;
    bool missing = false;
    for (const osmium::NodeRef& nr : nodes)
      if (!nr.location().valid()) missing = true;
    if (nodes.empty() || missing) {
      reason = kMissingNodes;
    } else if (!nodes.ends_have_same_location()) {
      reason = kUnclosedRing;
    } else if (nodes.size() <= 3) {
      reason = kTooFewNodes;
    } else if (way.tags().has_tag("area", "no")) {
      reason = kUnclosedRing;  // explicitly not an area
    }
    if (reason) c_.way_skips[way.id()] = reason;
  }

  void highway(const osmium::Way& way, const char* kind) {
    if (c_.highway_kinds.count(kind) == 0) return;
    const osmium::TagList& tags = way.tags();
    if (tags.has_tag("area", "yes")) return;  // pedestrian squares: areas, not streets
    if (!c_.options.include_tunnels) {
      const char* tunnel = tags.get_value_by_key("tunnel");
      if (tunnel && std::strcmp(tunnel, "no") != 0 && std::strcmp(tunnel, "building_passage") != 0) return;
    }
    const HighwayClass* cls = findHighwayClass(kind);
    float width = cls ? cls->width : 10.0f;
    if (const char* w = tags.get_value_by_key("width"))
      if (auto v = parseLength(w); v && *v >= 2.0 && *v <= 80.0) width = float(*v);
    ++c_.data.highway_ways;
    OsmHighway run;
    run.id = way.id();
    run.kind = kind;
    run.width = width;
    run.street_class = cls ? cls->street_class : 1;
    bool had_missing = false;
    auto flush = [&] {
      if (run.points.size() >= 2) c_.data.highways.push_back(run);
      run.points.clear();
    };
    const auto& box = c_.options.bbox;
    DVec2 prev(0.0);
    bool prev_valid = false, prev_inside = false;
    for (const osmium::NodeRef& nr : way.nodes()) {
      if (!nr.location().valid()) {
        had_missing = true;
        flush();
        prev_valid = false;
        continue;
      }
      const DVec2 p(nr.location().lon(), nr.location().lat());
      const bool inside = !box || box->contains(p.x, p.y);
      if (box && prev_valid && !prev_inside && !inside) {
        // A segment with both ends outside the box ends the run.
        flush();
      }
      if (run.points.empty() && prev_valid && (inside || prev_inside)) run.points.push_back(prev);
      if (inside || (prev_valid && prev_inside)) run.points.push_back(p);
      prev = p;
      prev_valid = true;
      prev_inside = inside;
    }
    flush();
    if (had_missing) ++c_.data.highway_missing_nodes;
  }
};

// Pass 1 helper: the building relations the manager will take (same test as MultipolygonManager::new_relation).
class RelationCounter : public osmium::handler::Handler {
 public:
  std::unordered_set<int64_t> ids;
  void relation(const osmium::Relation& r) {
    const char* type = r.tags().get_value_by_key("type");
    if (!type || (std::strcmp(type, "multipolygon") != 0 && std::strcmp(type, "boundary") != 0)) return;
    if (!isBuildingTags(r.tags())) return;
    for (const auto& m : r.members())
      if (m.type() == osmium::item_type::way) {
        ids.insert(r.id());
        return;
      }
  }
};

std::string lowerExtension(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return name;
}

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// osmium picks the format from the file name; names it does not know are sniffed (XML starts with '<').
osmium::io::File osmFile(const std::string& path) {
  const std::string name = lowerExtension(path);
  for (const char* known : {".osm.pbf", ".pbf", ".osm", ".osm.gz", ".osm.bz2", ".osc", ".osc.gz", ".osc.bz2"})
    if (endsWith(name, known)) return osmium::io::File(path);
  std::ifstream in(path, std::ios::binary);
  char first = 0;
  while (in.get(first) && std::isspace(static_cast<unsigned char>(first))) {
  }
  return osmium::io::File(path, first == '<' ? "osm" : "pbf");
}

}  // namespace

LonLatBox parseLonLatBox(const std::string& option, const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const double d = std::strtod(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0' || !std::isfinite(d))
      throw Error(option, "'" + text + "': expected minlon,minlat,maxlon,maxlat (four numbers, degrees)");
    v.push_back(d);
  }
  if (v.size() != 4)
    throw Error(option, "'" + text + "': expected minlon,minlat,maxlon,maxlat (four numbers, degrees)");
  LonLatBox b{v[0], v[1], v[2], v[3]};
  if (b.min_lon < -180.0 || b.max_lon > 180.0 || b.min_lat < -90.0 || b.max_lat > 90.0)
    throw Error(option, "'" + text + "': longitudes must lie in -180..180 and latitudes in -90..90");
  if (!(b.min_lon < b.max_lon) || !(b.min_lat < b.max_lat))
    throw Error(option, "'" + text + "': the minimum must be below the maximum (minlon,minlat,maxlon,maxlat)");
  return b;
}

OsmData readOsm(const std::string& path, const OsmReadOptions& options) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(path, "no such file");
  const uint64_t file_size = std::filesystem::file_size(path, ec);
  if (ec || file_size == 0) throw Error(path, "empty or unreadable file");

  OsmData data;
  Collector collector{options, data, {}, {}, {}, {}};
  for (const std::string& h : options.highways) collector.highway_kinds.insert(h);

  SkipReporter reporter;
  osmium::area::Assembler::config_type config;
  config.problem_reporter = &reporter;
  config.create_empty_areas = true;
  osmium::TagsFilter filter{false};
  filter.add_rule(true, osmium::TagMatcher{"building"});
  filter.add_rule(true, osmium::TagMatcher{"building:part"});
  osmium::area::MultipolygonManager<osmium::area::Assembler> manager{config, filter};
  RelationCounter relations;

  osmium::io::File file = osmFile(path);
  Progress progress("read " + std::filesystem::path(path).filename().string(), 2 * file_size);

  // Pass 1: relations.
  std::string pass1_error;
  try {
    osmium::io::Reader reader{file, osmium::osm_entity_bits::relation};
    uint64_t last = 0;
    while (osmium::memory::Buffer buffer = reader.read()) {
      osmium::apply(buffer, manager, relations);
      const uint64_t off = std::min<uint64_t>(reader.offset(), file_size);
      if (off > last) progress.advance(off - last), last = off;
    }
    reader.close();
    if (last < file_size) progress.advance(file_size - last);
  } catch (const std::exception& e) {
    pass1_error = e.what();
  }
  manager.prepare_for_lookup();

  // Pass 2: nodes, ways, relations (for counting); areas come out of the manager's callback.
  using Index = osmium::index::map::FlexMem<osmium::unsigned_object_id_type, osmium::Location>;
  Index positive_ids, negative_ids;
  osmium::handler::NodeLocationsForWays<Index, Index> locations{positive_ids, negative_ids};
  locations.ignore_errors();
  WayHandler ways(collector);
  auto area_handler = [&](osmium::memory::Buffer&& buffer) {
    for (const osmium::Area& a : buffer.select<osmium::Area>()) collector.area(a);
  };
  std::string pass2_error;
  try {
    osmium::io::Reader reader{file, osmium::osm_entity_bits::node | osmium::osm_entity_bits::way |
                                        osmium::osm_entity_bits::relation};
    uint64_t last = 0;
    while (osmium::memory::Buffer buffer = reader.read()) {
      osmium::apply(buffer, locations, ways, manager.handler(area_handler));
      const uint64_t off = std::min<uint64_t>(reader.offset(), file_size);
      if (off > last) progress.advance(off - last), last = off;
    }
    reader.close();
  } catch (const std::exception& e) {
    pass2_error = e.what();
  }
  // Areas still buffered in the manager (flushes happen every so often during the pass).
  try {
    manager.handler(area_handler).flush();
  } catch (const std::exception& e) {
    if (pass2_error.empty()) pass2_error = e.what();
  }
  progress.finish();
  data.read_error = !pass2_error.empty() ? pass2_error : pass1_error;
  if (data.read_error.find("out of order") != std::string::npos)
    data.read_error += " (the file must be sorted: nodes, then ways, then relations, each by id, as `osmium sort` "
                       "writes it)";

  // Skips of closed-way buildings: pre-check reasons first, then empty areas with the reporter's reason.
  for (const auto& [id, reason] : collector.way_skips)
    if (!collector.output.count(objectKey(false, id))) ++data.skipped[reason];
  for (const auto& [key, relation] : collector.failed) {
    if (collector.output.count(key)) continue;
    if (!relation && collector.way_skips.count(int64_t(key))) continue;  // counted above
    auto it = reporter.reasons.find(key);
    ++data.skipped[it != reporter.reasons.end() ? it->second : kAssemblyFailed];
  }
  // Relations that never came out: incomplete (members missing) or failed before producing an area.
  std::unordered_set<int64_t> incomplete;
  manager.for_each_incomplete_relation([&](const osmium::relations::RelationHandle& handle) {
    incomplete.insert(handle->id());
  });
  for (int64_t id : relations.ids) {
    const uint64_t key = objectKey(true, id);
    if (collector.output.count(key) || collector.failed.count(key)) continue;
    if (incomplete.count(id)) {
      ++data.skipped[kMissingMembers];
    } else {
      auto it = reporter.reasons.find(key);
      ++data.skipped[it != reporter.reasons.end() ? it->second : kAssemblyFailed];
    }
  }

  if (data.buildings.empty() && data.highways.empty()) {
    if (!data.read_error.empty())
      throw Error(path, "cannot read OSM data: " + data.read_error + " (after " + std::to_string(data.nodes) +
                            " nodes, " + std::to_string(data.ways) + " ways, " + std::to_string(data.relations) +
                            " relations, no building or highway among them)");
    std::string what = "no buildings or highways";
    if (options.bbox) what += " inside the --bbox";
    size_t skipped = 0;
    for (const auto& [reason, n] : data.skipped) skipped += n;
    if (skipped > 0) what += " (" + std::to_string(skipped) + " buildings skipped as malformed)";
    throw Error(path, what + ": nothing to import");
  }
  return data;
}

}  // namespace farfield::geodata
