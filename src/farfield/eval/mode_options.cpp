#include "farfield/eval/mode_options.h"

#include <cmath>
#include <stdexcept>

#include "farfield/core/check.h"
#include "farfield/core/checked_cast.h"
#include "farfield/core/error.h"

namespace farfield::eval {

namespace {

Error bad(const std::string& key, const std::string& expected, const std::string& text) {
  return Error("--mode-option " + key, "expected " + expected + ", got '" + text + "'");
}

std::string shortNumber(double v) {
  std::string s = std::to_string(v);
  s.erase(s.find_last_not_of('0') + 1);
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

}  // namespace

double numberOption(const ModeContext& context, const std::string& key, double fallback, double lo, double hi) {
  const std::string text = context.option(key);
  if (text.empty()) return fallback;
  const std::string expected = hi == std::numeric_limits<double>::max()
                                   ? "a number >= " + shortNumber(lo)
                                   : "a number in [" + shortNumber(lo) + ", " + shortNumber(hi) + "]";
  try {
    size_t used = 0;
    const double v = std::stod(text, &used);
    if (used != text.size() || !std::isfinite(v) || v < lo || v > hi) throw std::invalid_argument("range");
    return v;
  } catch (const std::exception&) {
    throw bad(key, expected, text);
  }
}

double positiveOption(const ModeContext& context, const std::string& key, double fallback) {
  const std::string text = context.option(key);
  if (text.empty()) return fallback;
  try {
    size_t used = 0;
    const double v = std::stod(text, &used);
    if (used != text.size() || !std::isfinite(v) || !(v > 0.0)) throw std::invalid_argument("range");
    return v;
  } catch (const std::exception&) {
    throw bad(key, "a positive number", text);
  }
}

size_t countOption(const ModeContext& context, const std::string& key, size_t fallback, size_t lo, size_t hi) {
  const std::string text = context.option(key);
  if (text.empty()) return fallback;
  const std::string expected = hi == std::numeric_limits<size_t>::max()
                                   ? "a whole number >= " + std::to_string(lo)
                                   : "a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  try {
    size_t used = 0;
    const long long n = std::stoll(text, &used);
    if (used != text.size() || !fitsIn<size_t>(n) || size_t(n) < lo || size_t(n) > hi)
      throw std::invalid_argument("range");
    return size_t(n);
  } catch (const std::exception&) {
    throw bad(key, expected, text);
  }
}

int intOption(const ModeContext& context, const std::string& key, int fallback, int lo, int hi) {
  FF_CHECK(0 <= lo && lo <= hi);
  return checkedCast<int>(countOption(context, key, size_t(fallback), size_t(lo), size_t(hi)), "--mode-option " + key,
                          "value");
}

uint64_t mebibytesOption(const ModeContext& context, const std::string& key, uint64_t fallback_bytes, double lo_mb,
                         double hi_mb) {
  if (context.option(key).empty()) return fallback_bytes;
  // The range keeps the product within uint64_t; the checked conversion says so if a caller widens it too far.
  return checkedCast<uint64_t>(numberOption(context, key, 0.0, lo_mb, hi_mb) * 1048576.0, "--mode-option " + key,
                               "bytes");
}

std::string choiceOption(const ModeContext& context, const std::string& key, const std::string& fallback,
                         std::initializer_list<const char*> choices) {
  const std::string text = context.option(key, fallback);
  std::string list;
  for (const char* c : choices) {
    if (text == c) return text;
    list += (list.empty() ? "" : ", ") + std::string(c);
  }
  throw bad(key, "one of " + list, text);
}

bool switchOption(const ModeContext& context, const std::string& key, bool fallback) {
  const std::string text = context.option(key);
  if (text.empty()) return fallback;
  if (text == "on" || text == "1" || text == "true" || text == "yes") return true;
  if (text == "off" || text == "0" || text == "false" || text == "no") return false;
  throw bad(key, "on or off", text);
}

void checkEveryOptionRead(const ModeContext& context) {
  for (const auto& [key, value] : context.options) {
    if (context.read_keys->count(key)) continue;
    std::string known;
    for (const std::string& k : *context.read_keys) known += (known.empty() ? "" : ", ") + k;
    throw Error("--mode-option " + key, "no mode of this run reads it (the modes read: " +
                                            (known.empty() ? std::string("nothing") : known) + ")");
  }
}

}  // namespace farfield::eval
