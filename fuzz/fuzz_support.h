// Shared by Farfield's libFuzzer targets (one per input format, docs/FUZZING.md): a scratch directory per process for
// readers that take a path, and the rule every target checks: bad input ends in farfield::Error. Anything else that
// escapes a reader (std::bad_alloc, a JSON library exception, std::out_of_range) is a finding: it is printed and the
// process aborts, which libFuzzer records as a crash with the input that caused it. Sanitizer reports (AddressSanitizer,
// UndefinedBehaviorSanitizer: the library is built with both for FF_FUZZ) are findings too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <typeinfo>
#include <unistd.h>

#include "farfield/core/error.h"
#include "farfield/core/log.h"

namespace farfield::fuzz {

// $TMPDIR/ff-fuzz-PID (/dev/shm when there is no TMPDIR: a file system in memory), created on first use and removed
// at exit. Every target writes its input there.
inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::filesystem::path base = tmp && *tmp ? tmp : "/dev/shm";
    std::error_code ec;
    if (!std::filesystem::is_directory(base, ec)) base = "/tmp";
    std::filesystem::path d = base / ("ff-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(scratch(), ignored);
    });
    return d;
  }();
  return dir;
}

// Empties scratch()/name (a directory the target fills per input) and returns it, created.
inline std::filesystem::path freshDirectory(const std::string& name) {
  const std::filesystem::path d = scratch() / name;
  std::error_code ec;
  std::filesystem::remove_all(d, ec);
  std::filesystem::create_directories(d);
  return d;
}

inline void writeBytes(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

// scratch()/name holding the bytes.
inline std::string writeInput(const std::string& name, const uint8_t* data, size_t size) {
  const std::filesystem::path p = scratch() / name;
  writeBytes(p, std::string_view(reinterpret_cast<const char*>(data), size));
  return p.string();
}

// Farfield's warnings for damaged input are expected by the thousand: only errors are logged.
inline void quietLogs() { setLogLevel(LogLevel::Off); }

// Runs a reader on one input: farfield::Error is the expected answer to bad input, anything else thrown a finding.
// FF_FUZZ_VERBOSE=1 in the environment prints the outcome (to check that seeds are read whole).
template <typename F>
void expectFarfieldErrors(F&& read) {
  static const bool verbose = std::getenv("FF_FUZZ_VERBOSE") != nullptr;  // checking seeds: say what was refused
  try {
    read();
    if (verbose) std::fprintf(stderr, "fuzz: read without error\n");
  } catch (const farfield::Error& e) {
    if (verbose) std::fprintf(stderr, "fuzz: farfield::Error: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: FINDING: %s escaped the reader instead of farfield::Error: %s\n",
                 typeid(e).name(), e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz: FINDING: a non-standard exception escaped the reader\n");
    std::abort();
  }
}

}  // namespace farfield::fuzz
