#include "farfield/gen/crowd.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "farfield/core/error.h"
#include "farfield/gen/street_network.h"

namespace farfield::gen {

namespace {

// HSV-ish tint: a hue, muted so clothes stay plausible.
Vec4 tintOf(std::mt19937_64& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float h = u(rng) * 6.0f, s = 0.15f + 0.35f * u(rng), v = 0.75f + 0.25f * u(rng);
  const float f = h - std::floor(h);
  const float p = v * (1 - s), q = v * (1 - s * f), r = v * (1 - s * (1 - f));
  Vec3 c;
  switch (int(h) % 6) {
    case 0: c = {v, r, p}; break;
    case 1: c = {q, v, p}; break;
    case 2: c = {p, v, r}; break;
    case 3: c = {p, q, v}; break;
    case 4: c = {r, p, v}; break;
    default: c = {v, p, q}; break;
  }
  return Vec4(c, 1.0f);
}

// The kerb line moved `offset` outwards (into the street): each edge shifted along its outward normal; at a
// reflex vertex the shifted edges meet (their intersection), at a convex one they are joined by a chord (a bevel,
// so a corner is never further than `offset` from the kerb, unlike a mitre).
Polygon2 sidewalkLoop(const Polygon2& kerb, float offset) {
  const size_t n = kerb.size();
  auto normal = [&](size_t i) {
    const Vec2 d = glm::normalize(kerb[(i + 1) % n] - kerb[i]);
    return Vec2(d.y, -d.x);  // outward for a counter-clockwise polygon
  };
  Polygon2 loop;
  for (size_t i = 0; i < n; ++i) {
    const size_t prev = (i + n - 1) % n;
    const Vec2 a = kerb[prev], b = kerb[i], c = kerb[(i + 1) % n];
    const Vec2 n0 = normal(prev), n1 = normal(i);
    if (cross2(b - a, c - b) >= 0.0f) {  // convex (left turn): bevel
      loop.push_back(b + n0 * offset);
      if (glm::length(n1 - n0) > 1e-4f) loop.push_back(b + n1 * offset);
    } else {  // reflex: the shifted lines meet at b + (n0 + n1) * offset / (1 + n0 . n1)
      loop.push_back(b + (n0 + n1) * (offset / (1.0f + glm::dot(n0, n1))));
    }
  }
  return cleanPolygon(loop, 1e-3f);
}

}  // namespace

Crowd generateCrowd(const urban::StreetGraph& streets, const CrowdOptions& options) {
  if (options.model_shares.empty()) throw Error("crowd", "no model shares");
  float share_sum = 0.0f;
  for (float s : options.model_shares) {
    if (!(s >= 0.0f)) throw Error("crowd", "model shares must be non-negative");
    share_sum += s;
  }
  if (!(share_sum > 0.0f)) throw Error("crowd", "model shares sum to 0");
  if (!(options.min_speed > 0.0f) || !(options.max_speed >= options.min_speed))
    throw Error("crowd", "speeds must be positive, min <= max");
  if (!(options.sidewalk_offset >= 0.0f)) throw Error("crowd", "sidewalk offset must be >= 0");
  if (options.outfits < 1) throw Error("crowd", "need at least one outfit");
  Crowd crowd;
  crowd.ground_height = options.ground_height;
  for (const BlockFootprint& block : buildableBlocks(streets)) {
    SidewalkRoute r;
    r.face = block.face;
    r.kerb = block.footprint;
    r.loop = sidewalkLoop(block.footprint, options.sidewalk_offset);
    if (r.loop.size() < 3 || signedArea(r.loop) <= 0.0) continue;
    r.distance.push_back(0.0f);
    for (size_t i = 0; i < r.loop.size(); ++i)
      r.distance.push_back(r.distance.back() + glm::length(r.loop[(i + 1) % r.loop.size()] - r.loop[i]));
    r.length = r.distance.back();
    r.distance.pop_back();
    if (r.length > 1.0f) crowd.routes.push_back(std::move(r));
  }
  if (crowd.routes.empty()) throw Error("crowd", "the street graph has no block with a sidewalk");
  std::vector<double> cumulative;
  double total = 0.0;
  for (const SidewalkRoute& r : crowd.routes) cumulative.push_back(total += r.length);
  std::mt19937_64 rng(options.seed * 0x9E3779B97F4A7C15ull + 17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  crowd.agents.resize(options.agents);
  for (CrowdAgent& a : crowd.agents) {
    const double at = u(rng) * total;
    a.route = uint32_t(std::min<size_t>(size_t(std::upper_bound(cumulative.begin(), cumulative.end(), at) -
                                               cumulative.begin()),
                                        crowd.routes.size() - 1));
    a.start = float(u(rng)) * crowd.routes[a.route].length;
    a.speed = options.min_speed + float(u(rng)) * (options.max_speed - options.min_speed);
    a.direction = u(rng) < 0.5 ? 1 : -1;
    a.phase = float(u(rng));
    double pick = u(rng) * share_sum;
    a.model = uint32_t(options.model_shares.size() - 1);
    for (size_t m = 0; m < options.model_shares.size(); ++m) {
      if (pick < options.model_shares[m]) {
        a.model = uint32_t(m);
        break;
      }
      pick -= options.model_shares[m];
    }
    a.tint = tintOf(rng);
  }
  // Outfits from their own streams, so that positions, speeds and tints stay those of earlier versions.
  crowd.region_tints = crowdRegionTints(options.seed, options.outfits);
  std::mt19937_64 outfit_rng(options.seed * 0xD1B54A32D192ED03ull + 29);
  std::uniform_int_distribution<uint32_t> pick_outfit(0, uint32_t(options.outfits - 1));
  for (CrowdAgent& a : crowd.agents) a.outfit = pick_outfit(outfit_rng);
  return crowd;
}

std::vector<Vec4> crowdRegionTints(uint64_t seed, size_t outfits) {
  if (outfits < 1) throw Error("crowd", "need at least one outfit");
  std::mt19937_64 rng(seed * 0xA24BAED4963EE407ull + 31);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  std::vector<Vec4> tints(outfits * kCrowdRegions);
  for (Vec4& t : tints) t = u01(rng) < 0.33f ? Vec4(1.0f) : tintOf(rng);
  return tints;
}

AgentPose agentPose(const Crowd& crowd, size_t i, float t) {
  const CrowdAgent& a = crowd.agents.at(i);
  const SidewalkRoute& r = crowd.routes[a.route];
  AgentPose pose;
  pose.walked = a.speed * t;
  float s = std::fmod(a.start + float(a.direction) * pose.walked, r.length);
  if (s < 0.0f) s += r.length;
  const size_t k = size_t(std::upper_bound(r.distance.begin(), r.distance.end(), s) - r.distance.begin()) - 1;
  const Vec2 p0 = r.loop[k], p1 = r.loop[(k + 1) % r.loop.size()];
  const float len = glm::length(p1 - p0);
  const Vec2 dir = len > 0.0f ? (p1 - p0) / len : Vec2(1.0f, 0.0f);
  const Vec2 p = p0 + dir * std::clamp(s - r.distance[k], 0.0f, len);
  const Vec2 walk = dir * float(a.direction);
  pose.heading = std::atan2(walk.y, walk.x);
  pose.position = Vec3(p, crowd.ground_height ? crowd.ground_height(p.x, p.y) : 0.0f);
  return pose;
}

}  // namespace farfield::gen
