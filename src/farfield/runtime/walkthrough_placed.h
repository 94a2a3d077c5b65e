// The state of a walkthrough over a placement database (Representation::Placed), shared by walkthrough.cpp (which
// owns it) and walkthrough_placed.cpp (which uses it). Internal to the runtime module.
#pragma once

#include <list>
#include <memory>
#include <unordered_map>
#include <vector>

#include "farfield/impostor/layered.h"
#include "farfield/runtime/walkthrough.h"
#include "farfield/store/background_reader.h"
#include "farfield/store/placement_store.h"

namespace farfield::runtime {

struct Walkthrough::Placed {
  struct Resident {
    std::unique_ptr<impostor::GpuLayeredImpostor> gpu;
    double error_rad = 0.0;  // the plan's parallax bound from its shaft
    uint64_t bytes = 0;
    std::list<uint32_t>::iterator lru;  // its place in Placed::lru
  };
  store::PlacementIndex index;
  std::unordered_map<uint32_t, Resident> resident;  // by impostor id
  std::list<uint32_t> lru;                          // most recent first
  uint64_t resident_bytes = 0;
  std::vector<uint8_t> hidden;                      // per object id: drawn by an impostor this frame
  // Per view-space node: the triangles of its visible set (whole objects; every object's where it has none), and
  // every object's, made when the placement is opened (Walkthrough::expectedTriangles).
  std::vector<double> node_triangles;
  double all_triangles = 0.0;
  struct {
    size_t frames = 0, cpv_frames = 0, visibility_frames = 0, impostor_draws = 0, geometry_fallbacks = 0, loads = 0, evictions = 0;
    double load_ms_total = 0.0, load_ms_max = 0.0, geometry_triangles = 0.0, impostor_quads = 0.0;
    uint64_t resident_bytes_max = 0;
    size_t over_gpu_budget_frames = 0;
    size_t coarse_draws = 0;  // fallback impostors drawn (placed under a coarser bound than the walkthrough's)
    size_t coarse_left_to_geometry = 0;  // ... left to geometry (WalkthroughOptions::coarser_impostors false)
    size_t read_ahead_loads = 0;         // loads by loadAhead (also in loads)
    double read_ahead_ms = 0.0;
    double upload_ms_max = 0.0;          // the slowest upload of an impostor (read and packed already)
  } stats;
  // The recent uploads of impostors, one unit each (an impostor's size is known only once it is taken from the
  // reader): what loadAhead expects the next to take.
  UploadRate upload_time;
  // The eye's motion over the last frame (loadAhead looks ahead along it).
  bool has_eye = false;
  Vec3 last_eye{0.0f}, motion{0.0f};
  // An impostor read from the database and its atlases packed: what the GPU upload needs (no GL).
  struct Prepared {
    impostor::LayeredAtlases atlases;
    double error_rad = 0.0;
  };
  static Prepared prepare(const WalkthroughOptions& options, const store::StoredPlacedImpostor& record);
  // Reads (or takes from the reader, waiting for it), uploads and makes resident the impostor `id` (stats.loads and
  // its time); returns it.
  std::unordered_map<uint32_t, Resident>::iterator load(const WalkthroughOptions& options, uint32_t id,
                                                        const store::StoredPlacedImpostor& record);
  // Uploads a prepared impostor and makes it resident (stats.loads; its time is the caller's).
  std::unordered_map<uint32_t, Resident>::iterator makeResident(uint32_t id, const Prepared& prepared);
  // An impostor to load: not resident, and one the walkthrough may draw (not left to geometry for its coarser bound).
  bool wanted(const WalkthroughOptions& options, uint32_t id) const;
  // Queues the impostors of `cpv` that are wanted for the reader.
  void prefetchCpv(const WalkthroughOptions& options, uint32_t cpv);

  // Impostors read and packed on a background thread ahead of the frames that need them (WalkthroughOptions::
  // read_ahead), so that such a frame only uploads; null without. Last: its thread reads the index above.
  std::unique_ptr<store::BackgroundReader<Prepared>> reader;
};

}  // namespace farfield::runtime
