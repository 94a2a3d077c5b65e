// Impostor candidates: object-hierarchy node x view cell (Jeschke et al. 2005, section 4).
//
// Cost: per node and axis, each CPV visible from the node costs at most apex_angles + distance_steps shaft tests,
// not their product, because Shaft::containsBox is monotone in both: a wider cone holds what a narrower one holds,
// and a larger minimum distance only removes viewpoints. So the CPV is served exactly by the shafts with an angle
// index >= the first that holds its region (at distance 0) and a distance index <= the last that still holds it.
#include "farfield/placement/candidates.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "farfield/core/error.h"

namespace farfield::placement {

namespace {

const char* const kWhat = "impostor candidates";

void validate(const CandidateOptions& o) {
  auto fail = [](const std::string& msg) { throw Error(kWhat, msg); };
  if (!o.shafts) return;
  if (o.apex_angles.empty()) fail("apex_angles is empty");
  for (float a : o.apex_angles)
    if (!(a > 0.0f && a <= float(kPi) + 1e-6f)) fail("apex angle " + std::to_string(a) + " rad is outside (0, pi]");
  if (!(o.direction_step > 0.0f && o.direction_step <= float(2.0 * kPi) + 1e-6f))
    fail("direction_step " + std::to_string(o.direction_step) + " rad is outside (0, 2 pi]");
  if (o.elevations.empty()) fail("elevations is empty");
  for (float e : o.elevations)
    if (!(std::abs(e) < 0.5f * float(kPi))) fail("elevation " + std::to_string(e) + " rad is outside (-pi/2, pi/2)");
  if (!(o.first_distance_factor > 0.0f) || !std::isfinite(o.first_distance_factor))
    fail("first_distance_factor " + std::to_string(o.first_distance_factor) + " must be > 0");
  if (o.distance_steps < 1 || o.distance_steps > 40) fail("distance_steps " + std::to_string(o.distance_steps) + " must be 1..40");
}

std::vector<Vec3> shaftAxes(const CandidateOptions& o) {
  const int n_dirs = std::max(1, int(std::lround(2.0 * kPi / double(o.direction_step))));
  std::vector<Vec3> axes;
  for (float e : o.elevations)
    for (int k = 0; k < n_dirs; ++k) {
      const double azimuth = double(k) * double(o.direction_step);
      axes.push_back(Vec3(float(std::cos(azimuth) * std::cos(e)), float(std::sin(azimuth) * std::cos(e)), std::sin(e)));
    }
  return axes;
}

void shaftCandidates(const ObjectHierarchy& h, int node, const std::vector<uint32_t>& visible, const ViewSpace& vs,
                     const CandidateOptions& o, const std::vector<Vec3>& axes, CandidateSet& out) {
  const Box3& bounds = h.nodes()[size_t(node)].bounds;
  const Vec3 apex = bounds.center();
  std::vector<float> angles = o.apex_angles;
  std::sort(angles.begin(), angles.end());
  const size_t n_angles = angles.size(), n_dists = size_t(o.distance_steps);
  std::vector<float> dists(n_dists);
  for (size_t k = 0; k < n_dists; ++k) dists[k] = h.size(node) * o.first_distance_factor * std::ldexp(1.0f, int(k));
  auto shaft = [&](const Vec3& axis, size_t a, size_t k) { return Shaft::make(apex, axis, angles[a], dists[k], kWhat); };

  for (const Vec3& axis : axes) {
    std::vector<std::vector<uint32_t>> served(n_angles * n_dists);
    const Shaft widest = Shaft::make(apex, axis, angles.back(), 0.0f, kWhat);
    for (uint32_t c : visible) {
      const Box3& region = vs.cpvs[c].region;
      if (!widest.containsBox(region)) continue;
      size_t a_first = 0;
      while (!Shaft::make(apex, axis, angles[a_first], 0.0f, kWhat).containsBox(region)) ++a_first;
      size_t k_end = 0;  // distances [0, k_end) hold the region
      while (k_end < n_dists && shaft(axis, n_angles - 1, k_end).containsBox(region)) ++k_end;
      for (size_t a = a_first; a < n_angles; ++a)
        for (size_t k = 0; k < k_end; ++k) served[a * n_dists + k].push_back(c);
    }
    std::set<std::vector<uint32_t>> seen;
    for (size_t a = 0; a < n_angles; ++a)
      for (size_t k = n_dists; k-- > 0;) {  // smallest cell first: narrow angle, far minimum distance
        ++out.counts.considered;
        const Shaft s = shaft(axis, a, k);
        std::vector<uint32_t>& cpvs = served[a * n_dists + k];
        if (s.mayIntersectBox(bounds)) {
          ++out.counts.intersecting;
        } else if (cpvs.empty()) {
          ++out.counts.no_cpv;
        } else if (o.drop_identical && !seen.insert(cpvs).second) {
          ++out.counts.identical;
        } else {
          out.candidates.push_back({node, s, std::move(cpvs)});
        }
      }
  }
}

void boxCandidates(int node, const Box3& bounds, const std::vector<Frustum>& frusta, const ViewSpace& vs,
                   bool leaves_only, CandidateSet& out) {
  for (const ViewSpaceNode& region : vs.nodes) {
    if (region.cpv_count == 0 || (leaves_only && region.children[0] >= 0)) continue;
    ++out.counts.considered;
    if (region.box.overlaps(bounds)) {
      ++out.counts.intersecting;
      continue;
    }
    std::vector<uint32_t> cpvs;
    for (uint32_t c = region.cpv_first; c < region.cpv_first + region.cpv_count; ++c)
      if (frusta[c].intersects(bounds)) cpvs.push_back(c);
    if (cpvs.empty()) ++out.counts.no_cpv;
    else out.candidates.push_back({node, region.box, std::move(cpvs)});
  }
}

}  // namespace

std::optional<Shaft> planningShaft(const Candidate& candidate, const ObjectHierarchy& hierarchy) {
  if (const Shaft* shaft = std::get_if<Shaft>(&candidate.cell)) return *shaft;
  return Shaft::enclosing(hierarchy.nodes()[size_t(candidate.node)].bounds.center(), std::get<Box3>(candidate.cell));
}

std::vector<Frustum> cpvFrusta(const ViewSpace& view_space, const Lens& lens) {
  std::vector<Frustum> frusta;
  frusta.reserve(view_space.cpvs.size());
  for (const Cpv& c : view_space.cpvs) frusta.push_back(enclosingFrustum(c.region, c.vdi, lens));
  return frusta;
}

CandidateSet generateCandidates(const ObjectHierarchy& hierarchy, const ViewSpace& view_space, const Lens& lens,
                                const CandidateOptions& options) {
  validate(options);
  lens.validate("impostor candidates lens");
  const std::vector<Frustum> frusta = cpvFrusta(view_space, lens);
  const std::vector<Vec3> axes = options.shafts ? shaftAxes(options) : std::vector<Vec3>{};
  CandidateSet out;
  for (int node = 0; node < int(hierarchy.nodes().size()); ++node) {
    const Box3& bounds = hierarchy.nodes()[size_t(node)].bounds;
    std::vector<uint32_t> visible;  // CPVs whose enclosing frustum may hold the cluster
    for (uint32_t c = 0; c < frusta.size(); ++c)
      if (frusta[c].intersects(bounds)) visible.push_back(c);
    if (options.shafts) shaftCandidates(hierarchy, node, visible, view_space, options, axes, out);
    if (options.rectangular_cells) boxCandidates(node, bounds, frusta, view_space, options.box_leaves_only, out);
  }
  out.counts.kept = out.candidates.size();
  return out;
}

}  // namespace farfield::placement
