// Sharded bakes: the partition of the view space (Graham's LPT list scheduling over estimated cell work).
#include "farfield/bake/shard.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "farfield/core/error.h"
#include "farfield/store/impostor_store.h"

namespace farfield::bake {

ShardSpec parseShard(const std::string& text, const std::string& what) {
  const size_t slash = text.find('/');
  const auto number = [&](const std::string& part, uint32_t& out) {
    if (part.empty() || part.size() > 9 || !std::all_of(part.begin(), part.end(), [](char c) { return c >= '0' && c <= '9'; }))
      return false;
    out = uint32_t(std::stoul(part));
    return true;
  };
  ShardSpec s;
  if (slash == std::string::npos || !number(text.substr(0, slash), s.index) || !number(text.substr(slash + 1), s.count) ||
      s.count == 0 || s.index >= s.count)
    throw Error(what, "expected K/N with 0 <= K < N (e.g. 0/4 .. 3/4), got '" + text + "'");
  return s;
}

std::vector<double> cellWeights(const urban::CellMap& map, const std::vector<uint32_t>& cells,
                                const extract::PipelineOptions& options) {
  std::vector<double> out;
  out.reserve(cells.size());
  for (uint32_t c : cells) {
    const double length = c < map.cellCount() ? double(map.graph().length(c)) : 0.0;
    double w = 1.0;
    if (options.pvs.spacing > 0.0f) w += std::floor(length / double(options.pvs.spacing)) + 1.0;
    w += options.station_spacing > 0.0f ? std::floor(length / double(options.station_spacing)) + 1.0 : 1.0;
    out.push_back(w);
  }
  return out;
}

std::vector<std::vector<uint32_t>> partitionCells(const std::vector<uint32_t>& cells,
                                                  const std::vector<double>& weights, uint32_t count,
                                                  const std::vector<uint32_t>& groups) {
  if (count == 0) throw Error("--shard", "the number of shards must be at least 1");
  if (weights.size() != cells.size() || (!groups.empty() && groups.size() != cells.size()))
    throw Error("partition", std::to_string(cells.size()) + " cells but " + std::to_string(weights.size()) +
                                 " weights and " + std::to_string(groups.size()) + " groups");
  // Units: the cells of one group (each cell alone without groups), with their summed weight and smallest id.
  struct Unit {
    double weight = 0.0;
    uint32_t first = 0xffffffffu;
    std::vector<uint32_t> cells;
  };
  std::map<uint64_t, Unit> by_group;
  for (size_t k = 0; k < cells.size(); ++k) {
    Unit& u = by_group[groups.empty() ? uint64_t(cells[k]) : (uint64_t(1) << 32) | groups[k]];
    u.weight += weights[k];
    u.first = std::min(u.first, cells[k]);
    u.cells.push_back(cells[k]);
  }
  std::vector<Unit> units;
  for (auto& [key, u] : by_group) units.push_back(std::move(u));
  // Heaviest first; equal weights by smallest id, so that the input's order does not matter.
  std::sort(units.begin(), units.end(), [](const Unit& a, const Unit& b) {
    if (a.weight != b.weight) return a.weight > b.weight;
    return a.first < b.first;
  });
  std::vector<std::vector<uint32_t>> parts(count);
  std::vector<double> load(count, 0.0);
  for (const Unit& u : units) {
    const size_t lightest = size_t(std::min_element(load.begin(), load.end()) - load.begin());  // first of equals
    parts[lightest].insert(parts[lightest].end(), u.cells.begin(), u.cells.end());
    load[lightest] += u.weight;
  }
  for (std::vector<uint32_t>& p : parts) std::sort(p.begin(), p.end());
  return parts;
}

uint32_t sceneDigest(const scene::Scene& scene) {
  std::string bytes;
  const auto put = [&](const void* p, size_t n) { bytes.append(static_cast<const char*>(p), n); };
  const uint64_t triangles = scene.triangleCount();
  put(&triangles, sizeof(triangles));
  for (const scene::Object& o : scene.objects) {
    bytes += o.name;
    bytes += '\0';
    put(&o.world_bounds.lo, sizeof(o.world_bounds.lo));
    put(&o.world_bounds.hi, sizeof(o.world_bounds.hi));
    if (!o.footprint.empty()) put(o.footprint.data(), o.footprint.size() * sizeof(Vec2));
  }
  return store::fileCheck(bytes).crc32;
}

}  // namespace farfield::bake
