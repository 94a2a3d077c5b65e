// Errors in three tiers (DESIGN.md): FF_CHECK for internal invariants, farfield::Error for bad user input,
// and counted skips (see skip_counter.h) for input that is dropped but reported.
#pragma once

#include <stdexcept>
#include <string>

namespace farfield {

// Bad user input: a file, an argument, degenerate geometry. The message names the input, the place in it and
// what was expected, e.g. "city.obj: vertex 12: NaN coordinate". The CLI prints "error: <what()>" and exits 2.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  // "<source>: <message>"; source is usually a file path.
  Error(const std::string& source, const std::string& message) : std::runtime_error(source + ": " + message) {}
};

}  // namespace farfield
