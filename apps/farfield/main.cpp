// farfield: the command-line front end. Parses arguments, calls the library, prints, returns an exit code:
// 0 success, 1 internal failure, 2 bad input (farfield::Error or bad arguments).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <system_error>

#include "command.h"
#include "farfield/core/error.h"

namespace {

// The release tarball (scripts/make_dist.sh) carries PROJ's proj.db and GDAL's data in share/proj and share/gdal
// next to bin/: point the libraries there unless the environment already names their data (PROJ_DATA, or PROJ_LIB
// before PROJ 9.1; GDAL_DATA). A build tree has no such folders and keeps the libraries' defaults (/usr/share/...).
void useBundledData() {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return;
  const fs::path share = exe.parent_path() / ".." / "share";
  const fs::path proj = fs::weakly_canonical(share / "proj", ec);
  if (!ec && !std::getenv("PROJ_DATA") && !std::getenv("PROJ_LIB") && fs::is_directory(proj, ec)) {
    setenv("PROJ_DATA", proj.c_str(), 0);
    setenv("PROJ_LIB", proj.c_str(), 0);
  }
  const fs::path gdal = fs::weakly_canonical(share / "gdal", ec);
  if (!ec && !std::getenv("GDAL_DATA") && fs::is_directory(gdal, ec)) setenv("GDAL_DATA", gdal.c_str(), 0);
}

}  // namespace

int main(int argc, char** argv) {
  useBundledData();
  CLI::App app{"Farfield: large scenes at a bounded frame time with measured impostor error.", "farfield"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "farfield 0.1.0");
  auto& commands = farfield::app::CommandRegistry::commands();
  std::sort(commands.begin(), commands.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& [name, setup] : commands) setup(app);
  const bool known_command = argc > 1 && std::any_of(commands.begin(), commands.end(),
                                                     [&](const auto& c) { return c.first == argv[1]; });
  if (argc > 1 && argv[1][0] != '-' && !known_command) {
    std::string known;
    for (const auto& [name, setup] : commands) known += (known.empty() ? "" : ", ") + name;
    std::fprintf(stderr, "error: unknown command '%s'; commands: %s\nRun with --help for usage.\n", argv[1],
                 known.c_str());
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    std::fprintf(stderr, "Run with --help for usage.\n");
    return 2;
  } catch (const farfield::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "internal error: %s\n", e.what());
    return 1;
  }
  return 0;
}
