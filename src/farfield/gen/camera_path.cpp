// Camera paths for walkthroughs: street walks along the street graph (the viewing cells of Sillion 1997 are the
// oriented street edges a walker moves along; Decoret 1999, section 6, measures walkthroughs in a city), fly-overs
// and orbits.
#include "farfield/gen/camera_path.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/gen/street_network.h"
#include "farfield/urban/street_graph.h"

namespace farfield::gen {

namespace {

using urban::StreetGraph;

// Hand-mapped random numbers (identical across standard libraries), as in street_network.cpp.
class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed ^ 0xd1b54a32d192ed03ull) {}
  double uniform() { return double(engine_() >> 11) * 0x1.0p-53; }
  uint64_t below(uint64_t n) { return n == 0 ? 0 : engine_() % n; }

 private:
  std::mt19937_64 engine_;
};

DVec2 d2(const Vec2& v) { return DVec2(v.x, v.y); }
Vec2 f2(const DVec2& v) { return Vec2(float(v.x), float(v.y)); }
DVec2 rightOf(const DVec2& d) { return DVec2(d.y, -d.x); }

double distPointSegment(const DVec2& p, const DVec2& a, const DVec2& b) {
  DVec2 ab = b - a;
  double len2 = glm::dot(ab, ab);
  double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

DVec2 bezier(const DVec2& p0, const DVec2& p1, const DVec2& p2, const DVec2& p3, double t) {
  const double u = 1.0 - t;
  return u * u * u * p0 + 3.0 * u * u * t * p1 + 3.0 * u * t * t * p2 + t * t * t * p3;
}

void checkFrames(int frames, float fps, float fov_deg, const char* what) {
  if (frames < 1) throw Error(what, "frames must be at least 1, got " + std::to_string(frames));
  if (!std::isfinite(fps) || fps <= 0.0f) throw Error(what, "fps must be positive");
  if (!std::isfinite(fov_deg) || fov_deg <= 0.0f || fov_deg >= 180.0f)
    throw Error(what, "fov must be in (0, 180) degrees");
}

// A polyline with cumulative arc length, sampled by distance.
struct Track {
  std::vector<DVec2> points;
  std::vector<double> at;  // arc length at each point

  void add(const DVec2& p) {
    if (!points.empty()) {
      const double l = glm::length(p - points.back());
      if (l <= 1e-9) return;
      at.push_back(at.back() + l);
    } else {
      at.push_back(0.0);
    }
    points.push_back(p);
  }
  double length() const { return at.empty() ? 0.0 : at.back(); }
  DVec2 sample(double s) const {
    if (points.size() == 1 || s <= 0.0) return points.front();
    if (s >= at.back()) {
      // Past the end: continue straight along the last piece.
      const DVec2 d = glm::normalize(points.back() - points[points.size() - 2]);
      return points.back() + d * (s - at.back());
    }
    const size_t i = size_t(std::upper_bound(at.begin(), at.end(), s) - at.begin());
    const double u = (s - at[i - 1]) / (at[i] - at[i - 1]);
    return points[i - 1] + u * (points[i] - points[i - 1]);
  }
};

// Builds the walker's track along a sequence of half-edges. On each street the walker keeps a lateral offset to
// the right of the centreline (a share of the half-width, so it stays on the street); at a junction a cubic
// Bezier close to a circular arc of the turn radius joins the offset line of the incoming street to that of the
// outgoing one. The arc is made smaller until every point of the turn lies inside one of the two streets
// (within 90% of the half-width of the centreline) and outside the buildable area of every block around the
// junction.
class TrackBuilder {
 public:
  TrackBuilder(const StreetGraph& graph, float side_share, float turn_radius)
      : graph_(graph), side_share_(side_share), turn_radius_(turn_radius) {}

  double offset(uint32_t e) const { return side_share_ * 0.5 * graph_.width(e); }

  // Adds the turn from half-edge `in` to `out` (out leaves the junction `in` arrives at): the straight part of
  // `in` up to the turn (the track ends on `in`'s offset line, `along` metres from its origin), then the turn.
  // Sets `along` to where the track ends on `out`.
  void turn(Track& track, uint32_t in, uint32_t out, double& along) {
    const uint32_t junction = graph_.destination(in);
    const DVec2 j = d2(graph_.position(junction));
    const DVec2 d1 = d2(graph_.direction(in)), d2v = d2(graph_.direction(out));
    const double o1 = offset(in), o2 = offset(out);
    const double len1 = graph_.length(in), len2 = graph_.length(out);
    const double theta = std::acos(std::clamp(glm::dot(d1, d2v), -1.0, 1.0));  // turn angle, 0 = straight on
    // Control-arm length of the cubic relative to the tangent length: that of a circular arc of angle theta.
    const double kfactor =
        theta > 1e-3 ? 4.0 / 3.0 * std::tan(0.25 * theta) / std::tan(0.5 * theta) : 2.0 / 3.0;
    // The turn starts after where the walker is on `in` and uses at most half of `out`, so consecutive turns
    // never overlap and the next one has room.
    const double reach1 = std::max(len1 - along - 0.01, 0.0), reach2 = 0.5 * len2;
    DVec2 a, b, c1, c2;

    // A real turn: a fillet of the corner where the two offset lines meet (x), tangent length from x.
    bool done = false;
    if (theta > degToRad(5.0) && theta < degToRad(170.0)) {
      const DVec2 p1 = j + rightOf(d1) * o1, p2 = j + rightOf(d2v) * o2;
      const double den = cross2(d1, d2v);
      const DVec2 x = p1 + d1 * (cross2(p2 - p1, d2v) / den);
      double t = turn_radius_ * std::tan(0.5 * theta);
      for (int attempt = 0; attempt <= 12 && !done; ++attempt) {
        if (attempt == 12) t = 0.0;  // a sharp corner at x
        a = x - d1 * t;
        b = x + d2v * t;
        c1 = a + d1 * (t * kfactor);
        c2 = b - d2v * (t * kfactor);
        const bool fits = glm::dot(a - j, d1) >= -reach1 && glm::dot(b - j, d2v) <= reach2;
        if (fits && (t == 0.0 || turnIsClear(a, c1, c2, b, in, out, junction))) done = true;
        t *= 0.7;
      }
    }
    // Straight on (possibly changing the lateral offset), a U-turn at a dead end, or a corner whose offset lines
    // meet too far away: a curve between points at distance t before and after the junction.
    if (!done) {
      const bool u_turn = theta >= degToRad(170.0);
      double t = u_turn ? 0.0 : std::min(std::max({turn_radius_ * std::tan(0.5 * std::min(theta, 1.5)),
                                                   2.0 * std::abs(o1 - o2), 1.0}),
                                         std::min(reach1, reach2));
      double k = u_turn ? 4.0 / 3.0 * std::max({o1, o2, 1.0}) : t * kfactor;
      for (int attempt = 0;; ++attempt) {
        a = j - d1 * t + rightOf(d1) * o1;
        b = j + d2v * t + rightOf(d2v) * o2;
        c1 = a + d1 * k;
        c2 = b - d2v * k;
        if (attempt >= 12) {
          // Straight from a to b: both lie within their offset of the junction, inside either street.
          c1 = a;
          c2 = b;
          break;
        }
        if (turnIsClear(a, c1, c2, b, in, out, junction)) break;
        if (u_turn) {
          k *= 0.7;
        } else {
          t *= 0.7;
          k = t * kfactor;
        }
      }
    }
    along = len2 + glm::dot(b - d2(graph_.destinationPosition(out)), d2v);
    track.add(a);
    constexpr int kSteps = 24;
    for (int i = 1; i <= kSteps; ++i) track.add(bezier(a, c1, c2, b, double(i) / kSteps));
  }

 private:
  const StreetGraph& graph_;
  float side_share_;
  float turn_radius_;
  std::unordered_map<uint32_t, Polygon2> footprints_;

  const Polygon2& footprint(uint32_t face) {
    auto it = footprints_.find(face);
    if (it == footprints_.end()) it = footprints_.emplace(face, buildableFootprint(graph_, face)).first;
    return it->second;
  }

  bool turnIsClear(const DVec2& a, const DVec2& c1, const DVec2& c2, const DVec2& b, uint32_t in, uint32_t out,
                   uint32_t junction) {
    const DVec2 p1 = d2(graph_.originPosition(in)), q1 = d2(graph_.destinationPosition(in));
    const DVec2 p2 = d2(graph_.originPosition(out)), q2 = d2(graph_.destinationPosition(out));
    const double r1 = 0.9 * 0.5 * graph_.width(in), r2 = 0.9 * 0.5 * graph_.width(out);
    const std::vector<uint32_t> blocks = graph_.blocksAtJunction(junction);
    constexpr int kChecks = 32;
    for (int i = 0; i <= kChecks; ++i) {
      const DVec2 p = bezier(a, c1, c2, b, double(i) / kChecks);
      if (distPointSegment(p, p1, q1) >= r1 && distPointSegment(p, p2, q2) >= r2) return false;
      for (uint32_t f : blocks) {
        const Polygon2& poly = footprint(f);
        if (!poly.empty() && pointInPolygon(f2(p), poly)) return false;
      }
    }
    return true;
  }
};

}  // namespace

Camera CameraPath::camera(size_t i, int width, int height, float near_plane, float far_plane) const {
  if (i >= frames.size())
    throw Error("camera path", "frame " + std::to_string(i) + " out of range (" + std::to_string(frames.size()) +
                                   " frames)");
  Camera cam;
  cam.eye = frames[i].eye;
  cam.at = frames[i].at;
  cam.up = frames[i].up;
  cam.fov_y = frames[i].fov_y;
  cam.width = width;
  cam.height = height;
  cam.near_plane = near_plane;
  cam.far_plane = far_plane;
  return cam;
}

CameraPath loadCameraPath(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open camera path file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object()) throw Error(path, "expected a JSON object with \"frames\"");
  CameraPath out;
  if (j.contains("kind")) {
    if (!j["kind"].is_string()) throw Error(path, "\"kind\" must be a string");
    out.kind = j["kind"].get<std::string>();
  }
  if (j.contains("fps")) {
    if (!j["fps"].is_number() || !std::isfinite(j["fps"].get<double>()) || j["fps"].get<double>() <= 0.0)
      throw Error(path, "\"fps\" must be a positive number");
    out.fps = float(j["fps"].get<double>());
  }
  if (!j.contains("frames") || !j["frames"].is_array()) throw Error(path, "missing \"frames\" array");
  const auto& frames = j["frames"];
  if (frames.empty()) throw Error(path, "no frames");
  out.frames.reserve(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    const auto& f = frames[i];
    const std::string where = "frame " + std::to_string(i) + ": ";
    if (!f.is_object()) throw Error(path, where + "expected an object with \"eye\", \"at\", \"up\", \"fov_deg\"");
    auto vec3 = [&](const char* key, bool required, const Vec3& fallback) {
      if (!f.contains(key)) {
        if (required) throw Error(path, where + "missing \"" + key + "\"");
        return fallback;
      }
      const auto& v = f[key];
      if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
        throw Error(path, where + "\"" + key + "\" must be [x, y, z]");
      Vec3 r(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
      if (!isFinite(r)) throw Error(path, where + "\"" + key + "\" is not finite");
      return r;
    };
    PathFrame frame;
    frame.eye = vec3("eye", true, Vec3(0.0f));
    frame.at = vec3("at", true, Vec3(0.0f));
    frame.up = vec3("up", false, Vec3(0.0f, 0.0f, 1.0f));
    if (f.contains("fov_deg")) {
      if (!f["fov_deg"].is_number()) throw Error(path, where + "\"fov_deg\" must be a number");
      const double fov = f["fov_deg"].get<double>();
      if (!std::isfinite(fov) || fov <= 0.0 || fov >= 180.0) throw Error(path, where + "\"fov_deg\" must be in (0, 180)");
      frame.fov_y = float(degToRad(fov));
    }
    const Vec3 view = frame.at - frame.eye;
    if (glm::length(view) <= 0.0f) throw Error(path, where + "\"eye\" and \"at\" coincide");
    if (glm::length(frame.up) <= 0.0f || glm::length(glm::cross(glm::normalize(view), glm::normalize(frame.up))) < 1e-4f)
      throw Error(path, where + "\"up\" is zero or parallel to the view direction");
    out.frames.push_back(frame);
  }
  return out;
}

void saveCameraPath(const CameraPath& path, const std::string& file) {
  using nlohmann::json;
  std::ofstream out(file, std::ios::binary);
  if (!out) throw Error(file, "cannot write camera path file");
  // One frame per line: small enough to diff, read and edit by hand.
  out << "{\"kind\": " << json(path.kind).dump() << ", \"fps\": " << json(path.fps).dump() << ",\n \"frames\": [";
  for (size_t i = 0; i < path.frames.size(); ++i) {
    const PathFrame& f = path.frames[i];
    const json frame{{"eye", {f.eye.x, f.eye.y, f.eye.z}},
                     {"at", {f.at.x, f.at.y, f.at.z}},
                     {"up", {f.up.x, f.up.y, f.up.z}},
                     {"fov_deg", float(radToDeg(f.fov_y))}};
    out << (i ? ",\n  " : "\n  ") << frame.dump();
  }
  out << "\n]}\n";
  if (!out) throw Error(file, "write failed");
}

CameraPath streetWalk(const urban::StreetGraph& graph, const StreetWalkOptions& options) {
  checkFrames(options.frames, options.fps, options.fov_deg, "street walk");
  if (!std::isfinite(options.turn_radius) || options.turn_radius < 0.0f)
    throw Error("street walk", "turn radius must be non-negative");
  if (graph.streetCount() == 0) throw Error("street walk", "the street graph has no streets");

  const bool car = options.walker == Walker::Car;
  const double speed = car ? 10.0 : 1.4;        // metres per second
  const double eye_height = car ? 1.2 : 1.7;    // metres above the ground
  const float side_share = car ? 0.25f : 0.5f;  // share of the half-width right of the centreline
  const double step = speed / options.fps;
  const double look_ahead = car ? 8.0 : 3.0;
  const double needed = step * (options.frames - 1) + look_ahead + 1.0;

  Rng rng(options.seed);
  TrackBuilder builder(graph, side_share, options.turn_radius);
  Track track;

  // Start a third of the way along a random half-edge (leaving room for the first turn), on the walker's side.
  uint32_t edge = uint32_t(rng.below(graph.halfEdgeCount()));
  double along = graph.length(edge) / 3.0;
  {
    const DVec2 o = d2(graph.originPosition(edge)), d = d2(graph.direction(edge));
    track.add(o + d * along + rightOf(d) * builder.offset(edge));
  }
  // Walk junction to junction until the track is long enough (with a bound for graphs of tiny streets).
  const size_t max_edges = 1000000;
  for (size_t count = 0; track.length() < needed && count < max_edges; ++count) {
    const uint32_t junction = graph.destination(edge);
    // Any street but the way back; hairpin turns (over 135 degrees) only when there is nothing else.
    std::vector<uint32_t> choices, hairpins;
    for (uint32_t e : graph.outgoing(junction)) {
      if (e == StreetGraph::twin(edge)) continue;
      const bool hairpin = glm::dot(graph.direction(edge), graph.direction(e)) < -0.7071f;
      (hairpin ? hairpins : choices).push_back(e);
    }
    if (choices.empty()) choices = hairpins;
    uint32_t next = StreetGraph::twin(edge);  // dead end: turn back
    if (!choices.empty()) {
      // Going straight on is likelier than turning (weights 1 to 2.5).
      const Vec2 din = graph.direction(edge);
      std::vector<double> weight(choices.size());
      double total = 0.0;
      for (size_t i = 0; i < choices.size(); ++i) {
        weight[i] = 1.0 + 1.5 * std::max(0.0f, glm::dot(din, graph.direction(choices[i])));
        total += weight[i];
      }
      double pick = rng.uniform() * total;
      next = choices.back();
      for (size_t i = 0; i < choices.size(); ++i) {
        if (pick < weight[i]) {
          next = choices[i];
          break;
        }
        pick -= weight[i];
      }
    }
    builder.turn(track, edge, next, along);
    edge = next;
  }

  auto groundAt = [&](const DVec2& p) {
    return options.ground_height ? double(options.ground_height(float(p.x), float(p.y))) : 0.0;
  };
  CameraPath path;
  path.kind = "street";
  path.fps = options.fps;
  path.frames.reserve(size_t(options.frames));
  for (int i = 0; i < options.frames; ++i) {
    const double s = step * i;
    const DVec2 p = track.sample(s);
    DVec2 q = track.sample(s + look_ahead);
    if (glm::length(q - p) < 1e-3) q = p + DVec2(0.0, 1.0);
    PathFrame frame;
    frame.eye = Vec3(float(p.x), float(p.y), float(groundAt(p) + eye_height));
    frame.at = Vec3(float(q.x), float(q.y), float(groundAt(q) + eye_height));
    frame.up = Vec3(0.0f, 0.0f, 1.0f);
    frame.fov_y = float(degToRad(options.fov_deg));
    path.frames.push_back(frame);
  }
  return path;
}

CameraPath flyover(const Box3& bounds, const FlyoverOptions& options) {
  checkFrames(options.frames, options.fps, options.fov_deg, "flyover");
  if (bounds.empty() || !isFinite(bounds.lo) || !isFinite(bounds.hi)) throw Error("flyover", "empty scene bounds");
  if (!std::isfinite(options.altitude)) throw Error("flyover", "altitude must be finite");
  const DVec2 from(bounds.lo.x, bounds.lo.y), to(bounds.hi.x, bounds.hi.y);
  DVec2 dir = to - from;
  if (glm::length(dir) <= 0.0) dir = DVec2(1.0, 0.0);
  dir = glm::normalize(dir);
  const double z = double(bounds.lo.z) + options.altitude;
  // Looking ahead and down at the ground a little over two altitudes ahead (about 25 degrees down).
  const double pitch = degToRad(25.0);
  CameraPath path;
  path.kind = "flyover";
  path.fps = options.fps;
  for (int i = 0; i < options.frames; ++i) {
    const double u = options.frames > 1 ? double(i) / (options.frames - 1) : 0.5;
    const DVec2 p = from + (to - from) * u;
    PathFrame frame;
    frame.eye = Vec3(float(p.x), float(p.y), float(z));
    const DVec3 look(dir.x * std::cos(pitch), dir.y * std::cos(pitch), -std::sin(pitch));
    frame.at = frame.eye + Vec3(look * 100.0);
    frame.up = Vec3(0.0f, 0.0f, 1.0f);
    frame.fov_y = float(degToRad(options.fov_deg));
    path.frames.push_back(frame);
  }
  return path;
}

CameraPath orbit(const Box3& bounds, const OrbitOptions& options) {
  checkFrames(options.frames, options.fps, options.fov_deg, "orbit");
  if (bounds.empty() || !isFinite(bounds.lo) || !isFinite(bounds.hi)) throw Error("orbit", "empty scene bounds");
  if (!std::isfinite(options.radius_scale) || options.radius_scale <= 0.0f)
    throw Error("orbit", "radius scale must be positive");
  if (!std::isfinite(options.elevation_deg) || std::abs(options.elevation_deg) >= 89.0f)
    throw Error("orbit", "elevation must be within (-89, 89) degrees");
  const DVec3 centre = DVec3(bounds.center());
  const double radius = options.radius_scale * 0.5 * glm::length(DVec3(bounds.extent()));
  if (radius <= 0.0) throw Error("orbit", "scene bounds have zero size");
  const double el = degToRad(options.elevation_deg);
  CameraPath path;
  path.kind = "orbit";
  path.fps = options.fps;
  for (int i = 0; i < options.frames; ++i) {
    const double a = 2.0 * kPi * double(i) / options.frames;
    const DVec3 eye = centre + radius * DVec3(std::cos(el) * std::cos(a), std::cos(el) * std::sin(a), std::sin(el));
    PathFrame frame;
    frame.eye = Vec3(eye);
    frame.at = Vec3(centre);
    frame.up = Vec3(0.0f, 0.0f, 1.0f);
    frame.fov_y = float(degToRad(options.fov_deg));
    path.frames.push_back(frame);
  }
  return path;
}

}  // namespace farfield::gen

namespace farfield::gen {

Box3 eyeBounds(const CameraPath& path, float margin_m, const std::string& where) {
  if (path.frames.empty()) throw Error(where, "the path has no frames");
  if (!(margin_m >= 0.0f)) throw Error(where, "the margin must be 0 or more metres");
  Box3 box;
  for (const PathFrame& f : path.frames) box.expand(f.eye);
  box.lo.x -= margin_m;
  box.lo.y -= margin_m;
  box.hi.x += margin_m;
  box.hi.y += margin_m;
  box.hi.z = std::max(box.hi.z, box.lo.z + 0.5f);
  return box;
}

}  // namespace farfield::gen
