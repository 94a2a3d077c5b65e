#include "farfield/eval/mode_options.h"

#include <cmath>
#include <stdexcept>

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

size_t countOption(const ModeContext& context, const std::string& key, size_t fallback, size_t lo) {
  const std::string text = context.option(key);
  if (text.empty()) return fallback;
  try {
    size_t used = 0;
    const long long n = std::stoll(text, &used);
    if (used != text.size() || n < 0 || size_t(n) < lo) throw std::invalid_argument("range");
    return size_t(n);
  } catch (const std::exception&) {
    throw bad(key, "a whole number >= " + std::to_string(lo), text);
  }
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
