#include "farfield/eval/bench.h"

#include <sys/utsname.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/progress.h"
#include "farfield/image/png_io.h"
#include "farfield/scene/bvh.h"
#include "farfield/core/allocator.h"
#include "farfield/eval/mode_options.h"
#include "farfield/eval/parallax_error.h"
#include "farfield/eval/temporal_error.h"

namespace fs = std::filesystem;

namespace farfield::eval {
namespace {

std::string isoDateUtc() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// Mode names become parts of file names: keep letters, digits, '-', '_' and '.', replace the rest.
std::string fileSafe(const std::string& name) {
  std::string out = name;
  for (char& c : out)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) c = '_';
  return out;
}

std::string frameTag(size_t path_frame) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "f%05zu", path_frame);
  return buf;
}

// Evenly spaced positions among n measured frames: first and last included.
std::set<size_t> samplePositions(size_t n, int samples) {
  std::set<size_t> positions;
  if (n == 0 || samples <= 0) return positions;
  if (samples == 1 || n == 1) {
    positions.insert(n / 2);
    return positions;
  }
  for (int i = 0; i < samples; ++i)
    positions.insert(size_t(std::llround(double(i) * double(n - 1) / double(samples - 1))));
  return positions;
}

// Share of pixels where the reference shows geometry and the frame the sky (both id images of the same size).
double crackShare(const image::IdImage& reference, const image::IdImage& frame) {
  if (reference.pixelCount() == 0 || reference.pixelCount() != frame.pixelCount()) return 0.0;
  size_t cracks = 0;
  for (size_t i = 0; i < reference.pixelCount(); ++i)
    cracks += (reference.pixels()[i] != 0 && frame.pixels()[i] == 0) ? 1 : 0;
  return double(cracks) / double(reference.pixelCount());
}

}  // namespace

MachineInfo machineInfo() {
  MachineInfo info;
  char host[256] = {};
  if (gethostname(host, sizeof(host) - 1) == 0) info.hostname = host;
  utsname u{};
  if (uname(&u) == 0) info.os = std::string(u.sysname) + " " + u.release + " " + u.machine;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0) {
      const size_t colon = line.find(':');
      if (colon != std::string::npos) {
        info.cpu = line.substr(colon + 1);
        info.cpu.erase(0, info.cpu.find_first_not_of(" \t"));
      }
      break;
    }
  }
  if (info.cpu.empty()) info.cpu = "unknown cpu";
  info.logical_cores = std::thread::hardware_concurrency();
  return info;
}

const ModeResult* BenchResult::mode(const std::string& name) const {
  for (const ModeResult& m : modes)
    if (m.name == name) return &m;
  return nullptr;
}

BenchResult runBench(gpu::Context& context, const scene::Scene& scene, const gen::CameraPath& path,
                     const BenchOptions& options) {
  // Modes: "full" first (the baseline), then the asked ones in their order, without repeats.
  std::vector<std::string> names{"full"};
  for (const std::string& name : options.modes)
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  checkModeNames(names);
  if (path.frames.empty()) throw Error("camera path", "has no frames");
  if (options.stride < 1) throw Error("--stride", "must be at least 1");
  if (options.repeats < 1) throw Error("--repeats", "must be at least 1");
  if (options.t_max_ms && !(*options.t_max_ms > 0.0)) throw Error("--tmax", "must be a positive number of ms");
  if (options.width < 1 || options.height < 1) throw Error("--size", "width and height must be positive");
  if (options.bad_pixel_threshold < 0 || options.bad_pixel_threshold > 255)
    throw Error("bad pixel threshold", "must be 0..255 (8-bit units)");
  if (options.error_px && !(std::isfinite(*options.error_px) && *options.error_px > 0.0))
    throw Error("--error-px", "the error bound must be a positive number of pixels");

  BenchResult result;
  result.scene = options.scene_label;
  result.path = options.path_label;
  result.path_frames = path.frames.size();
  for (size_t i = 0; i < path.frames.size(); i += options.stride) {
    if (options.frames != 0 && result.frame_indices.size() >= options.frames) break;
    result.frame_indices.push_back(i);
  }
  result.width = options.width;
  result.height = options.height;
  result.date = isoDateUtc();
  result.machine = machineInfo();
  const AllocatorSettings allocator = currentAllocatorSettings();
  result.allocator = allocator.description;
  result.allocator_applied = allocator.applied;
  result.reference = options.reference;
  result.baseline_added =
      std::find(options.modes.begin(), options.modes.end(), "full") == options.modes.end();
  result.bad_pixel_threshold = options.bad_pixel_threshold;
  result.repeats = options.repeats;
  result.t_max_ms = options.t_max_ms;
  auto camera_of = [&](size_t i) {
    return pathCamera(path, i, options.width, options.height, options.near_plane, options.far_plane);
  };
  for (size_t i : result.frame_indices) camera_of(i);  // a bad camera fails before any rendering

  const bool save_samples = !options.out_dir.empty() && options.samples > 0;
  if (save_samples) fs::create_directories(fs::path(options.out_dir) / "frames");

  context.makeCurrent();
  result.renderer = context.description();
  ModeRunResources run(scene, options.width, options.height, options.mode_options);
  const gpu::GpuScene& gpu_scene = run.gpu_scene;
  gpu::Renderer& renderer = run.renderer;
  gpu::RenderTarget& target = run.target;
  ModeContext& mode_context = run.context;
  mode_context.t_max_ms = options.t_max_ms;
  gpu::RenderTarget reference_target;
  if (options.reference) reference_target = gpu::RenderTarget(options.width, options.height);

  std::vector<std::unique_ptr<Mode>> modes;
  for (const std::string& name : names) modes.push_back(createMode(name, mode_context));
  for (auto& mode : modes) mode->prepare(mode_context);
  checkEveryOptionRead(mode_context);
  const std::vector<gpu::DrawItem> reference_items = gpu_scene.drawItems();

  const size_t mode_count = modes.size();
  result.modes.resize(mode_count);
  for (size_t m = 0; m < mode_count; ++m) result.modes[m].name = names[m];

  FrameRunner runner(renderer, target);
  {
    const size_t first = result.frame_indices.front();
    const Camera camera = camera_of(first);
    for (auto& mode : modes) runner.run(*mode, camera, first);
    if (options.reference) renderer.render(camera, reference_items, reference_target);
  }

  const std::set<size_t> sample_at = save_samples ? samplePositions(result.frame_indices.size(), options.samples)
                                                  : std::set<size_t>{};
  bool impostor_sampled = false;  // a sample shows a frame in which a mode drew an impostor
  bool impostor_modes = true;     // a mode says whether it drew impostors (known after the first frame)
  const fs::path out_dir(options.out_dir);
  // The previous measured frame of the reference and of each mode, for the popping error.
  image::ColorImage previous_reference;
  std::vector<image::ColorImage> previous_frame(mode_count);
  Progress progress("bench", result.frame_indices.size() * mode_count);
  for (size_t k = 0; k < result.frame_indices.size(); ++k) {
    const size_t path_frame = result.frame_indices[k];
    const Camera camera = camera_of(path_frame);
    image::ColorImage reference;
    image::IdImage reference_ids;
    if (options.reference) {
      renderer.render(camera, reference_items, reference_target);
      reference = reference_target.readColor();
      reference_ids = reference_target.readIds();
    }
    // A sample: an evenly spaced frame, or the first in which a mode drew an impostor (known once the modes ran, so
    // until one has, every frame is kept until then).
    bool sample = sample_at.count(k) != 0;
    const bool may_sample = save_samples && impostor_modes && !impostor_sampled;
    std::vector<image::ColorImage> frames(mode_count);
    std::vector<image::IdImage> frame_ids(mode_count);
    for (size_t j = 0; j < mode_count; ++j) {
      const size_t m = (k + j) % mode_count;
      ModeResult& mode_result = result.modes[m];
      // The first render; the repeats are later passes over the path (below).
      mode_result.frames.push_back(runner.run(*modes[m], camera, path_frame));
      mode_result.order.push_back(int(j));
      if (options.reference || sample || may_sample) {
        frames[m] = target.readColor();
        if (options.reference) {
          image::ImageMetrics e = image::compareImages(reference, frames[m], options.bad_pixel_threshold);
          if (!(e.psnr_db < kPsnrCapDb)) e.psnr_db = kPsnrCapDb;  // +inf (identical) and above the cap
          mode_result.errors.push_back(e);
          frame_ids[m] = target.readIds();
          mode_result.crack_shares.push_back(crackShare(reference_ids, frame_ids[m]));
          mode_result.parallax_px.push_back(frameParallaxPx(reference_ids, frame_ids[m], scene.objects.size()));
          mode_result.popping.push_back(
              k == 0 ? std::numeric_limits<double>::quiet_NaN()
                     : poppingError(previous_frame[m], frames[m], previous_reference, reference));
        }
      }
      progress.advance();
    }
    const bool impostors = std::any_of(result.modes.begin(), result.modes.end(),
                                       [](const ModeResult& m) { return m.frames.back().impostors == 1; });
    if (may_sample && impostors) sample = true;
    if (sample && impostors) impostor_sampled = true;
    impostor_modes = std::any_of(result.modes.begin(), result.modes.end(),
                                 [](const ModeResult& m) { return m.frames.back().impostors >= 0; });
    if (sample) {
      SampleFrame sample_frame;
      sample_frame.path_frame = path_frame;
      const std::string tag = frameTag(path_frame);
      for (size_t m = 0; m < mode_count; ++m) {
        const ModeResult& mode_result = result.modes[m];
        const std::string name = "frames/" + tag + "_" + fileSafe(mode_result.name) + ".png";
        image::writePng((out_dir / name).string(), frames[m]);
        sample_frame.mode_png[mode_result.name] = name;
        if (options.reference) {
          const std::string diff = "frames/" + tag + "_" + fileSafe(mode_result.name) + "_diff.png";
          image::writePng((out_dir / diff).string(), image::diffHeatmap(reference, frames[m]));
          sample_frame.diff_png[mode_result.name] = diff;
          if (!std::isnan(mode_result.parallax_px.back())) {
            // Where objects are drawn away from where the reference shows them: the parallax error per pixel.
            const std::string par = "frames/" + tag + "_" + fileSafe(mode_result.name) + "_parallax.png";
            image::writePng((out_dir / par).string(), parallaxHeatmap(reference_ids, frame_ids[m]));
          }
        }
      }
      if (options.reference) {
        sample_frame.reference_png = "frames/" + tag + "_reference.png";
        image::writePng((out_dir / sample_frame.reference_png).string(), reference);
      }
      result.samples.push_back(std::move(sample_frame));
    }
    if (options.reference) {
      for (size_t m = 0; m < mode_count; ++m) previous_frame[m] = std::move(frames[m]);
      previous_reference = std::move(reference);
    }
  }
  progress.finish();
  // The repeats: whole passes over the path again, timing only, each frame's fastest render kept. A frame's renders are
  // a pass apart (seconds), so a slow spell of the machine shorter than a pass does not slow all of them; a mode sees
  // the path's frames in their order again, so its caches evolve as in the first pass (and, as on any repeat, what it
  // loaded is loaded).
  for (int r = 1; r < options.repeats; ++r) {
    Progress again_progress("bench: pass " + std::to_string(r + 1) + " of " + std::to_string(options.repeats),
                            result.frame_indices.size() * mode_count);
    for (size_t k = 0; k < result.frame_indices.size(); ++k) {
      const size_t path_frame = result.frame_indices[k];
      const Camera camera = camera_of(path_frame);
      for (size_t j = 0; j < mode_count; ++j) {
        const size_t m = (k + j) % mode_count;
        FrameRecord& record = result.modes[m].frames[k];
        const FrameRecord again = runner.run(*modes[m], camera, path_frame);
        if (again.wall_ms < record.wall_ms) record = again;
        again_progress.advance();
      }
    }
    again_progress.finish();
  }

  for (size_t m = 0; m < mode_count; ++m) {
    result.modes[m].info = modes[m]->info();  // first: it may hold the mode's error bound
    summarizeModeResult(result.modes[m], options.error_px);
    if (options.t_max_ms)
      for (const FrameRecord& f : result.modes[m].frames)
        result.modes[m].frames_over_tmax += f.wall_ms > *options.t_max_ms ? 1 : 0;
  }
  const double full_median = result.modes.front().wall.median;
  for (ModeResult& m : result.modes) m.speedup_vs_full = m.wall.median > 0.0 ? full_median / m.wall.median : 0.0;
  return result;
}

void summarizeModeResult(ModeResult& m, std::optional<double> error_px) {
  summarizeFrames(m);
  m.governed = false;
  m.frames_relaxed = 0;
  m.bound_scale_max = 1.0;
  for (const FrameRecord& f : m.frames) {
    if (f.governor_level < 0) continue;
    m.governed = true;
    m.frames_relaxed += f.bound_scale > 1.0;
    m.bound_scale_max = std::max(m.bound_scale_max, f.bound_scale);
  }
  m.has_errors = !m.errors.empty();
  m.psnr_db_mean = m.psnr_db_min = m.ssim_mean = m.bad_pixel_share_mean = m.crack_share_mean = 0.0;
  m.parallax_px_mean = m.parallax_px_max = 0.0;
  m.has_parallax = false;
  if (m.has_errors) {
    double psnr_sum = 0.0, ssim_sum = 0.0, bad_sum = 0.0;
    m.psnr_db_min = kPsnrCapDb;
    for (const image::ImageMetrics& e : m.errors) {
      psnr_sum += e.psnr_db;
      ssim_sum += e.ssim;
      bad_sum += e.bad_pixel_share;
      m.psnr_db_min = std::min(m.psnr_db_min, e.psnr_db);
    }
    const double n = double(m.errors.size());
    m.psnr_db_mean = psnr_sum / n;
    m.ssim_mean = ssim_sum / n;
    m.bad_pixel_share_mean = bad_sum / n;
    double crack_sum = 0.0;
    for (double c : m.crack_shares) crack_sum += c;
    m.crack_share_mean = m.crack_shares.empty() ? 0.0 : crack_sum / double(m.crack_shares.size());
    double parallax_sum = 0.0;
    size_t parallax_frames = 0;
    for (double p : m.parallax_px) {
      if (std::isnan(p)) continue;
      parallax_sum += p;
      ++parallax_frames;
      m.parallax_px_max = std::max(m.parallax_px_max, p);
    }
    m.has_parallax = parallax_frames > 0;
    m.parallax_px_mean = parallax_frames ? parallax_sum / double(parallax_frames) : 0.0;
  }

  // The bound: the run's, else the mode's own.
  m.error_bound_px.reset();
  m.error_bound_source.clear();
  if (error_px) {
    m.error_bound_px = *error_px;
    m.error_bound_source = "--error-px";
  } else if (auto it = m.info.find("error_bound_px"); it != m.info.end() && std::isfinite(it->second) &&
                                                        it->second > 0.0) {
    m.error_bound_px = it->second;
    m.error_bound_source = "mode";
  }
  m.over_bound.assign(m.frames.size(), -1);
  m.frames_over_bound = m.frames_checked = 0;
  if (m.error_bound_px) {
    for (size_t k = 0; k < m.frames.size() && k < m.parallax_px.size(); ++k) {
      if (std::isnan(m.parallax_px[k])) continue;
      // A governed frame is checked against the bound it kept (FrameRecord::bound_scale; 1 when not relaxed).
      m.over_bound[k] = m.parallax_px[k] > *m.error_bound_px * m.frames[k].bound_scale ? 1 : 0;
      m.frames_over_bound += size_t(m.over_bound[k]);
      ++m.frames_checked;
    }
  }

  std::vector<double> popping;
  for (double p : m.popping)
    if (!std::isnan(p)) popping.push_back(p);
  m.has_popping = !popping.empty();
  m.popping_summary = summarize(popping);
}

}  // namespace farfield::eval
