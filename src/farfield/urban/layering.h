// Greedy layering of a cell's distant objects by visibility-event weights (Decoret et al. 1999, section 4.2).
//
// Partitions the objects into layers such that every pair in a layer has w_ij <= T: objects among which only
// negligible visibility events occur share one meshed impostor; objects with larger parallax between them go to
// different layers.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/urban/visibility_events.h"

namespace farfield::urban {

// T in radians from the user's pixel error: error_px pixels of an image image_width pixels wide covering the
// horizontal field of view fov_x (radians): T = error_px * fov_x / image_width. The paper uses 10 px at 512 x 512
// (T = 0.0204 rad with a 60-degree field of view). Throws farfield::Error for a negative or non-finite error, a
// field of view outside (0, pi) or a non-positive width.
double layerThreshold(double error_px, double fov_x, int image_width);

enum class LayerOrder {
  NearestFirst,  // by distance of the footprint to the cell segment, nearest first (ties by index); the default
  Given,         // in the order of the objects
};

enum class LayerChoice {
  LeastGrowth,   // the accepting layer whose 2D bounding box grows least in area (ties: smaller resulting area,
                 // then lower layer index); the default
  SmallestArea,  // the accepting layer whose bounding box including the object has the smallest area (the paper's
                 // wording; ties: lower layer index)
};

struct LayeringOptions {
  double threshold = 0.0204;  // T, radians (10 px over a 60-degree, 512-pixel-wide image)
  LayerOrder order = LayerOrder::NearestFirst;
  LayerChoice choice = LayerChoice::LeastGrowth;
};

struct Layering {
  std::vector<std::vector<uint32_t>> layers;  // object indices per layer, in the order they joined it
  std::vector<uint32_t> layer_of;             // per object: its layer
  std::vector<Box2> bounds;                   // per layer: bounding box of its members' footprints
  std::vector<uint32_t> order;                // the order in which objects were placed
  size_t layerCount() const { return layers.size(); }
};

// Places every object, one at a time in the chosen order: into an existing layer when no edge from the object to a
// member of that layer weighs more than T (choosing among several such layers as `choice` says), else into a new
// layer. `objects` gives the footprints (bounding boxes, distances) and must match graph.objectCount(). Throws
// farfield::Error for a size mismatch or a negative or non-finite threshold.
Layering layerObjects(const EventGraph& graph, std::span<const EventObject> objects, const CellSegment& cell,
                      const LayeringOptions& options = {});

}  // namespace farfield::urban
