// The steps of placeImpostors (place.cpp, the driver), one file each: the options' checks and JSON
// (place_options.cpp), the from-region visibility (place_visibility.cpp), the estimates supplied to the placement
// algorithm (place_estimates.cpp), the passes that plan, choose and capture the layered impostors (place_passes.cpp)
// and the database's index (place_database.cpp). Internal to the bake module: only src/farfield/bake/place*.cpp
// include it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/bake/place.h"
#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/core/enclosing_frustum.h"
#include "farfield/core/error_bound.h"
#include "farfield/core/object_fill.h"
#include "farfield/gpu/cost_profile.h"
#include "farfield/gpu/renderer.h"
#include "farfield/impostor/layered.h"
#include "farfield/placement/candidates.h"
#include "farfield/placement/object_hierarchy.h"
#include "farfield/placement/view_space.h"
#include "farfield/scene/bvh.h"
#include "farfield/scene/scene.h"
#include "farfield/store/placement_store.h"
#include "farfield/urban/pvs.h"

namespace farfield::bake {

// Throws farfield::Error naming the option out of range (place_options.cpp).
void validate(const PlaceOptions& o);

// The objects seen from each minimum-size region (or sample point), by its lower corner: ascending object ids.
using VisibleSets = std::map<std::array<float, 3>, std::vector<uint32_t>>;

// From-region visibility of the minimum-size regions, by their lower corner; sample points shared by neighbouring
// regions are rendered once (place_visibility.cpp). Counted in `report`.
struct RegionVisibility {
  // Reads options.visibility_cache where it matches; makes the sampler when options.visibility.
  RegionVisibility(const scene::Scene& scene, const gpu::GpuScene& gpu_scene, const Box3& space,
                   const PlaceOptions& options, PlaceReport& report);
  // The visible set of `region` (ViewSpaceCallbacks::visible_set): read from the cache, else sampled.
  std::vector<uint32_t> visibleSet(const Box3& region);
  // Once the visible sets are known: their mean size, and the cache written when some were sampled anew.
  void finish();

  const PlaceOptions& options;
  PlaceReport& report;
  const nlohmann::json cache_key;  // the cache's identity: what the visible sets depend on
  std::unique_ptr<urban::PvsSampler> sampler;
  VisibleSets region_visible, point_visible, cached;
};

// The estimates supplied to the placement algorithm, from the cost profile (place_estimates.cpp): a view's time
// over the objects its enclosing frustum meets (the problem view space's), and a cluster's time as geometry and as
// an impostor in a CPV (the greedy's).
struct PlaceEstimates {
  PlaceEstimates(const scene::Scene& scene, const scene::Bvh& bvh, const gpu::CostProfile& profile,
                 const std::vector<gpu::ObjectDrawCost>& cost, const placement::ObjectHierarchy& hierarchy,
                 const VisibleSets& region_visible, const PlaceOptions& options, const Lens& lens,
                 const ErrorBound& bound);

  // What the objects an enclosing frustum meets (of the visible set, when there is one) cost as geometry, and their
  // fill from the region's nearest point: the view space's estimates and the CPVs' fill sums count the same objects.
  struct Workload {
    uint64_t triangles = 0, draws = 0;
    double fill = 0.0;
  };
  double geometryMs(uint64_t triangles, uint64_t draws, double fill) const;
  void addObject(Workload& w, uint32_t id, const Box3& region) const;
  Workload workloadIn(const Frustum& frustum, const Box3& region, const std::vector<uint32_t>* visible);
  const std::vector<uint32_t>* visibleFrom(const Box3& region) const;
  // A view's time (ViewSpaceCallbacks::estimate).
  double estimate(const Box3& region, const Vdi& vdi, const std::vector<uint32_t>* visible);
  // Once the problem view space is known: its CPVs' frusta and whole fill, for tObject and tImpostor.
  void prepareCpvs(const placement::ViewSpace& problem);
  double tObject(int node, uint32_t cpv);
  double tImpostor(const impostor::LayeredPlan& plan, uint32_t cpv) const;

  const scene::Scene& scene;
  const scene::Bvh& bvh;
  const gpu::CostProfile& profile;
  const std::vector<gpu::ObjectDrawCost>& cost;  // per object: its triangles and draw calls
  const placement::ObjectHierarchy& hierarchy;
  const VisibleSets& region_visible;
  const PlaceOptions& options;
  const Lens& lens;
  const ErrorBound& bound;
  const double pixels;
  // The objects' fill (core/object_fill.h), from the nearest point of a region: at least what any view in it covers.
  const FillLens fill_lens;
  const double max_pitch;
  std::vector<uint32_t> ids;  // workloadIn's scratch
  // The problem view space (prepareCpvs), its CPVs' enclosing frusta and their whole fill.
  const placement::ViewSpace* view_space = nullptr;
  std::vector<Frustum> frusta;
  std::vector<double> cpv_fill;
  std::unordered_map<uint64_t, double> t_object_memo;
};

// The impostors placed: the passes choose, capture and write them (place_passes.cpp), the database's index lists
// them with the CPVs that show them (place_database.cpp).
struct PlacedImpostors {
  // Creates `out_dir` and writes each impostor the greedy chooses into it at once.
  void placeInPasses(const scene::Scene& scene, const gpu::GpuScene& gpu_scene, gpu::Renderer& renderer,
                     const placement::ObjectHierarchy& hierarchy, const placement::ViewSpace& view_space,
                     const placement::CandidateSet& all, const ErrorBound& bound, PlaceEstimates& est,
                     const PlaceOptions& options, const std::string& out_dir, PlaceReport& report);
  // Writes the index, which names the impostors shown somewhere, and completes `report` but for wall_s.
  void writeDatabase(const scene::Scene& scene, const Box3& space, const placement::ViewSpace& view_space,
                     const VisibleSets& region_visible, const PlaceOptions& options, const std::string& out_dir,
                     PlaceReport& report) const;

  uint64_t generation = 0;                                  // of the database being written
  std::map<uint32_t, store::StoredPlacedImpostor> written;  // impostor id -> record
  std::map<uint32_t, double> id_bytes;                      // impostor id -> bytes of its id textures
  std::map<uint32_t, impostor::LayeredPlan> chosen_plans;   // impostor id -> its plan (uncropped)
  std::vector<double> cpv_t;                                // per CPV: its time with the impostors shown so far
  std::vector<std::vector<std::pair<uint32_t, int>>> cpv_shown;  // per CPV: (impostor id, node)
  std::map<uint32_t, size_t> uses;  // impostor id -> CPVs showing it
};

}  // namespace farfield::bake
