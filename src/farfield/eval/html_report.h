// A benchmark run as one self-contained web page (`farfield report`, `make demo`'s out/demo/report.html): the verdict
// of the two promises first (t_max and the error bound, kept on how many frames, the database's bytes, the speedup
// over full geometry), then the table of every mode, the plots, and a strip of sample frames with their difference
// heat maps against the full-geometry reference. Everything is read from a directory written by `farfield bench`
// (bench.json and the PNGs it names); images are embedded as data URIs, so the page needs no other file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

namespace farfield::eval {

struct HtmlReportOptions {
  std::string title = "Farfield benchmark";
  // The mode the verdict is about; "" = the run's placed, mmi-dynamic, mmi or smi mode, the first of them present,
  // else the last mode by name that is neither "full" nor "culled", else the last one.
  std::string mode;
  std::string database;  // impostor database directory whose bytes the verdict states; "" = not stated
  std::string notes;     // preformatted text under the table (e.g. the commands that made the run)
};

// The first screen: what the run promised and what it kept, for one mode.
struct Verdict {
  std::string mode;
  size_t frames = 0;                 // frames measured
  std::optional<double> t_max_ms;    // the frame budget checked (bench --tmax), none when not checked
  size_t frames_over_tmax = 0;
  std::optional<double> bound_px;    // the error bound checked, none when the mode has none
  size_t frames_checked_against_bound = 0;
  size_t frames_over_bound = 0;
  double speedup_vs_full = 0.0;      // median frame time of the baseline over the mode's
  std::optional<double> speedup_vs_culled;
  std::optional<uint64_t> database_bytes;
  // A governed mode (bench.json "frames_relaxed" not null): frames drawn at a coarser level, and the largest bound
  // kept as a multiple of the promised one. The bound check above is against the bound each frame kept.
  std::optional<size_t> frames_relaxed;
  double bound_scale_max = 1.0;
  // A placement database (`farfield place`: placement.json in HtmlReportOptions::database): the layered impostors it
  // holds and their GPU bytes; none for another database.
  std::optional<size_t> impostors_placed;
  double impostor_gpu_bytes = 0.0;
  // The mode's measured frames that drew an impostor, and their longest stretch (path frames, first and last), from
  // the mode's info (frames_with_impostors, impostor_stretch_*: eval/mmi_mode.h); none when the mode does not say.
  std::optional<size_t> frames_with_impostors;
  std::optional<std::pair<size_t, size_t>> impostor_stretch;

  // Both promises that were checked held on every frame (and the bound was checked on every frame).
  bool kept() const;
};

// The verdict of a bench.json (already parsed; `where` names it in errors). Throws farfield::Error naming `where`
// for a run without the mode asked for, without modes, or with fields of the wrong type, and naming the database's
// placement.json when it is malformed.
Verdict readVerdict(const nlohmann::json& bench, const std::string& where, const HtmlReportOptions& options);

// Total bytes of the regular files under `directory` (recursively); throws farfield::Error naming it when it is
// not a directory.
uint64_t directoryBytes(const std::filesystem::path& directory);

// The page for the run in `bench_dir`. Throws farfield::Error naming the file for a missing or malformed
// bench.json and for an image it names that is missing.
std::string htmlReport(const std::filesystem::path& bench_dir, const HtmlReportOptions& options);

// htmlReport() written to `output` (its directory is created).
void writeHtmlReport(const std::filesystem::path& bench_dir, const std::filesystem::path& output,
                     const HtmlReportOptions& options);

// Text helpers the page is built with (exposed for tests).
std::string base64(const std::string& bytes);
std::string htmlEscape(const std::string& text);

}  // namespace farfield::eval
