#include "farfield/gpu/glsl_bindings.h"

#include <cctype>
#include <cstdlib>
#include <string>
#include <unordered_map>
#include <vector>

namespace farfield::gpu {

GlslBindings& GlslBindings::operator|=(const GlslBindings& o) {
  buffers.insert(o.buffers.begin(), o.buffers.end());
  written_buffers.insert(o.written_buffers.begin(), o.written_buffers.end());
  images.insert(o.images.begin(), o.images.end());
  written_images.insert(o.written_images.begin(), o.written_images.end());
  samplers.insert(o.samplers.begin(), o.samplers.end());
  return *this;
}

namespace {

// The source with comments replaced by spaces (line breaks kept).
std::string withoutComments(std::string_view s) {
  std::string out(s);
  for (size_t i = 0; i + 1 < out.size(); ++i) {
    if (out[i] == '/' && out[i + 1] == '/') {
      while (i < out.size() && out[i] != '\n') out[i++] = ' ';
    } else if (out[i] == '/' && out[i + 1] == '*') {
      const size_t end = out.find("*/", i + 2);
      const size_t stop = end == std::string::npos ? out.size() : end + 2;
      for (; i < stop; ++i)
        if (out[i] != '\n') out[i] = ' ';
      --i;
    }
  }
  return out;
}

bool identChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// A preprocessor condition (#if, #elif) over the macros defined so far: defined(X), defined X, !, &&, ||, parentheses,
// integers and macros (their integer value, 0 when undefined). Anything else makes the condition true, so that its
// declarations count (the check errs towards more bindings).
class Condition {
 public:
  Condition(std::string_view text, const std::unordered_map<std::string, std::string>& macros)
      : text_(text), macros_(macros) {}
  bool value() {
    const long v = orExpr();
    skipSpace();
    return failed_ || at_ != text_.size() ? true : v != 0;
  }

 private:
  void skipSpace() {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
  }
  bool take(std::string_view token) {
    skipSpace();
    if (text_.substr(at_, token.size()) != token) return false;
    at_ += token.size();
    return true;
  }
  std::string word() {
    skipSpace();
    const size_t start = at_;
    while (at_ < text_.size() && identChar(text_[at_])) ++at_;
    return std::string(text_.substr(start, at_ - start));
  }
  long orExpr() {
    long v = andExpr();
    while (take("||")) v = (andExpr() != 0) || v != 0;
    return v;
  }
  long andExpr() {
    long v = unary();
    while (take("&&")) v = (unary() != 0) && v != 0;
    return v;
  }
  long unary() {
    if (take("!")) return unary() == 0;
    if (take("(")) {
      const long v = orExpr();
      if (!take(")")) failed_ = true;
      return v;
    }
    const std::string w = word();
    if (w.empty()) {
      failed_ = true;
      return 1;
    }
    if (w == "defined") {
      const bool paren = take("(");
      const std::string name = word();
      if (paren && !take(")")) failed_ = true;
      return macros_.count(name) ? 1 : 0;
    }
    if (std::isdigit(static_cast<unsigned char>(w[0]))) return std::atol(w.c_str());
    const auto it = macros_.find(w);
    return it == macros_.end() ? 0 : std::atol(it->second.c_str());
  }
  std::string_view text_;
  const std::unordered_map<std::string, std::string>& macros_;
  size_t at_ = 0;
  bool failed_ = false;
};

// The lines of `text` that the preprocessor keeps, after its conditionals over the macros the text defines.
std::string activeLines(const std::string& text) {
  std::unordered_map<std::string, std::string> macros;
  struct Level {
    bool outer, active, taken;
  };
  std::vector<Level> stack;
  bool active = true;
  std::string out;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    start = end + 1;
    size_t p = line.find_first_not_of(" \t");
    if (p == std::string::npos || line[p] != '#') {
      if (active) out += line + "\n";
      if (end == text.size()) break;
      continue;
    }
    ++p;
    while (p < line.size() && std::isspace(static_cast<unsigned char>(line[p]))) ++p;
    size_t q = p;
    while (q < line.size() && identChar(line[q])) ++q;
    const std::string directive = line.substr(p, q - p);
    const std::string rest = line.substr(q);
    const auto name = [&]() {
      size_t a = rest.find_first_not_of(" \t");
      size_t b = a;
      while (b < rest.size() && identChar(rest[b])) ++b;
      return a == std::string::npos ? std::string() : rest.substr(a, b - a);
    };
    if (directive == "define" && active) {
      const std::string n = name();
      const size_t value = rest.find(n) + n.size();
      const size_t v = rest.find_first_not_of(" \t", value);
      macros[n] = v == std::string::npos ? std::string() : rest.substr(v);
    } else if (directive == "undef" && active) {
      macros.erase(name());
    } else if (directive == "ifdef" || directive == "ifndef" || directive == "if") {
      bool c = true;
      if (directive == "ifdef") c = macros.count(name()) != 0;
      else if (directive == "ifndef") c = macros.count(name()) == 0;
      else c = Condition(rest, macros).value();
      stack.push_back({active, active && c, c});
      active = stack.back().active;
    } else if (directive == "elif" && !stack.empty()) {
      Level& l = stack.back();
      const bool c = !l.taken && Condition(rest, macros).value();
      l.active = l.outer && c;
      l.taken = l.taken || c;
      active = l.active;
    } else if (directive == "else" && !stack.empty()) {
      Level& l = stack.back();
      l.active = l.outer && !l.taken;
      l.taken = true;
      active = l.active;
    } else if (directive == "endif" && !stack.empty()) {
      active = stack.back().outer;
      stack.pop_back();
    }
    if (end == text.size()) break;
  }
  return out;
}

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

GlslBindings glslBindings(std::string_view source) {
  GlslBindings b;
  const std::string text = activeLines(withoutComments(source));
  for (size_t at = text.find("layout"); at != std::string::npos; at = text.find("layout", at + 6)) {
    if ((at > 0 && identChar(text[at - 1])) || (at + 6 < text.size() && identChar(text[at + 6]))) continue;
    size_t open = at + 6;
    while (open < text.size() && std::isspace(static_cast<unsigned char>(text[open]))) ++open;
    if (open >= text.size() || text[open] != '(') continue;
    const size_t close = text.find(')', open);
    if (close == std::string::npos) break;
    // binding = N inside the parentheses
    const std::string inside = text.substr(open + 1, close - open - 1);
    const size_t key = inside.find("binding");
    if (key == std::string::npos) continue;
    size_t p = inside.find('=', key);
    if (p == std::string::npos) continue;
    ++p;
    while (p < inside.size() && std::isspace(static_cast<unsigned char>(inside[p]))) ++p;
    if (p >= inside.size() || !std::isdigit(static_cast<unsigned char>(inside[p]))) continue;
    const int binding = std::atoi(inside.c_str() + p);
    // The words up to the declaration's name: qualifiers, "buffer" or "uniform", the type.
    bool readonly = false, buffer = false, uniform = false;
    std::string type;
    size_t q = close + 1;
    while (q < text.size() && text[q] != ';' && text[q] != '{') {
      if (!identChar(text[q])) {
        ++q;
        continue;
      }
      const size_t start = q;
      while (q < text.size() && identChar(text[q])) ++q;
      const std::string word = text.substr(start, q - start);
      if (word == "readonly") readonly = true;
      else if (word == "buffer") buffer = true;
      else if (word == "uniform") uniform = true;
      else if (type.empty() && (startsWith(word, "image") || startsWith(word, "iimage") ||
                                startsWith(word, "uimage") || startsWith(word, "sampler") ||
                                startsWith(word, "isampler") || startsWith(word, "usampler")))
        type = word;
    }
    if (buffer) {
      b.buffers.insert(binding);
      if (!readonly) b.written_buffers.insert(binding);
    } else if (uniform && type.find("image") != std::string::npos) {
      b.images.insert(binding);
      if (!readonly) b.written_images.insert(binding);
    } else if (uniform && type.find("sampler") != std::string::npos) {
      b.samplers.insert(binding);
    }
  }
  return b;
}

}  // namespace farfield::gpu
