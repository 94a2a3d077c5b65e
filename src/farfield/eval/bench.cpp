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

// The parallax error of a frame (99th percentile, pixels), or NaN when its item buffer shows ids that are not scene
// objects (an impostor drawn with an id of its own: the metric needs the ids of the objects it stands for).
std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, v);
  return buf;
}

std::string markdownHeader(const BenchResult& r) {
  std::ostringstream md;
  md << "- scene: `" << r.scene << "`, camera path: `" << r.path << "` (" << r.frame_indices.size() << " of "
     << r.path_frames << " frames measured), size " << r.width << "x" << r.height << "\n";
  md << "- renderer: " << r.renderer << "\n";
  md << "- machine: " << r.machine.hostname << ", " << r.machine.cpu << " (" << r.machine.logical_cores
     << " logical cores), " << r.machine.os << "\n";
  md << "- date: " << r.date << "\n";
  md << "- allocator: " << r.allocator << "\n";
  md << "- frame time: CPU wall clock from the mode's selection through every pass to glFinish; modes run "
        "interleaved (each frame every mode in turn, the order rotated per frame) after one untimed warm-up frame "
        "each; percentiles interpolate linearly between closest ranks.\n";
  md << "- speedup vs full = median ms of full / median ms of the mode.\n";
  if (r.baseline_added) md << "- \"full\" was not asked for; it ran anyway as the baseline.\n";
  if (r.reference)
    md << "- error against full-geometry reference frames: PSNR (identical frames are capped at "
       << fmt("%.0f", kPsnrCapDb) << " dB), SSIM, share of pixels off by more than " << r.bad_pixel_threshold
       << "/255; cracks = share of pixels where the reference shows geometry and the mode's frame shows sky "
          "(object ids); parallax = 99th percentile, over the pixels that show an object, of the distance (pixels) "
          "from each pixel to where the reference shows the object drawn there (0 where the objects agree; object "
          "ids, eval/parallax_error.h), mean and worst over the frames; n/a for modes whose impostors carry no object "
          "ids.\n"
       << "- frames over bound = frames whose parallax (99th percentile, px) exceeds the error bound: --error-px "
          "when given, else the bound the mode reports (marked (mode)); \"-\" = no bound; counted over the frames "
          "whose parallax could be measured. Popping = how much the mode's image changes between consecutive measured "
          "frames beyond the reference's own change (mean absolute RGB difference, 8-bit units, clamped at 0; "
          "eval/temporal_error.h): a representation switch that pops shows as a peak.\n";
  else
    md << "- no reference frames (run with --reference for image error).\n";
  return md.str();
}

// "bound px | frames over bound": "-" without a bound; "k of n" frames checked (n/a when none could be).
std::string boundCells(const ModeResult& m) {
  if (!m.error_bound_px) return "- | -";
  std::string bound = fmt("%.2f", *m.error_bound_px) + (m.error_bound_source == "mode" ? " (mode)" : "");
  if (m.frames_checked == 0) return bound + " | n/a";
  return bound + " | " + std::to_string(m.frames_over_bound) + " of " + std::to_string(m.frames_checked);
}

std::string markdownTable(const BenchResult& r) {
  std::ostringstream md;
  md << "| mode | median ms | p95 ms | p99 ms | max ms | GPU median ms | triangles | draw calls | objects | "
        "speedup vs full | PSNR mean dB | PSNR min dB | SSIM mean | pixels > "
     << r.bad_pixel_threshold << "/255 | cracks | parallax px mean | parallax px max | bound px | frames over bound | "
        "popping mean | popping p99 | popping max |\n";
  md << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
        "---:|\n";
  for (const ModeResult& m : r.modes) {
    md << "| " << m.name << " | " << fmt("%.2f", m.wall.median) << " | " << fmt("%.2f", m.wall.p95) << " | "
       << fmt("%.2f", m.wall.p99) << " | " << fmt("%.2f", m.wall.max) << " | " << fmt("%.2f", m.gpu.median)
       << " | " << fmt("%.0f", m.mean_triangles) << " | " << fmt("%.1f", m.mean_draw_calls) << " | "
       << fmt("%.1f", m.mean_objects) << " | " << fmt("%.2f", m.speedup_vs_full) << "x | ";
    if (m.has_errors) {
      const auto psnr = [](double v) { return v >= kPsnrCapDb ? std::string("identical") : fmt("%.2f", v); };
      md << psnr(m.psnr_db_mean) << " | " << psnr(m.psnr_db_min) << " | " << fmt("%.4f", m.ssim_mean) << " | "
         << fmt("%.3f", 100.0 * m.bad_pixel_share_mean) << "% | " << fmt("%.3f", 100.0 * m.crack_share_mean)
         << "% | " << (m.has_parallax ? fmt("%.2f", m.parallax_px_mean) : std::string("n/a")) << " | "
         << (m.has_parallax ? fmt("%.2f", m.parallax_px_max) : std::string("n/a")) << " | "
         << boundCells(m) << " | ";
      if (m.has_popping)
        md << fmt("%.3f", m.popping_summary.mean) << " | " << fmt("%.3f", m.popping_summary.p99) << " | "
           << fmt("%.3f", m.popping_summary.max) << " |\n";
      else
        md << "n/a | n/a | n/a |\n";
    } else {
      md << "n/a | n/a | n/a | n/a | n/a | n/a | n/a | " << boundCells(m) << " | n/a | n/a | n/a |\n";
    }
  }
  return md.str();
}

void writeText(const std::string& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  if (!out) throw Error(file, "cannot open for writing");
  out << text;
  if (!out) throw Error(file, "write failed");
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
    const bool sample = sample_at.count(k) != 0;
    SampleFrame sample_frame;
    sample_frame.path_frame = path_frame;
    const std::string tag = frameTag(path_frame);
    for (size_t j = 0; j < mode_count; ++j) {
      const size_t m = (k + j) % mode_count;
      ModeResult& mode_result = result.modes[m];
      // The first render; the repeats are later passes over the path (below).
      mode_result.frames.push_back(runner.run(*modes[m], camera, path_frame));
      mode_result.order.push_back(int(j));
      if (options.reference || sample) {
        image::ColorImage frame = target.readColor();
        image::IdImage ids;
        if (options.reference) {
          image::ImageMetrics e = image::compareImages(reference, frame, options.bad_pixel_threshold);
          if (!(e.psnr_db < kPsnrCapDb)) e.psnr_db = kPsnrCapDb;  // +inf (identical) and above the cap
          mode_result.errors.push_back(e);
          ids = target.readIds();
          mode_result.crack_shares.push_back(crackShare(reference_ids, ids));
          mode_result.parallax_px.push_back(frameParallaxPx(reference_ids, ids, scene.objects.size()));
          mode_result.popping.push_back(
              k == 0 ? std::numeric_limits<double>::quiet_NaN()
                     : poppingError(previous_frame[m], frame, previous_reference, reference));
        }
        if (sample) {
          const std::string name = "frames/" + tag + "_" + fileSafe(mode_result.name) + ".png";
          image::writePng((out_dir / name).string(), frame);
          sample_frame.mode_png[mode_result.name] = name;
          if (options.reference) {
            const std::string diff = "frames/" + tag + "_" + fileSafe(mode_result.name) + "_diff.png";
            image::writePng((out_dir / diff).string(), image::diffHeatmap(reference, frame));
            sample_frame.diff_png[mode_result.name] = diff;
            if (!std::isnan(mode_result.parallax_px.back())) {
              // Where objects are drawn away from where the reference shows them: the parallax error per pixel.
              const std::string par = "frames/" + tag + "_" + fileSafe(mode_result.name) + "_parallax.png";
              image::writePng((out_dir / par).string(), parallaxHeatmap(reference_ids, ids));
            }
          }
        }
        if (options.reference) previous_frame[m] = std::move(frame);
      }
      progress.advance();
    }
    if (sample) {
      if (options.reference) {
        sample_frame.reference_png = "frames/" + tag + "_reference.png";
        image::writePng((out_dir / sample_frame.reference_png).string(), reference);
      }
      result.samples.push_back(std::move(sample_frame));
    }
    if (options.reference) previous_reference = std::move(reference);
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
      m.over_bound[k] = m.parallax_px[k] > *m.error_bound_px ? 1 : 0;
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

void writeBenchJson(const BenchResult& r, const std::string& file) {
  using Json = nlohmann::ordered_json;
  Json j;
  j["scene"] = r.scene;
  j["path"] = r.path;
  j["path_frames"] = r.path_frames;
  j["frames"] = r.frame_indices.size();
  j["size"] = {r.width, r.height};
  j["renderer"] = r.renderer;
  j["date"] = r.date;
  j["machine"] = {{"hostname", r.machine.hostname},
                  {"os", r.machine.os},
                  {"cpu", r.machine.cpu},
                  {"logical_cores", r.machine.logical_cores}};
  j["baseline"] = "full";
  j["baseline_added"] = r.baseline_added;
  j["reference"] = r.reference;
  j["warmup_frames_per_mode"] = 1;
  j["percentiles"] = "linear interpolation between closest ranks";
  j["psnr_cap_db"] = kPsnrCapDb;
  j["bad_pixel_threshold"] = r.bad_pixel_threshold;
  j["allocator"] = {{"applied", r.allocator_applied}, {"description", r.allocator}};
  Json modes = Json::object();
  for (const ModeResult& m : r.modes) {
    Json e;
    e["median_ms"] = m.wall.median;
    e["p95_ms"] = m.wall.p95;
    e["p99_ms"] = m.wall.p99;
    e["max_ms"] = m.wall.max;
    e["mean_ms"] = m.wall.mean;
    e["gpu_median_ms"] = m.gpu.median;
    e["gpu_p95_ms"] = m.gpu.p95;
    e["mean_triangles"] = m.mean_triangles;
    e["mean_draw_calls"] = m.mean_draw_calls;
    e["mean_objects"] = m.mean_objects;
    e["speedup_vs_full"] = m.speedup_vs_full;
    if (m.has_errors) {
      e["psnr_db_mean"] = m.psnr_db_mean;
      e["psnr_db_min"] = m.psnr_db_min;
      e["ssim_mean"] = m.ssim_mean;
      e["bad_pixel_share_mean"] = m.bad_pixel_share_mean;
      e["crack_share_mean"] = m.crack_share_mean;
      e["parallax_p99_px_mean"] = m.has_parallax ? Json(m.parallax_px_mean) : Json(nullptr);
      e["parallax_p99_px_max"] = m.has_parallax ? Json(m.parallax_px_max) : Json(nullptr);
      e["popping_mean"] = m.has_popping ? Json(m.popping_summary.mean) : Json(nullptr);
      e["popping_p99"] = m.has_popping ? Json(m.popping_summary.p99) : Json(nullptr);
      e["popping_max"] = m.has_popping ? Json(m.popping_summary.max) : Json(nullptr);
    } else {
      e["popping_mean"] = nullptr;
      e["popping_p99"] = nullptr;
      e["popping_max"] = nullptr;
      e["parallax_p99_px_mean"] = nullptr;
      e["parallax_p99_px_max"] = nullptr;
      e["psnr_db_mean"] = nullptr;
      e["psnr_db_min"] = nullptr;
      e["ssim_mean"] = nullptr;
      e["bad_pixel_share_mean"] = nullptr;
      e["crack_share_mean"] = nullptr;
    }
    e["error_bound_px"] = m.error_bound_px ? Json(*m.error_bound_px) : Json(nullptr);
    e["error_bound_source"] = m.error_bound_px ? Json(m.error_bound_source) : Json(nullptr);
    const bool checked = m.error_bound_px && m.frames_checked > 0;
    e["frames_over_bound"] = checked ? Json(m.frames_over_bound) : Json(nullptr);
    e["frames_checked_against_bound"] = m.frames_checked;
    e["t_max_ms"] = r.t_max_ms ? Json(*r.t_max_ms) : Json(nullptr);
    e["frames_over_tmax"] = r.t_max_ms ? Json(m.frames_over_tmax) : Json(nullptr);
    e["repeats"] = r.repeats;
    Json info = Json::object();
    for (const auto& [key, value] : m.info) info[key] = value;
    e["info"] = info;
    modes[m.name] = e;
  }
  j["modes"] = modes;
  Json samples = Json::array();
  for (const SampleFrame& s : r.samples) {
    Json e;
    e["path_frame"] = s.path_frame;
    e["reference"] = s.reference_png;
    e["modes"] = s.mode_png;
    e["diffs"] = s.diff_png;
    samples.push_back(e);
  }
  j["samples"] = samples;
  j["plots"] = r.plots;
  writeText(file, j.dump(2) + "\n");
}

void writeBenchMarkdown(const BenchResult& r, const std::string& file) {
  writeText(file, "# Walkthrough benchmark\n\n" + markdownHeader(r) + "\n" + markdownTable(r));
}

void writeFramesCsv(const BenchResult& r, const std::string& file) {
  std::ostringstream out;
  out << "frame,path_frame,mode,order,wall_ms,gpu_ms,triangles,draw_calls,objects,psnr_db,ssim,bad_pixel_share,"
         "parallax_p99_px,over_bound,popping\n";
  char line[512];
  for (size_t k = 0; k < r.frame_indices.size(); ++k) {
    for (const ModeResult& m : r.modes) {
      if (k >= m.frames.size()) continue;
      const FrameRecord& f = m.frames[k];
      std::snprintf(line, sizeof(line), "%zu,%zu,%s,%d,%.4f,%.4f,%llu,%u,%u,", k, f.path_frame, m.name.c_str(),
                    k < m.order.size() ? m.order[k] : 0, f.wall_ms, f.gpu_ms, (unsigned long long)f.triangles,
                    f.draw_calls, f.objects);
      out << line;
      if (k < m.errors.size()) {
        const image::ImageMetrics& e = m.errors[k];
        const double p = k < m.parallax_px.size() ? m.parallax_px[k] : std::numeric_limits<double>::quiet_NaN();
        std::snprintf(line, sizeof(line), "%.4f,%.6f,%.6f,", e.psnr_db, e.ssim, e.bad_pixel_share);
        out << line << (std::isnan(p) ? std::string() : fmt("%.3f", p)) << ",";
      } else {
        out << ",,,,";
      }
      // over_bound: "-" without a bound, empty when not checked, else 1 or 0.
      if (!m.error_bound_px)
        out << "-";
      else if (k < m.over_bound.size() && m.over_bound[k] >= 0)
        out << m.over_bound[k];
      out << ",";
      const double pop = k < m.popping.size() ? m.popping[k] : std::numeric_limits<double>::quiet_NaN();
      out << (std::isnan(pop) ? std::string() : fmt("%.4f", pop)) << "\n";
    }
  }
  writeText(file, out.str());
}

void writeBenchOutputs(const BenchResult& r, const std::string& out_dir) {
  fs::create_directories(out_dir);
  const fs::path dir(out_dir);
  writeBenchJson(r, (dir / "bench.json").string());
  writeBenchMarkdown(r, (dir / "bench.md").string());
  writeFramesCsv(r, (dir / "frames.csv").string());
}

std::vector<std::string> runPlotScript(const std::string& out_dir, const std::string& script,
                                       const std::string& python) {
  std::vector<std::string> plots;
  if (script.empty() || !fs::exists(script)) {
    FF_WARN("plot script '" << script << "' not found; no plots (give --plot-script)");
    return plots;
  }
  std::vector<std::string> candidates;
  const char* env = std::getenv("FF_PYTHON");
  for (const std::string& c : {python, std::string(env ? env : ""), std::string("python3"),
                               std::string("/usr/bin/python3")})
    if (!c.empty() && std::find(candidates.begin(), candidates.end(), c) == candidates.end())
      candidates.push_back(c);
  // The script's own names; removed first so that a failed run cannot pass off stale plots as new.
  const std::vector<std::string> names{"frame_time.png", "error.png", "parallax.png", "popping.png"};
  for (const std::string& n : names) fs::remove(fs::path(out_dir) / n);
  // Probe quietly for an interpreter with matplotlib (python3 on PATH may be a virtual environment without it,
  // while the system one has it), then run the script once with the first that has it.
  std::string chosen;
  for (const std::string& py : candidates) {
    const std::string probe = shellQuote(py) + " -c 'import matplotlib' >/dev/null 2>&1";
    const int status = std::system(probe.c_str());
    if (status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0) {
      chosen = py;
      break;
    }
  }
  if (chosen.empty()) {
    std::string tried;
    for (const std::string& c : candidates) tried += (tried.empty() ? "" : ", ") + c;
    FF_WARN("no python with matplotlib found (tried " << tried << "); bench continues without plots");
    return plots;
  }
  const std::string command = shellQuote(chosen) + " " + shellQuote(script) + " " + shellQuote(out_dir);
  std::fflush(stdout);
  const int status = std::system(command.c_str());
  const int code = (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
  if (code != 0) {
    FF_WARN(chosen << " " << script << " failed (exit code " << code << "); no plots");
    return plots;
  }
  for (const std::string& n : names)
    if (fs::exists(fs::path(out_dir) / n)) plots.push_back(n);
  return plots;
}

void writeReport(const BenchResult& r, const std::string& out_dir, const std::string& report_file) {
  const fs::path report_dir = fs::absolute(fs::path(report_file)).parent_path();
  fs::create_directories(report_dir);
  // Links relative to the report, so the report and its images can be moved together.
  const auto link = [&](const std::string& relative_to_out) {
    const fs::path target = fs::absolute(fs::path(out_dir) / relative_to_out);
    return fs::proximate(target, report_dir).generic_string();
  };
  std::ostringstream md;
  md << "# Walkthrough benchmark report\n\n" << markdownHeader(r) << "\n## Frame time and image error\n\n"
     << markdownTable(r) << "\n";
  md << "Per-frame numbers: [frames.csv](" << link("frames.csv") << "), summary: [bench.json](" << link("bench.json")
     << ").\n\n";
  if (!r.plots.empty()) {
    md << "## Plots\n\n";
    for (const std::string& p : r.plots) md << "![" << fs::path(p).stem().string() << "](" << link(p) << ")\n\n";
  }
  if (!r.samples.empty()) {
    md << "## Sample frames\n\n";
    if (r.reference)
      md << "Each mode's frame, with the difference heat map against the full-geometry reference below it (black = "
            "equal; blue, red, yellow, white = growing difference).\n\n";
    for (const SampleFrame& s : r.samples) {
      md << "### Path frame " << s.path_frame << "\n\n|";
      if (!s.reference_png.empty()) md << " reference |";
      for (const ModeResult& m : r.modes) md << " " << m.name << " |";
      md << "\n|";
      const size_t columns = r.modes.size() + (s.reference_png.empty() ? 0 : 1);
      for (size_t c = 0; c < columns; ++c) md << "---|";
      md << "\n|";
      if (!s.reference_png.empty()) md << " ![reference](" << link(s.reference_png) << ") |";
      for (const ModeResult& m : r.modes) {
        auto it = s.mode_png.find(m.name);
        md << " " << (it == s.mode_png.end() ? "" : "![" + m.name + "](" + link(it->second) + ")") << " |";
      }
      md << "\n";
      if (!s.diff_png.empty()) {
        md << "|";
        if (!s.reference_png.empty()) md << " |";
        for (const ModeResult& m : r.modes) {
          auto it = s.diff_png.find(m.name);
          md << " " << (it == s.diff_png.end() ? "" : "![" + m.name + " diff](" + link(it->second) + ")") << " |";
        }
        md << "\n";
      }
      md << "\n";
    }
  }
  writeText(report_file, md.str());
}

}  // namespace farfield::eval
