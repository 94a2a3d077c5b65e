#include "farfield/terrain/flythrough.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "farfield/core/error.h"

namespace farfield::terrain {
namespace {

struct Tile {
  Vec2 centre;
  float mean = 0.0f;
  float relief = 0.0f;  // standard deviation of heights
};

Vec2 catmullRom(const Vec2& p0, const Vec2& p1, const Vec2& p2, const Vec2& p3, float t) {
  const float t2 = t * t, t3 = t2 * t;
  return 0.5f * ((2.0f * p1) + (-p0 + p2) * t + (2.0f * p0 - 5.0f * p1 + 4.0f * p2 - p3) * t2 +
                 (-p0 + 3.0f * p1 - 3.0f * p2 + p3) * t3);
}

float smoothstep(float t) {
  t = std::clamp(t, 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

}  // namespace

std::vector<Viewpoint> flythroughPath(const Heightfield& hf, const FlythroughOptions& o,
                                      FlythroughLandmarks* landmarks) {
  if (o.frames < 2 || o.frames > kMaxFlythroughFrames)
    throw Error("flythrough", "needs 2.." + std::to_string(kMaxFlythroughFrames) + " frames, got " +
                                  std::to_string(o.frames));
  if (hf.width < 8 || hf.height < 8) throw Error(hf.source, "heightfield too small for a flythrough (need 8x8)");
  const float ex = float(hf.extentX()), ey = float(hf.extentY());
  const float diag = std::sqrt(ex * ex + ey * ey);
  const float lo = hf.minHeight(), hi = hf.maxHeight();
  const float span = std::max(hi - lo, 1.0f);

  // Coarse tiles: about 10 across the longer side.
  const int tiles_x = std::max(3, int(std::lround(10.0f * ex / std::max(ex, ey))));
  const int tiles_y = std::max(3, int(std::lround(10.0f * ey / std::max(ex, ey))));
  std::vector<Tile> tiles;
  for (int ty = 0; ty < tiles_y; ++ty)
    for (int tx = 0; tx < tiles_x; ++tx) {
      const int i0 = tx * (hf.width - 1) / tiles_x, i1 = (tx + 1) * (hf.width - 1) / tiles_x;
      const int j0 = ty * (hf.height - 1) / tiles_y, j1 = (ty + 1) * (hf.height - 1) / tiles_y;
      double sum = 0.0, sum2 = 0.0;
      int n = 0;
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
          const double h = hf.at(i, j);
          sum += h, sum2 += h * h, ++n;
        }
      Tile t;
      t.mean = float(sum / n);
      t.relief = float(std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n))));
      t.centre = Vec2(float(0.5 * (i0 + i1) * hf.cell_x), float(0.5 * (j0 + j1) * hf.cell_y));
      tiles.push_back(t);
    }
  // The plain: the lowest, flattest tile. The mountains: the highest tile within reach of it (the reach grows until
  // that tile stands out: a quarter of the height range above the plain). The plain beyond: the lowest, flattest
  // tile within reach past the mountains (on the far side from the plain), or, if there is none, a point past the
  // mountains inside the map. Keeping the features within reach keeps the pace of the flight one at which sprites
  // can be reused (the paper's path has a keyframe every 37 frames on average).
  auto flatness = [&](const Tile& t) { return (t.mean - lo) / span + 2.0f * t.relief / span; };
  const Tile* plain = &tiles.front();
  for (const Tile& t : tiles)
    if (flatness(t) < flatness(*plain)) plain = &t;
  const Vec2 a = plain->centre;
  const Tile* mountain = nullptr;
  for (float reach = o.reach * diag; !mountain || mountain->mean < plain->mean + 0.25f * span; reach *= 1.5f) {
    mountain = nullptr;
    for (const Tile& t : tiles)
      if (glm::length(t.centre - a) <= reach && (!mountain || t.mean > mountain->mean)) mountain = &t;
    if (reach > 2.0f * diag) break;
  }
  const Vec2 m = mountain->centre;
  const float hop = std::max(glm::length(m - a), 0.05f * diag);
  const Vec2 forward = glm::normalize(m - a + Vec2(1e-3f, 0.0f));
  const Tile* beyond = nullptr;
  for (const Tile& t : tiles) {
    const Vec2 d = t.centre - m;
    const float dist = glm::length(d);
    if (dist < 0.5f * hop || dist > 1.5f * hop || glm::dot(d, forward) < 0.6f * dist) continue;
    if (!beyond || flatness(t) < flatness(*beyond)) beyond = &t;
  }
  Vec2 b;
  if (beyond) {
    b = beyond->centre;
  } else {
    b = m + forward * hop;
    b = glm::clamp(b, Vec2(0.05f * ex, 0.05f * ey), Vec2(0.95f * ex, 0.95f * ey));
  }
  if (landmarks) *landmarks = {a, m, b};

  // Control points of the ground track: start far out, the plain, the mountains, the plain beyond.
  const Vec2 start = a - forward * (o.start_distance * diag);
  const Vec2 pts[6] = {start - forward * diag * 0.3f, start, a, m, b, b + (b - m)};
  const float clearance = o.clearance > 0.0f ? o.clearance : std::max(120.0f, 0.02f * diag);
  const float start_altitude = hi + o.start_height * diag;

  // The approach (start -> plain, a straight line) takes a fixed share of the frames and slows down to the cruise
  // speed (a cubic Hermite distance profile: fast at the start, the cruise speed on arrival); plain -> mountains ->
  // beyond (a Catmull-Rom curve) follows at constant speed.
  const float len1 = glm::length(a - start), len2 = glm::length(m - a), len3 = glm::length(b - m);
  const float approach_share = 0.25f;
  const int approach_frames = std::max(1, int(std::lround(approach_share * float(o.frames - 1))));
  const float cruise = (len2 + len3) / float(std::max(1, o.frames - 1 - approach_frames));  // metres per frame
  const float v0 = 1.5f * len1, v1 = std::min(cruise * float(approach_frames), 1.5f * len1);
  std::vector<Vec2> track(size_t(o.frames));
  std::vector<float> approach(size_t(o.frames));  // 1 at the start, 0 from the plain on
  for (int f = 0; f < o.frames; ++f) {
    if (f <= approach_frames) {
      const float u = float(f) / float(approach_frames);
      const float u2 = u * u, u3 = u2 * u;
      const float d = len1 * (3 * u2 - 2 * u3) + v0 * (u3 - 2 * u2 + u) + v1 * (u3 - u2);
      const float t = len1 > 0.0f ? std::clamp(d / len1, 0.0f, 1.0f) : 1.0f;
      track[size_t(f)] = glm::mix(start, a, t);
      approach[size_t(f)] = 1.0f - t;
    } else {
      const float dist = std::min(float(f - approach_frames) * cruise, len2 + len3);
      float seg_t;
      int seg;
      if (dist < len2) {
        seg = 1;
        seg_t = len2 > 0 ? dist / len2 : 1.0f;
      } else {
        seg = 2;
        seg_t = len3 > 0 ? std::min((dist - len2) / len3, 1.0f) : 1.0f;
      }
      track[size_t(f)] = catmullRom(pts[seg], pts[seg + 1], pts[seg + 2], pts[seg + 3], seg_t);
      approach[size_t(f)] = 0.0f;
    }
  }

  // Altitude: clearance above the highest ground within a radius of the track, smoothed along the path.
  auto groundMax = [&](Vec2 p, float radius) {
    float h = -std::numeric_limits<float>::max();
    for (int k = 0; k < 9; ++k) {
      const float ang = float(k) * float(kPi) / 4.0f;
      const Vec2 q = k == 8 ? p : p + radius * Vec2(std::cos(ang), std::sin(ang));
      h = std::max(h, hf.sample(q.x, q.y));
    }
    return h;
  };
  // The ground under and near the track, then the highest of it over a window of frames ahead and behind, so the
  // camera climbs before a ridge rather than on it.
  std::vector<float> ground(size_t(o.frames));
  for (int f = 0; f < o.frames; ++f) ground[size_t(f)] = groundMax(track[size_t(f)], 0.03f * diag);
  const int reach_frames = std::max(1, o.frames / 12);
  std::vector<float> altitude(size_t(o.frames));
  for (int f = 0; f < o.frames; ++f) {
    float g = ground[size_t(f)];
    for (int k = -reach_frames / 2; k <= reach_frames; ++k) g = std::max(g, ground[size_t(std::clamp(f + k, 0, o.frames - 1))]);
    altitude[size_t(f)] = glm::mix(g + clearance, start_altitude, smoothstep(approach[size_t(f)]));
  }
  const int window = std::max(1, o.frames / 40);
  std::vector<float> smooth(altitude.size());
  for (int f = 0; f < o.frames; ++f) {
    float peak = altitude[size_t(f)];  // never below the clearance: smooth the maximum over the window
    for (int k = -window; k <= window; ++k)
      peak = std::max(peak, altitude[size_t(std::clamp(f + k, 0, o.frames - 1))] - 0.5f * clearance);
    smooth[size_t(f)] = peak;
  }
  std::vector<float> smoother(smooth.size());
  for (int f = 0; f < o.frames; ++f) {
    double sum = 0.0;
    int n = 0;
    for (int k = -window; k <= window; ++k) sum += smooth[size_t(std::clamp(f + k, 0, o.frames - 1))], ++n;
    smoother[size_t(f)] = std::max(float(sum / n), altitude[size_t(f)] - 0.5f * clearance);
  }

  std::vector<Viewpoint> path(size_t(o.frames));
  const float fov = float(degToRad(o.fov_deg));
  const float ahead = o.look_ahead * diag;
  for (int f = 0; f < o.frames; ++f) {
    Viewpoint& v = path[size_t(f)];
    v.fov_y = fov;
    v.eye = Vec3(track[size_t(f)], smoother[size_t(f)]);
    // Look ahead along the track (direction from a later frame), down at the ground there; during the approach,
    // at the plain.
    const int next = std::min(f + std::max(1, o.frames / 60), o.frames - 1);
    Vec2 dir = next > f ? track[size_t(next)] - track[size_t(f)] : track[size_t(f)] - track[size_t(std::max(f - 1, 0))];
    if (glm::length(dir) < 1e-3f) dir = forward;
    dir = glm::normalize(dir);
    const Vec2 target_xy = track[size_t(f)] + dir * ahead;
    const Vec2 clamped = glm::clamp(target_xy, Vec2(0.0f), Vec2(ex, ey));
    // On the ground there, but always at least 8.5 degrees below the horizon (a slope of 0.15).
    const Vec3 ahead_point(target_xy, std::min(hf.sample(clamped.x, clamped.y), v.eye.z - 0.15f * ahead));
    const Vec3 plain_point(a, hf.sample(a.x, a.y));
    v.at = glm::mix(ahead_point, plain_point, smoothstep(approach[size_t(f)]));
  }
  return path;
}

std::vector<Viewpoint> backAndForth(const std::vector<Viewpoint>& path, size_t first, size_t length, int repeats) {
  if (length == 0 || first + length > path.size() || repeats < 1)
    throw Error("back-and-forth path", "span [" + std::to_string(first) + ", " + std::to_string(first + length) +
                                           ") outside the path's " + std::to_string(path.size()) + " frames");
  std::vector<Viewpoint> out;
  for (int r = 0; r < repeats; ++r) {
    for (size_t k = 0; k < length; ++k) out.push_back(path[first + k]);
    for (size_t k = length; k-- > 0;) out.push_back(path[first + k]);
  }
  return out;
}

}  // namespace farfield::terrain
