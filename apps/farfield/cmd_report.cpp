// farfield report BENCH_DIR [-o report.html] [--mode M] [--database DIR] [--title T] [--notes FILE]
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

#include "command.h"
#include "farfield/core/error.h"
#include "farfield/eval/html_report.h"

namespace farfield::app {
namespace {

struct ReportArgs {
  std::string bench_dir, output, notes_file;
  eval::HtmlReportOptions options;
};

void runReport(ReportArgs& args) {
  if (!args.notes_file.empty()) {
    std::ifstream in(args.notes_file);
    if (!in) throw Error(args.notes_file, "cannot be read");
    std::ostringstream s;
    s << in.rdbuf();
    args.options.notes = s.str();
  }
  const std::string output = args.output.empty() ? args.bench_dir + "/report.html" : args.output;
  eval::writeHtmlReport(args.bench_dir, output, args.options);
  std::printf("wrote %s\n", output.c_str());
}

const RegisterCommand reg("report", [](CLI::App& app) {
  auto args = std::make_shared<ReportArgs>();
  auto* cmd = app.add_subcommand("report", "Write a benchmark run (farfield bench -o DIR) as one self-contained web "
                                           "page: the verdict of the two promises, the table, plots, sample frames.");
  cmd->add_option("bench_dir", args->bench_dir, "Directory written by farfield bench")->required();
  cmd->add_option("-o,--output", args->output, "Page to write (default BENCH_DIR/report.html)");
  cmd->add_option("--mode", args->options.mode, "Mode the verdict is about (default: placed, mmi-dynamic, mmi or "
                                                "smi, whichever the run has)");
  cmd->add_option("--database", args->options.database, "Impostor database whose size the verdict states");
  cmd->add_option("--title", args->options.title, "Page title")->capture_default_str();
  cmd->add_option("--notes", args->notes_file, "Text file shown under the table (how the run was made)");
  cmd->callback([args] { runReport(*args); });
});

}  // namespace
}  // namespace farfield::app
