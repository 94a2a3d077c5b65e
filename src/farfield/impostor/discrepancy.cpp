// Depth discrepancy image and chain following (Sillion et al. 1997, section 4.2, step 4, "Identification of
// important features").
//
// Why a relative metric by default: the captured depth of a surface seen at a grazing angle changes from pixel to
// pixel in proportion to its distance, so an absolute threshold in metres either floods the far half of the image
// with discrepancy pixels or misses real steps nearby. The ratio |a - b| / min(a, b) treats a 10 m gap at 100 m
// like a 100 m gap at 1 km; both move by about the same amount on screen when the viewer moves.
//
// Why two chains per step: both sides of a step are above the threshold. Following only pixels that are depth
// continuous with the current one keeps the chain on one surface, so the near side and the far side are traced
// separately and each gets its own constraint polyline at its pixel centres. The triangles between the two
// polylines are then the only ones that span the step, one pixel wide, and each polyline's vertices take the depth
// of their own surface.
#include "farfield/impostor/discrepancy.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "farfield/core/error.h"
#include "farfield/core/douglas_peucker.h"

namespace farfield::impostor {
namespace {

constexpr int kNx[8] = {1, 1, 0, -1, -1, -1, 0, 1};
constexpr int kNy[8] = {0, 1, 1, 1, 0, -1, -1, -1};

}  // namespace

image::DepthImage linearizeDepth(const image::DepthImage& window_depth, const image::Image<uint8_t>& mask,
                                 const Camera& camera) {
  const int w = window_depth.width(), h = window_depth.height();
  if (mask.width() != w || mask.height() != h)
    throw Error("impostor capture", "depth image and data mask differ in size");
  if (camera.width != w || camera.height != h)
    throw Error("impostor capture", "depth image is " + std::to_string(w) + "x" + std::to_string(h) +
                                        " but the camera is " + std::to_string(camera.width) + "x" +
                                        std::to_string(camera.height));
  image::DepthImage linear(w, h, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!mask.at(x, y)) continue;
      const float z = window_depth.at(x, y);
      if (!(z > 0.0f && z <= 1.0f))
        throw Error("impostor capture", "depth image pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                                            "): window depth " + std::to_string(z) + " is not in (0, 1]");
      linear.at(x, y) = camera.linearDepth(z);
    }
  return linear;
}

float pairDiscrepancy(float a, float b, DiscrepancyMetric metric) {
  const float d = std::abs(a - b);
  if (metric == DiscrepancyMetric::Absolute) return d;
  const float m = std::min(a, b);
  return m > 0.0f ? d / m : std::numeric_limits<float>::infinity();
}

image::Image<float> discrepancyImage(const image::DepthImage& linear_depth, const image::Image<uint8_t>& mask,
                                     DiscrepancyMetric metric) {
  const int w = linear_depth.width(), h = linear_depth.height();
  image::Image<float> out(w, h, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!mask.at(x, y)) continue;
      float best = 0.0f;
      for (int k = 0; k < 8; ++k) {
        const int nx = x + kNx[k], ny = y + kNy[k];
        if (nx < 0 || ny < 0 || nx >= w || ny >= h || !mask.at(nx, ny)) continue;
        best = std::max(best, pairDiscrepancy(linear_depth.at(x, y), linear_depth.at(nx, ny), metric));
      }
      out.at(x, y) = best;
    }
  return out;
}

size_t DiscrepancyLines::segmentCount() const {
  size_t n = 0;
  for (const DiscrepancyChain& c : chains)
    if (c.polyline.size() >= 2) n += c.polyline.size() - 1;
  return n;
}

DiscrepancyLines extractDiscrepancyLines(const image::DepthImage& linear_depth, const image::Image<uint8_t>& mask,
                                         const DiscrepancyOptions& options) {
  const int w = linear_depth.width(), h = linear_depth.height();
  if (mask.width() != w || mask.height() != h)
    throw Error("impostor capture", "depth image and data mask differ in size");
  DiscrepancyLines result;
  result.discrepancy = discrepancyImage(linear_depth, mask, options.metric);
  const image::Image<float>& disc = result.discrepancy;

  auto data = [&](int x, int y) { return x >= 0 && y >= 0 && x < w && y < h && mask.at(x, y) != 0; };
  auto onContour = [&](int x, int y) {
    return !data(x - 1, y) || !data(x + 1, y) || !data(x, y - 1) || !data(x, y + 1);
  };

  // Candidates in decreasing discrepancy (step 1 of the loop), ties in scan order.
  std::vector<uint32_t> order;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (mask.at(x, y) && disc.at(x, y) >= options.threshold) order.push_back(uint32_t(y * w + x));
  result.pixels_above = order.size();
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return disc.pixels()[a] > disc.pixels()[b]; });

  image::Image<uint8_t> used(w, h, 0);
  // Step 2: one direction of the chain from `start`; appends the pixels visited (not `start`).
  auto follow = [&](IVec2 start, std::vector<IVec2>& out) {
    IVec2 cur = start;
    int prev_dir = -1;
    while (true) {
      int best = -1;
      int best_turn = 9;
      float best_disc = -1.0f;
      const float depth = linear_depth.at(cur.x, cur.y);
      for (int k = 0; k < 8; ++k) {
        const int nx = cur.x + kNx[k], ny = cur.y + kNy[k];
        if (!data(nx, ny) || used.at(nx, ny) || disc.at(nx, ny) < options.threshold) continue;
        if (!depthContinuous(depth, linear_depth.at(nx, ny), options)) continue;  // across the step
        // Straightest continuation first (turn in 45-degree steps), then the larger discrepancy.
        const int turn = prev_dir < 0 ? 0 : std::min((k - prev_dir + 8) % 8, (prev_dir - k + 8) % 8);
        const float d = disc.at(nx, ny);
        if (turn < best_turn || (turn == best_turn && d > best_disc)) {
          best = k;
          best_turn = turn;
          best_disc = d;
        }
      }
      if (best < 0) return;
      cur += IVec2(kNx[best], kNy[best]);
      used.at(cur.x, cur.y) = 1;
      out.push_back(cur);
      prev_dir = best;
      if (onContour(cur.x, cur.y)) return;  // blocked by the external contour
    }
  };

  for (uint32_t index : order) {
    const IVec2 start(int(index % uint32_t(w)), int(index / uint32_t(w)));
    if (used.at(start.x, start.y)) continue;
    used.at(start.x, start.y) = 1;
    std::vector<IVec2> forward, backward;
    follow(start, forward);
    follow(start, backward);
    DiscrepancyChain chain;
    chain.pixels.assign(backward.rbegin(), backward.rend());
    chain.pixels.push_back(start);
    chain.pixels.insert(chain.pixels.end(), forward.begin(), forward.end());
    if (chain.pixels.size() < std::max<size_t>(options.min_chain_pixels, 2)) {
      ++result.short_chains;
    } else {
      // Step 3: polygonal approximation through the pixel centres.
      std::vector<DVec2> centres;
      centres.reserve(chain.pixels.size());
      for (const IVec2& p : chain.pixels) centres.push_back(DVec2(p.x + 0.5, p.y + 0.5));
      chain.polyline = simplifyPolyline(centres, options.tolerance_px);
    }
    result.chains.push_back(std::move(chain));
  }
  return result;
}

}  // namespace farfield::impostor
