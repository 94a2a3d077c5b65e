// Decoret et al. 1999, "Multi-layered impostors for accelerated rendering", section 4.2: grouping into layers.
#include "farfield/urban/layering.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "farfield/core/error.h"

namespace farfield::urban {

namespace {

double area(const Box2& box) {
  if (box.empty()) return 0.0;
  return double(box.hi.x - box.lo.x) * double(box.hi.y - box.lo.y);
}

Box2 merged(Box2 box, const Box2& other) {
  box.expand(other);
  return box;
}

}  // namespace

double layerThreshold(double error_px, double fov_x, int image_width) {
  if (!(error_px >= 0.0) || !std::isfinite(error_px))
    throw Error("layer threshold", "pixel error must be a finite number >= 0, got " + std::to_string(error_px));
  if (!(fov_x > 0.0 && fov_x < kPi))
    throw Error("layer threshold", "horizontal field of view must be in (0, pi) radians, got " + std::to_string(fov_x));
  if (image_width <= 0)
    throw Error("layer threshold", "image width must be positive, got " + std::to_string(image_width));
  // One pixel covers about fov_x / width radians (exactly at the image centre of a pinhole camera it is a little
  // less; the edges a little more), so error_px pixels of relative motion is this angle.
  return error_px * fov_x / double(image_width);
}

// The paper colours the graph heuristically: the minimum number of layers is a graph-colouring problem, NP-complete
// in general, and the greedy placement runs in O(objects * layers + edges).
//
// Order: nearest first. The nearest objects take part in the strongest visibility events (parallax grows as the
// inverse of distance, and the near objects are the occluders), so placing them first makes them open the layers,
// and the farther objects, whose mutual weights are small, then fill the layers with the fewest conflicts.
// It also makes the first layers the front-most ones, which the dynamic updates of section 5.5 convert first.
//
// Choice among accepting layers: the paper picks the layer whose bounding box including the new object has the
// smallest area (objects close together in the image need a smaller texture for a given sampling rate); the
// default here minimises the growth of that box instead, which prefers the layer the object already sits in or
// next to over a small layer elsewhere that the object would stretch across the city. Both are available.
Layering layerObjects(const EventGraph& graph, std::span<const EventObject> objects, const CellSegment& cell,
                      const LayeringOptions& options) {
  if (graph.objectCount() != objects.size())
    throw Error("layering", "the event graph has " + std::to_string(graph.objectCount()) + " objects but " +
                                std::to_string(objects.size()) + " footprints were given");
  if (!(options.threshold >= 0.0) || !std::isfinite(options.threshold))
    throw Error("layering", "threshold T must be a finite number >= 0 radians");
  constexpr uint32_t kUnplaced = 0xffffffffu;
  const size_t n = objects.size();

  Layering out;
  out.layer_of.assign(n, kUnplaced);
  std::vector<Box2> boxes(n);
  for (size_t i = 0; i < n; ++i) boxes[i] = polygonBounds(objects[i].footprint);

  out.order.resize(n);
  std::iota(out.order.begin(), out.order.end(), 0u);
  if (options.order == LayerOrder::NearestFirst) {
    std::vector<double> distance(n);
    for (size_t i = 0; i < n; ++i) distance[i] = distanceToCell(objects[i].footprint, cell);
    std::stable_sort(out.order.begin(), out.order.end(),
                     [&](uint32_t a, uint32_t b) { return distance[a] < distance[b]; });
  }

  // Per layer, the heaviest edge from the current object to a member; reset after each object through `touched`.
  std::vector<double> heaviest;
  std::vector<uint32_t> touched;
  for (uint32_t object : out.order) {
    for (const WeightEdge& e : graph.edges(object)) {
      const uint32_t layer = out.layer_of[e.to];
      if (layer == kUnplaced) continue;
      if (heaviest[layer] == 0.0) touched.push_back(layer);
      heaviest[layer] = std::max(heaviest[layer], e.weight);
    }
    uint32_t best = kUnplaced;
    double best_key = 0.0, best_area = 0.0;
    for (uint32_t layer = 0; layer < out.layers.size(); ++layer) {
      if (heaviest[layer] > options.threshold) continue;
      const double old_area = area(out.bounds[layer]);
      const double new_area = area(merged(out.bounds[layer], boxes[object]));
      const double key = options.choice == LayerChoice::LeastGrowth ? new_area - old_area : new_area;
      if (best == kUnplaced || key < best_key || (key == best_key && new_area < best_area)) {
        best = layer;
        best_key = key;
        best_area = new_area;
      }
    }
    for (uint32_t layer : touched) heaviest[layer] = 0.0;
    touched.clear();
    if (best == kUnplaced) {
      best = uint32_t(out.layers.size());
      out.layers.emplace_back();
      out.bounds.emplace_back();
      heaviest.push_back(0.0);
    }
    out.layers[best].push_back(object);
    out.bounds[best].expand(boxes[object]);
    out.layer_of[object] = best;
  }
  return out;
}

}  // namespace farfield::urban
