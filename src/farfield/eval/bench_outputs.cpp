// bench.json, bench.md, frames.csv, the plots and the markdown report of a walkthrough benchmark (eval/bench.h).
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/number_format.h"
#include "farfield/eval/bench.h"

namespace fs = std::filesystem;

namespace farfield::eval {
namespace {

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
  md << "- own CPU = Farfield's own CPU time per frame: wall time less the time inside GL calls that do or wait for "
        "GPU work (draws, dispatches, clears, waits; on llvmpipe the rasterizer's own work) and less the harness's "
        "waits (gpu/gl_counters.h). GL calls, uploads (buffer, texture and uniform bytes from the CPU) and syncs "
        "(calls that wait for the GPU: readbacks, glFinish, query results not yet available) are means per frame, "
        "counted at every GL call; they do not depend on the machine.\n";
  if (r.baseline_added) md << "- \"full\" was not asked for; it ran anyway as the baseline.\n";
  if (r.reference)
    md << "- error against full-geometry reference frames: PSNR (identical frames are capped at "
       << formatNumber("%.0f", kPsnrCapDb) << " dB), SSIM, share of pixels off by more than " << r.bad_pixel_threshold
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
  std::string bound = formatNumber("%.2f", *m.error_bound_px) + (m.error_bound_source == "mode" ? " (mode)" : "");
  if (m.frames_checked == 0) return bound + " | n/a";
  return bound + " | " + std::to_string(m.frames_over_bound) + " of " + std::to_string(m.frames_checked);
}

std::string markdownTable(const BenchResult& r) {
  std::ostringstream md;
  md << "| mode | median ms | p95 ms | p99 ms | max ms | GPU median ms | own CPU median ms | triangles | draw calls | "
        "GL calls | uploaded KB | syncs | objects | speedup vs full | PSNR mean dB | PSNR min dB | SSIM mean | pixels > "
     << r.bad_pixel_threshold << "/255 | cracks | parallax px mean | parallax px max | bound px | frames over bound | "
        "popping mean | popping p99 | popping max |\n";
  md << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
        "---:|---:|---:|---:|\n";
  for (const ModeResult& m : r.modes) {
    const auto counted = [&](const std::string& v) { return m.calls.counted ? v : std::string("n/a"); };
    md << "| " << m.name << " | " << formatNumber("%.2f", m.wall.median) << " | " << formatNumber("%.2f", m.wall.p95)
       << " | " << formatNumber("%.2f", m.wall.p99) << " | " << formatNumber("%.2f", m.wall.max) << " | "
       << formatNumber("%.2f", m.gpu.median) << " | " << counted(formatNumber("%.3f", m.cpu.median)) << " | "
       << formatNumber("%.0f", m.mean_triangles) << " | " << formatNumber("%.1f", m.mean_draw_calls) << " | "
       << counted(formatNumber("%.0f", m.calls.gl_calls_mean)) << " | "
       << counted(formatNumber("%.1f", m.calls.upload_bytes_mean / 1024.0)) << " | "
       << counted(formatNumber("%.2f", m.calls.syncs_mean)) << " | " << formatNumber("%.1f", m.mean_objects) << " | "
       << formatNumber("%.2f", m.speedup_vs_full) << "x | ";
    if (m.has_errors) {
      const auto psnr = [](double v) { return v >= kPsnrCapDb ? std::string("identical") : formatNumber("%.2f", v); };
      md << psnr(m.psnr_db_mean) << " | " << psnr(m.psnr_db_min) << " | " << formatNumber("%.4f", m.ssim_mean) << " | "
         << formatNumber("%.3f", 100.0 * m.bad_pixel_share_mean) << "% | "
         << formatNumber("%.3f", 100.0 * m.crack_share_mean) << "% | "
         << (m.has_parallax ? formatNumber("%.2f", m.parallax_px_mean) : std::string("n/a")) << " | "
         << (m.has_parallax ? formatNumber("%.2f", m.parallax_px_max) : std::string("n/a")) << " | " << boundCells(m)
         << " | ";
      if (m.has_popping)
        md << formatNumber("%.3f", m.popping_summary.mean) << " | " << formatNumber("%.3f", m.popping_summary.p99)
           << " | " << formatNumber("%.3f", m.popping_summary.max) << " |\n";
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
    // What the frames asked of OpenGL (null where GL calls were not counted).
    const bool counted = m.calls.counted;
    e["cpu_median_ms"] = counted ? Json(m.cpu.median) : Json(nullptr);
    e["cpu_p95_ms"] = counted ? Json(m.cpu.p95) : Json(nullptr);
    e["cpu_max_ms"] = counted ? Json(m.cpu.max) : Json(nullptr);
    e["driver_median_ms"] = counted ? Json(m.calls.driver_ms_median) : Json(nullptr);
    e["mean_gl_calls"] = counted ? Json(m.calls.gl_calls_mean) : Json(nullptr);
    e["max_gl_calls"] = counted ? Json(m.calls.gl_calls_max) : Json(nullptr);
    e["max_draw_calls"] = counted ? Json(m.calls.draw_calls_max) : Json(nullptr);
    e["mean_dispatches"] = counted ? Json(m.calls.dispatches_mean) : Json(nullptr);
    e["mean_upload_bytes"] = counted ? Json(m.calls.upload_bytes_mean) : Json(nullptr);
    e["max_upload_bytes"] = counted ? Json(m.calls.upload_bytes_max) : Json(nullptr);
    e["mean_syncs"] = counted ? Json(m.calls.syncs_mean) : Json(nullptr);
    e["max_syncs"] = counted ? Json(m.calls.syncs_max) : Json(nullptr);
    e["frames_with_syncs"] = counted ? Json(m.calls.frames_with_syncs) : Json(nullptr);
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
    // Governed modes (eval/governed_mode.h): frames drawn at a coarser level and the largest bound kept.
    e["frames_relaxed"] = m.governed ? Json(m.frames_relaxed) : Json(nullptr);
    e["bound_scale_max"] = m.governed ? Json(m.bound_scale_max) : Json(nullptr);
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

// One line per governed mode: the budget, the frames over it, the frames relaxed and the largest bound kept.
std::string governorLines(const BenchResult& r) {
  std::string out;
  for (const ModeResult& m : r.modes) {
    if (!m.governed) continue;
    out += "\n- " + m.name + ": t_max " + (r.t_max_ms ? formatNumber("%.2f", *r.t_max_ms) : std::string("-")) +
           " ms, " + std::to_string(m.frames_over_tmax) + " of " + std::to_string(m.frames.size()) +
           " frames over it; " + std::to_string(m.frames_relaxed) +
           " frames relaxed (drawn at a coarser level), the bound kept up to " +
           formatNumber("%.2f", m.bound_scale_max) + "x the promised one" +
           (m.error_bound_px ? " (" + formatNumber("%.2f", *m.error_bound_px * m.bound_scale_max) + " px)"
                             : std::string()) +
           "\n";
  }
  return out;
}

void writeBenchMarkdown(const BenchResult& r, const std::string& file) {
  writeText(file, "# Walkthrough benchmark\n\n" + markdownHeader(r) + "\n" + markdownTable(r) + governorLines(r));
}

void writeFramesCsv(const BenchResult& r, const std::string& file) {
  std::ostringstream out;
  out << "frame,path_frame,mode,order,wall_ms,gpu_ms,triangles,draw_calls,objects,psnr_db,ssim,bad_pixel_share,"
         "parallax_p99_px,over_bound,popping,cpu_ms,driver_ms,gl_calls,dispatches,upload_bytes,syncs,governor_level,"
         "predicted_ms,corrected_ms,bound_scale,impostors\n";
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
        out << line << (std::isnan(p) ? std::string() : formatNumber("%.3f", p)) << ",";
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
      out << (std::isnan(pop) ? std::string() : formatNumber("%.4f", pop)) << ",";
      // The GL counters: empty where they were not installed.
      if (f.counted)
        std::snprintf(line, sizeof(line), "%.4f,%.4f,%llu,%u,%llu,%u,", f.cpu_ms, f.driver_ms,
                      (unsigned long long)f.gl_calls, f.dispatches, (unsigned long long)f.upload_bytes, f.syncs);
      else
        std::snprintf(line, sizeof(line), ",,,,,,");
      out << line;
      // The governor's decision: empty for a mode without one.
      if (f.governor_level >= 0)
        std::snprintf(line, sizeof(line), "%d,%.4f,%.4f,%.4f,", f.governor_level, f.predicted_ms, f.corrected_ms,
                      f.bound_scale);
      else
        std::snprintf(line, sizeof(line), ",,,,");
      out << line << (f.impostors >= 0 ? std::to_string(f.impostors) : std::string()) << "\n";
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
  const std::vector<std::string> names{"frame_time.png", "error.png", "parallax.png", "popping.png", "governor.png"};
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
