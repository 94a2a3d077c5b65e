#include "farfield/eval/html_report.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/core/number_format.h"

namespace farfield::eval {
namespace fs = std::filesystem;
namespace {

std::string readFileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string(), "cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A number field of a mode, none when absent or null; an error naming the field when it is not a number.
std::optional<double> optionalNumber(const nlohmann::json& mode, const char* key, const std::string& where) {
  const auto it = mode.find(key);
  if (it == mode.end() || it->is_null()) return std::nullopt;
  if (!it->is_number()) throw Error(where, std::string("\"") + key + "\" must be a number");
  return it->get<double>();
}

double number(const nlohmann::json& mode, const char* key, const std::string& where) {
  const std::optional<double> v = optionalNumber(mode, key, where);
  if (!v) throw Error(where, std::string("\"") + key + "\" is missing");
  return *v;
}

const nlohmann::json& modesOf(const nlohmann::json& bench, const std::string& where) {
  if (!bench.is_object()) throw Error(where, "expected a JSON object written by farfield bench");
  const auto it = bench.find("modes");
  if (it == bench.end() || !it->is_object() || it->empty()) throw Error(where, "no \"modes\" in the run");
  return *it;
}

std::string cell(const std::optional<double>& v, const char* fmt, const char* none = "n/a") {
  return v ? formatNumber(fmt, *v) : std::string(none);
}

// MB as `farfield place` and the other commands print them: 2^20 bytes.
std::string megabytes(uint64_t bytes) { return formatNumber("%.1f MB", double(bytes) / 1048576.0); }

std::string dataUri(const fs::path& png) { return "data:image/png;base64," + base64(readFileBytes(png)); }

std::string figure(const fs::path& dir, const std::string& file, const std::string& caption) {
  return "<figure><img src=\"" + dataUri(dir / file) + "\" alt=\"" + htmlEscape(caption) + "\"><figcaption>" +
         htmlEscape(caption) + "</figcaption></figure>\n";
}

const char* kStyle = R"(<style>
body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1400px;padding:0 1em;color:#222}
.verdict{border-radius:8px;padding:1em 1.5em;margin:1em 0;font-size:1.25em}
.kept{background:#e5f5e8;border:2px solid #2e8b47}.broken{background:#fdf1e1;border:2px solid #d08a1e}
.verdict p{margin:.3em 0}.verdict b{font-size:1.1em}
table{border-collapse:collapse;font-size:.9em}td,th{border:1px solid #ccc;padding:.3em .6em;text-align:right}
th{background:#f2f2f2}td:first-child,th:first-child{text-align:left}
figure{display:inline-block;margin:.4em;vertical-align:top}figure img{max-width:440px;display:block}
figcaption{font-size:.8em;color:#555}.plots figure img{max-width:680px}
pre{background:#f6f6f6;padding:1em;overflow-x:auto;font-size:.85em}.meta{color:#555;font-size:.9em}
</style>
)";

}  // namespace

bool Verdict::kept() const {
  if (t_max_ms && frames_over_tmax > 0) return false;
  if (bound_px && (frames_over_bound > 0 || frames_checked_against_bound < frames)) return false;
  return true;
}

std::string base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16 | uint32_t(uint8_t(bytes[i + 1])) << 8 | uint8_t(bytes[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += kAlphabet[(v >> s) & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = uint32_t(uint8_t(bytes[i])) << 16 | uint32_t(uint8_t(bytes[i + 1])) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

std::optional<double> kilobytes(std::optional<double> bytes) {
  if (bytes) return *bytes / 1024.0;
  return std::nullopt;
}

std::string htmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

uint64_t directoryBytes(const fs::path& directory) {
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) throw Error(directory.string(), "not a directory");
  uint64_t bytes = 0;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(directory))
    if (e.is_regular_file()) bytes += e.file_size();
  return bytes;
}

Verdict readVerdict(const nlohmann::json& bench, const std::string& where, const HtmlReportOptions& options) {
  const nlohmann::json& modes = modesOf(bench, where);
  Verdict v;
  v.mode = options.mode;
  if (v.mode.empty()) {
    std::string last;
    for (const auto& [name, mode] : modes.items()) {
      last = name;
      if (name != "full" && name != "culled") v.mode = name;
    }
    if (v.mode.empty()) v.mode = last;
    for (const char* preferred : {"smi", "mmi", "mmi-dynamic", "placed"})
      if (modes.contains(preferred)) v.mode = preferred;
  }
  const auto it = modes.find(v.mode);
  if (it == modes.end()) throw Error(where, "the run has no mode \"" + v.mode + "\"");
  const nlohmann::json& mode = *it;
  const std::string at = where + ": modes." + v.mode;
  const auto frames = bench.find("frames");
  if (frames == bench.end() || !frames->is_number_unsigned()) throw Error(where, "\"frames\" must be a count");
  v.frames = frames->get<size_t>();
  v.t_max_ms = optionalNumber(mode, "t_max_ms", at);
  if (v.t_max_ms) v.frames_over_tmax = size_t(number(mode, "frames_over_tmax", at));
  v.bound_px = optionalNumber(mode, "error_bound_px", at);
  if (v.bound_px) {
    v.frames_over_bound = size_t(number(mode, "frames_over_bound", at));
    v.frames_checked_against_bound = size_t(number(mode, "frames_checked_against_bound", at));
  }
  if (const auto relaxed = mode.find("frames_relaxed"); relaxed != mode.end() && !relaxed->is_null()) {
    v.frames_relaxed = size_t(number(mode, "frames_relaxed", at));
    v.bound_scale_max = number(mode, "bound_scale_max", at);
  }
  v.speedup_vs_full = number(mode, "speedup_vs_full", at);
  if (const auto culled = modes.find("culled"); culled != modes.end() && v.mode != "culled")
    v.speedup_vs_culled = number(*culled, "median_ms", where + ": modes.culled") / number(mode, "median_ms", at);
  if (!options.database.empty()) {
    v.database_bytes = directoryBytes(options.database);
    const fs::path placement = fs::path(options.database) / "placement.json";
    if (fs::exists(placement)) {
      try {
        const nlohmann::json summary = nlohmann::json::parse(readFileBytes(placement)).at("summary");
        v.impostors_placed = summary.at("impostors").get<size_t>();
        v.impostor_gpu_bytes = summary.at("memory_bytes").get<double>();
      } catch (const nlohmann::json::exception& e) {
        throw Error(placement.string(), std::string("no impostor count and memory in its summary: ") + e.what());
      }
    }
  }
  if (const auto info = mode.find("info"); info != mode.end() && info->is_object()) {
    const std::string info_at = at + ".info";
    if (const std::optional<double> with = optionalNumber(*info, "frames_with_impostors", info_at))
      v.frames_with_impostors = size_t(*with);
    const std::optional<double> first = optionalNumber(*info, "impostor_stretch_first_frame", info_at);
    const std::optional<double> last = optionalNumber(*info, "impostor_stretch_last_frame", info_at);
    if (first && last) v.impostor_stretch = std::make_pair(size_t(*first), size_t(*last));
  }
  return v;
}

std::string htmlReport(const fs::path& bench_dir, const HtmlReportOptions& options) {
  const fs::path json_path = bench_dir / "bench.json";
  nlohmann::json bench;
  try {
    bench = nlohmann::json::parse(readFileBytes(json_path));
  } catch (const nlohmann::json::exception& e) {
    throw Error(json_path.string(), std::string("malformed JSON: ") + e.what());
  }
  const std::string where = json_path.string();
  const Verdict v = readVerdict(bench, where, options);
  const nlohmann::json& modes = modesOf(bench, where);

  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" << htmlEscape(options.title)
    << "</title>\n" << kStyle << "</head><body>\n<h1>" << htmlEscape(options.title) << "</h1>\n";

  // The verdict: the first screen.
  h << "<div class=\"verdict " << (v.kept() ? "kept" : "broken") << "\">\n<p><b>" << htmlEscape(v.mode) << "</b>: "
    << (v.kept() ? "both promises kept" : "a promise was broken") << "</p>\n";
  if (v.t_max_ms)
    h << "<p>t_max " << formatNumber("%.3g", *v.t_max_ms) << " ms met on <b>" << (v.frames - v.frames_over_tmax)
      << " of " << v.frames << "</b> frames</p>\n";
  else
    h << "<p>t_max not checked (bench --tmax)</p>\n";
  if (v.bound_px)
    h << "<p>error bound " << formatNumber("%.3g", *v.bound_px) << " px met on <b>"
      << (v.frames_checked_against_bound - v.frames_over_bound) << " of " << v.frames
      << "</b> frames (parallax p99 against the full-geometry reference)</p>\n";
  else
    h << "<p>no error bound for this mode</p>\n";
  if (v.frames_relaxed)
    h << "<p>frame governor: <b>" << *v.frames_relaxed << " of " << v.frames
      << "</b> frames relaxed (drawn at a coarser level)"
      << (*v.frames_relaxed > 0
              ? ", the bound kept up to " + formatNumber("%.3g", v.bound_scale_max) + "x the promised one" +
                    (v.bound_px ? " (" + formatNumber("%.3g", *v.bound_px * v.bound_scale_max) + " px)"
                                : std::string()) +
                    ", each frame checked against the bound it kept"
              : std::string())
      << "</p>\n";
  if (v.database_bytes) h << "<p>database " << megabytes(*v.database_bytes) << "</p>\n";
  if (v.impostors_placed) {
    if (*v.impostors_placed == 0) {
      h << "<p>impostors: <b>none placed</b> (no view was predicted over t_max): every frame is geometry</p>\n";
    } else {
      h << "<p>impostors: <b>" << *v.impostors_placed << " layered impostors</b> placed ("
        << megabytes(uint64_t(v.impostor_gpu_bytes)) << " on the GPU)";
      if (v.frames_with_impostors) {
        h << ", drawn in <b>" << *v.frames_with_impostors << " of " << v.frames << "</b> frames";
        if (v.impostor_stretch)
          h << " (longest stretch: path frames " << v.impostor_stretch->first << "-" << v.impostor_stretch->second
            << ")";
      }
      h << "</p>\n";
    }
  }
  h << "<p>speedup <b>" << formatNumber("%.2fx", v.speedup_vs_full) << "</b> over full geometry";
  if (v.speedup_vs_culled) h << ", " << formatNumber("%.2fx", *v.speedup_vs_culled) << " over view-frustum culling";
  h << " (median frame time)</p>\n";
  {
    // What the verdict's mode asks of the machine per frame (null in runs before GL calls were counted).
    const nlohmann::json& mode = modes[v.mode];
    const std::string at = where + ": modes." + v.mode;
    const std::optional<double> cpu = optionalNumber(mode, "cpu_median_ms", at);
    const std::optional<double> syncs = optionalNumber(mode, "mean_syncs", at);
    if (cpu && syncs)
      h << "<p>Farfield's own CPU time " << formatNumber("%.3f", *cpu) << " ms a frame (median), "
        << formatNumber("%.0f", number(mode, "mean_draw_calls", at)) << " draw calls and "
        << formatNumber("%.2f", *syncs) << " CPU-GPU synchronisations a frame</p>\n";
  }
  h << "</div>\n";

  auto text = [&](const char* key) {
    const auto it = bench.find(key);
    return it != bench.end() && it->is_string() ? it->get<std::string>() : std::string();
  };
  std::string size;
  if (const auto s = bench.find("size"); s != bench.end() && s->is_array() && s->size() == 2)
    size = std::to_string(s->at(0).get<int>()) + "x" + std::to_string(s->at(1).get<int>());
  h << "<p class=\"meta\">scene " << htmlEscape(text("scene")) << ", path " << htmlEscape(text("path")) << ", "
    << v.frames << " frames at " << size << "; " << htmlEscape(text("renderer")) << "; " << htmlEscape(text("date"))
    << "</p>\n";

  // Every mode.
  h << "<h2>Modes</h2>\n<table><tr><th>mode</th><th>median ms</th><th>p95 ms</th><th>p99 ms</th><th>max ms</th>"
       "<th>GPU median ms</th><th>own CPU median ms</th><th>triangles</th><th>draw calls</th><th>GL calls</th>"
       "<th>uploaded KB</th><th>syncs</th><th>speedup</th><th>PSNR dB</th><th>cracks</th>"
       "<th>parallax p99 px</th><th>over bound</th><th>over t_max</th></tr>\n";
  // Baselines first, then the rest by name.
  std::vector<std::string> order;
  for (const char* baseline : {"full", "culled"})
    if (modes.contains(baseline)) order.push_back(baseline);
  for (const auto& [name, mode] : modes.items())
    if (name != "full" && name != "culled") order.push_back(name);
  double psnr_cap = 99.0;
  if (const auto cap = bench.find("psnr_cap_db"); cap != bench.end() && cap->is_number()) psnr_cap = cap->get<double>();
  for (const std::string& name : order) {
    const nlohmann::json& mode = modes[name];
    const std::string at = where + ": modes." + name;
    const std::optional<double> bound = optionalNumber(mode, "error_bound_px", at);
    const std::optional<double> tmax = optionalNumber(mode, "t_max_ms", at);
    const std::optional<double> psnr = optionalNumber(mode, "psnr_db_mean", at);
    const std::optional<double> cracks = optionalNumber(mode, "crack_share_mean", at);
    h << "<tr><td>" << htmlEscape(name) << "</td><td>" << formatNumber("%.2f", number(mode, "median_ms", at))
      << "</td><td>" << formatNumber("%.2f", number(mode, "p95_ms", at)) << "</td><td>"
      << formatNumber("%.2f", number(mode, "p99_ms", at)) << "</td><td>"
      << formatNumber("%.2f", number(mode, "max_ms", at)) << "</td><td>"
      << cell(optionalNumber(mode, "gpu_median_ms", at), "%.2f") << "</td><td>"
      << cell(optionalNumber(mode, "cpu_median_ms", at), "%.3f") << "</td><td>"
      << formatNumber("%.0f", number(mode, "mean_triangles", at)) << "</td><td>"
      << formatNumber("%.0f", number(mode, "mean_draw_calls", at)) << "</td><td>"
      << cell(optionalNumber(mode, "mean_gl_calls", at), "%.0f") << "</td><td>"
      << cell(kilobytes(optionalNumber(mode, "mean_upload_bytes", at)), "%.1f") << "</td><td>"
      << cell(optionalNumber(mode, "mean_syncs", at), "%.2f") << "</td><td>"
      << formatNumber("%.2fx", number(mode, "speedup_vs_full", at)) << "</td><td>"
      << (psnr && *psnr >= psnr_cap ? std::string("identical") : cell(psnr, "%.2f")) << "</td><td>"
      << (cracks ? formatNumber("%.3f%%", *cracks * 100.0) : std::string("n/a")) << "</td><td>"
      << cell(optionalNumber(mode, "parallax_p99_px_mean", at), "%.2f") << "</td><td>"
      << (bound ? std::to_string(size_t(number(mode, "frames_over_bound", at))) + "/" + std::to_string(v.frames)
                : std::string("-"))
      << "</td><td>"
      << (tmax ? std::to_string(size_t(number(mode, "frames_over_tmax", at))) + "/" + std::to_string(v.frames)
               : std::string("-"))
      << "</td></tr>\n";
  }
  h << "</table>\n";
  if (!options.notes.empty()) h << "<h2>How this was made</h2>\n<pre>" << htmlEscape(options.notes) << "</pre>\n";

  // Plots.
  if (const auto plots = bench.find("plots"); plots != bench.end() && plots->is_array() && !plots->empty()) {
    h << "<h2>Per frame</h2>\n<div class=\"plots\">\n";
    for (const nlohmann::json& p : *plots) {
      if (!p.is_string()) throw Error(where, "\"plots\" must hold file names");
      h << figure(bench_dir, p.get<std::string>(), p.get<std::string>());
    }
    h << "</div>\n";
  }

  // Sample frames: the reference, the verdict's mode and its difference heat map.
  if (const auto samples = bench.find("samples"); samples != bench.end() && samples->is_array() && !samples->empty()) {
    h << "<h2>Sample frames</h2>\n<p>Left to right: the full-geometry reference, " << htmlEscape(v.mode)
      << ", and the difference heat map of the two (black: identical).</p>\n";
    for (const nlohmann::json& s : *samples) {
      if (!s.is_object()) throw Error(where, "\"samples\" must hold objects");
      const std::string frame = std::to_string(s.value("path_frame", 0));
      h << "<div>\n";
      auto image = [&](const char* group, const std::string& caption) {
        const auto g = s.find(group);
        if (g == s.end()) return;
        const nlohmann::json* file =
            g->is_string() ? &*g : (g->is_object() && g->contains(v.mode) ? &(*g)[v.mode] : nullptr);
        if (file && file->is_string() && !file->get<std::string>().empty())
          h << figure(bench_dir, file->get<std::string>(), "frame " + frame + ": " + caption);
      };
      image("reference", "reference");
      image("modes", v.mode);
      image("diffs", v.mode + " against the reference");
      h << "</div>\n";
    }
  }
  h << "<p class=\"meta\">Written by farfield report from " << htmlEscape(json_path.string()) << ".</p>\n"
    << "</body></html>\n";
  return h.str();
}

void writeHtmlReport(const fs::path& bench_dir, const fs::path& output, const HtmlReportOptions& options) {
  const std::string page = htmlReport(bench_dir, options);
  if (output.has_parent_path()) fs::create_directories(output.parent_path());
  std::ofstream out(output, std::ios::binary);
  out << page;
  if (!out) throw Error(output.string(), "cannot be written");
}

}  // namespace farfield::eval
