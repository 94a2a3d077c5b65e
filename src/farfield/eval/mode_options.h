// The one parser of the benchmark modes' options (--mode-option key=value): typed values with their ranges, each
// error naming `--mode-option KEY` and what was expected. Every read marks the key as known to the run, so that
// after the modes are made and prepared the harness can refuse a key no mode of the run reads (a typo such as
// `erorr_px=2` is an error, not a silently ignored wish).
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <string>

#include "farfield/eval/mode.h"

namespace farfield::eval {

// A finite number in [lo, hi]; `fallback` when the key is absent.
double numberOption(const ModeContext& context, const std::string& key, double fallback, double lo,
                    double hi = std::numeric_limits<double>::max());
// A finite number > 0; `fallback` when absent.
double positiveOption(const ModeContext& context, const std::string& key, double fallback);
// A whole number in [lo, hi]; `fallback` when absent.
size_t countOption(const ModeContext& context, const std::string& key, size_t fallback, size_t lo = 1,
                   size_t hi = std::numeric_limits<size_t>::max());
// countOption for an int option: a whole number in [lo, hi] (0 <= lo <= hi); `fallback` when absent.
int intOption(const ModeContext& context, const std::string& key, int fallback, int lo, int hi);
// A memory size given in MiB (a finite number in [lo_mb, hi_mb], fractions allowed), in bytes; `fallback_bytes` when
// absent. The default range ends at 16 TiB.
uint64_t mebibytesOption(const ModeContext& context, const std::string& key, uint64_t fallback_bytes,
                         double lo_mb = 1.0, double hi_mb = 16777216.0);
// One of `choices`; `fallback` when absent.
std::string choiceOption(const ModeContext& context, const std::string& key, const std::string& fallback,
                         std::initializer_list<const char*> choices);
// on/off (also 1/0, true/false, yes/no); `fallback` when absent.
bool switchOption(const ModeContext& context, const std::string& key, bool fallback);

// Throws farfield::Error naming --mode-option and the key for an option of the run that no mode read (call after
// creating and preparing the run's modes), listing the keys that were read.
void checkEveryOptionRead(const ModeContext& context);

}  // namespace farfield::eval
