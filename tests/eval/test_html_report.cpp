#include "farfield/eval/html_report.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "eval/eval_test_scenes.h"
#include "farfield/core/error.h"
#include "farfield/eval/bench.h"
#include "farfield/gpu/context.h"
#include "farfield/scene/builtin.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::eval {
namespace {

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

// Decodes base64 the slow, obvious way (an independent check of the encoder).
std::string decodeBase64(const std::string& text) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string bits;
  for (char c : text) {
    if (c == '=') break;
    const size_t v = alphabet.find(c);
    EXPECT_NE(v, std::string::npos);
    for (int b = 5; b >= 0; --b) bits += ((v >> b) & 1) ? '1' : '0';
  }
  std::string out;
  for (size_t i = 0; i + 8 <= bits.size(); i += 8) out += char(std::stoi(bits.substr(i, 8), nullptr, 2));
  return out;
}

TEST(HtmlReport, Base64MatchesTheRfcVectorsAndRoundTrips) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  std::string bytes;
  for (int i = 0; i < 300; ++i) bytes += char((i * 37) & 255);
  EXPECT_EQ(decodeBase64(base64(bytes)), bytes);
}

TEST(HtmlReport, EscapesMarkup) {
  EXPECT_EQ(htmlEscape("a<b>&\"c\""), "a&lt;b&gt;&amp;&quot;c&quot;");
}

TEST(HtmlReport, DirectoryBytesSumsEveryFile) {
  const fs::path dir = test::scratchDir("html_report_bytes");
  fs::create_directories(dir / "sub");
  writeText(dir / "a.bin", std::string(1000, 'x'));
  writeText(dir / "sub" / "b.bin", std::string(234, 'y'));
  EXPECT_EQ(directoryBytes(dir), 1234u);
  EXPECT_THROW(directoryBytes(dir / "a.bin"), Error);
}

nlohmann::json madeUpRun() {
  return nlohmann::json::parse(R"({
    "frames": 10,
    "modes": {
      "full": {"median_ms": 100.0, "speedup_vs_full": 1.0},
      "culled": {"median_ms": 40.0, "speedup_vs_full": 2.5},
      "mmi": {"median_ms": 20.0, "speedup_vs_full": 5.0, "t_max_ms": 30.0, "frames_over_tmax": 3,
              "error_bound_px": 2.0, "frames_over_bound": 0, "frames_checked_against_bound": 10}
    }})");
}

TEST(HtmlReport, VerdictCountsBothPromisesOfTheChosenMode) {
  const nlohmann::json run = madeUpRun();
  const Verdict v = readVerdict(run, "bench.json", {});
  EXPECT_EQ(v.mode, "mmi");
  EXPECT_EQ(v.frames, 10u);
  ASSERT_TRUE(v.t_max_ms.has_value());
  EXPECT_DOUBLE_EQ(*v.t_max_ms, 30.0);
  EXPECT_EQ(v.frames_over_tmax, 3u);
  EXPECT_EQ(v.frames_over_bound, 0u);
  EXPECT_DOUBLE_EQ(v.speedup_vs_full, 5.0);
  ASSERT_TRUE(v.speedup_vs_culled.has_value());
  EXPECT_DOUBLE_EQ(*v.speedup_vs_culled, 2.0);
  EXPECT_FALSE(v.kept());  // 3 frames over t_max

  nlohmann::json kept = run;
  kept["modes"]["mmi"]["frames_over_tmax"] = 0;
  EXPECT_TRUE(readVerdict(kept, "bench.json", {}).kept());
  // A bound checked on fewer frames than were measured is not a kept promise.
  kept["modes"]["mmi"]["frames_checked_against_bound"] = 9;
  EXPECT_FALSE(readVerdict(kept, "bench.json", {}).kept());

  EXPECT_FALSE(v.frames_relaxed.has_value());  // not a governed mode
  nlohmann::json governed = run;
  governed["modes"]["mmi"]["frames_relaxed"] = 4;
  governed["modes"]["mmi"]["bound_scale_max"] = 2.0;
  const Verdict g = readVerdict(governed, "bench.json", {});
  ASSERT_TRUE(g.frames_relaxed.has_value());
  EXPECT_EQ(*g.frames_relaxed, 4u);
  EXPECT_DOUBLE_EQ(g.bound_scale_max, 2.0);
  governed["modes"]["mmi"]["bound_scale_max"] = "two";
  EXPECT_THROW(readVerdict(governed, "bench.json", {}), Error);

  HtmlReportOptions culled;
  culled.mode = "culled";
  const Verdict c = readVerdict(run, "bench.json", culled);
  EXPECT_FALSE(c.t_max_ms.has_value());
  EXPECT_FALSE(c.bound_px.has_value());
  EXPECT_FALSE(c.speedup_vs_culled.has_value());
  EXPECT_TRUE(c.kept());
}

// A placement database's impostors (its placement.json summary) and the frames that drew them (the mode's info).
TEST(HtmlReport, VerdictStatesTheImpostorsPlacedAndTheFramesTheyServed) {
  const fs::path dir = test::scratchDir("html_report_placement");
  writeText(dir / "placement.json", R"({"summary": {"impostors": 7, "memory_bytes": 2621440.0}})");
  nlohmann::json run = madeUpRun();
  run["modes"]["mmi"]["info"] = {{"frames_with_impostors", 6.0}, {"impostor_stretch_first_frame", 4.0},
                                 {"impostor_stretch_last_frame", 12.0}, {"impostor_stretch_frames", 5.0}};
  HtmlReportOptions options;
  options.database = dir.string();
  const Verdict v = readVerdict(run, "bench.json", options);
  ASSERT_TRUE(v.impostors_placed.has_value());
  EXPECT_EQ(*v.impostors_placed, 7u);
  EXPECT_DOUBLE_EQ(v.impostor_gpu_bytes, 2.5 * 1048576.0);
  ASSERT_TRUE(v.frames_with_impostors.has_value());
  EXPECT_EQ(*v.frames_with_impostors, 6u);
  ASSERT_TRUE(v.impostor_stretch.has_value());
  EXPECT_EQ(v.impostor_stretch->first, 4u);
  EXPECT_EQ(v.impostor_stretch->second, 12u);

  // The page says so on its first screen.
  for (auto& [name, mode] : run["modes"].items())
    for (const char* k : {"p95_ms", "p99_ms", "max_ms", "mean_triangles", "mean_draw_calls"}) mode[k] = 1.0;
  writeText(dir / "bench.json", run.dump());
  const std::string page = htmlReport(dir, options);
  EXPECT_NE(page.find("7 layered impostors</b> placed (2.5 MB on the GPU), drawn in <b>6 of 10</b> frames "
                      "(longest stretch: path frames 4-12)"),
            std::string::npos);

  // None placed: said plainly. Without a placement (a pipeline store) or without the mode's info: not stated.
  writeText(dir / "placement.json", R"({"summary": {"impostors": 0, "memory_bytes": 0}})");
  EXPECT_NE(htmlReport(dir, options).find("<b>none placed</b>"), std::string::npos);
  fs::remove(dir / "placement.json");
  EXPECT_FALSE(readVerdict(run, "bench.json", options).impostors_placed.has_value());
  EXPECT_FALSE(readVerdict(madeUpRun(), "bench.json", {}).frames_with_impostors.has_value());
  // A placement.json without its summary names the file.
  writeText(dir / "placement.json", R"({"impostors": []})");
  try {
    readVerdict(run, "bench.json", options);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("placement.json"), std::string::npos) << e.what();
  }
}

TEST(HtmlReport, BadRunsNameTheFileAndWhatIsWrong) {
  HtmlReportOptions missing;
  missing.mode = "placed";
  try {
    readVerdict(madeUpRun(), "x/bench.json", missing);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("x/bench.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("placed"), std::string::npos) << e.what();
  }
  nlohmann::json no_modes = madeUpRun();
  no_modes.erase("modes");
  EXPECT_THROW(readVerdict(no_modes, "bench.json", {}), Error);
  nlohmann::json bad_type = madeUpRun();
  bad_type["modes"]["mmi"]["frames_over_tmax"] = "three";
  EXPECT_THROW(readVerdict(bad_type, "bench.json", {}), Error);

  const fs::path dir = test::scratchDir("html_report_bad");
  try {
    htmlReport(dir, {});
    FAIL() << "expected an error for a missing bench.json";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bench.json"), std::string::npos) << e.what();
  }
  writeText(dir / "bench.json", "{\"frames\": 3, \"modes\": {");
  EXPECT_THROW(htmlReport(dir, {}), Error);
  nlohmann::json with_plot = madeUpRun();
  for (auto& [name, mode] : with_plot["modes"].items())
    for (const char* k : {"p95_ms", "p99_ms", "max_ms", "mean_triangles", "mean_draw_calls"}) mode[k] = 1.0;
  with_plot["plots"] = {"frame_time.png"};
  writeText(dir / "bench.json", with_plot.dump());
  try {
    htmlReport(dir, {});
    FAIL() << "expected an error for a missing plot";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("frame_time.png"), std::string::npos) << e.what();
  }
}

// A real run: culled on builtin:cubes against the reference, with a bound of 1 px (culled is exact: every frame
// keeps it) and a frame budget no frame can keep (0.001 ms).
TEST(HtmlReport, PageOfARealRunIsSelfContainedAndStatesTheVerdict) {
  const fs::path dir = test::scratchDir("html_report_run");
  BenchOptions options;
  options.modes = {"culled"};
  options.width = 64;
  options.height = 64;
  options.frames = 3;
  options.reference = true;
  options.samples = 2;
  options.error_px = 1.0;
  options.t_max_ms = 0.001;
  options.out_dir = dir.string();
  options.scene_label = "builtin:cubes";
  options.path_label = "side walk (test)";
  const scene::Scene scene = scene::builtinScene("cubes");
  const BenchResult result = runBench(gpu::sharedHeadlessContext(), scene, test::sideWalkPath(3), options);
  writeBenchOutputs(result, dir.string());

  HtmlReportOptions report;
  report.title = "Cubes <test>";
  report.database = dir.string() + "/frames";
  report.notes = "farfield bench builtin:cubes --modes culled";
  writeHtmlReport(dir, dir / "page" / "report.html", report);
  std::ifstream in(dir / "page" / "report.html");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string page = ss.str();

  EXPECT_NE(page.find("<title>Cubes &lt;test&gt;</title>"), std::string::npos);
  EXPECT_NE(page.find("class=\"verdict broken\""), std::string::npos);
  EXPECT_NE(page.find("t_max 0.001 ms met on <b>0 of 3</b> frames"), std::string::npos);
  EXPECT_NE(page.find("error bound 1 px met on <b>3 of 3</b> frames"), std::string::npos);
  EXPECT_NE(page.find("farfield bench builtin:cubes --modes culled"), std::string::npos);
  // The verdict's mode (culled, the GPU-driven frame) states what it asks of the machine: no synchronisation.
  EXPECT_NE(page.find("Farfield's own CPU time"), std::string::npos);
  EXPECT_NE(page.find("0.00 CPU-GPU synchronisations a frame"), std::string::npos);
  EXPECT_NE(page.find("<th>own CPU median ms</th>"), std::string::npos);
  // Baselines first; culled draws exactly what full geometry draws.
  ASSERT_NE(page.find("<tr><td>culled</td>"), std::string::npos);
  EXPECT_LT(page.find("<tr><td>full</td>"), page.find("<tr><td>culled</td>"));
  EXPECT_NE(page.find("<td>identical</td>"), std::string::npos);
  // Every image is embedded, and the first one decodes to a PNG.
  const std::regex img("<img src=\"([^\"]*)\"");
  size_t images = 0;
  for (auto it = std::sregex_iterator(page.begin(), page.end(), img); it != std::sregex_iterator(); ++it) {
    const std::string src = (*it)[1];
    ASSERT_EQ(src.rfind("data:image/png;base64,", 0), 0u) << src.substr(0, 60);
    if (images++ == 0) {
      EXPECT_EQ(decodeBase64(src.substr(22)).substr(1, 3), "PNG");
    }
  }
  // The plots the run wrote (bench.json "plots"), and per sample the reference, the mode and its heat map.
  std::ifstream json_in(dir / "bench.json");
  const nlohmann::json run = nlohmann::json::parse(json_in);
  EXPECT_EQ(images, run.at("plots").size() + 2u * 3u);
  EXPECT_EQ(page.find("src=\"frames/"), std::string::npos);
}

}  // namespace
}  // namespace farfield::eval
