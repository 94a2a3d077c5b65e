#include "farfield/scene/off_check.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::scene {
namespace {

constexpr long long kMaxCount = 100'000'000;
constexpr long long kMaxFaceVertices = 1000;

class OffLines {
 public:
  explicit OffLines(const std::string& path) : path_(path), in_(path, std::ios::binary) {
    if (!in_) throw Error(path, "cannot open file");
  }
  // The tokens of the next line that holds any (comments after '#' dropped); false at the end of the file.
  bool next(std::vector<std::string>& tokens) {
    std::string line;
    while (std::getline(in_, line)) {
      ++line_;
      if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
      tokens.clear();
      std::istringstream words(line);
      for (std::string w; words >> w;) tokens.push_back(w);
      if (!tokens.empty()) return true;
    }
    return false;
  }
  [[noreturn]] void fail(const std::string& reason) const {
    throw Error(path_ + ":" + std::to_string(line_), reason);
  }
  void require(bool ok, const std::string& reason) const {
    if (!ok) fail(reason);
  }

 private:
  std::string path_;
  std::ifstream in_;
  long long line_ = 0;
};

bool parseInteger(const std::string& text, long long& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  value = std::strtoll(text.c_str(), &end, 10);
  return errno == 0 && *end == '\0';
}

bool parseNumber(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return *end == '\0' && std::isfinite(value);
}

}  // namespace

void checkOffFile(const std::string& path) {
  OffLines lines(path);
  std::vector<std::string> t;
  lines.require(lines.next(t), "empty file: expected the OFF header");
  std::string header = t[0];
  for (char& c : header) c = char(std::toupper(static_cast<unsigned char>(c)));
  lines.require(header.size() >= 3 && header.compare(header.size() - 3, 3, "OFF") == 0,
                "expected the OFF header, got '" + t[0] + "'");
  std::vector<std::string> counts(t.begin() + 1, t.end());
  if (counts.empty()) {
    lines.require(lines.next(t), "expected the vertex, face and edge counts after the header");
    counts = t;
  }
  long long vertices = -1, faces = -1;
  lines.require(counts.size() >= 2 && parseInteger(counts[0], vertices) && parseInteger(counts[1], faces) &&
                    vertices >= 0 && faces >= 0 && vertices <= kMaxCount && faces <= kMaxCount,
                "expected the vertex and face counts (0 to 100 million)");
  for (long long v = 0; v < vertices; ++v) {
    lines.require(lines.next(t), "the file ends after " + std::to_string(v) + " of " + std::to_string(vertices) +
                                     " vertices");
    double x = 0.0;
    lines.require(t.size() >= 3 && parseNumber(t[0], x) && parseNumber(t[1], x) && parseNumber(t[2], x),
                  "vertex " + std::to_string(v) + ": expected three finite coordinates");
  }
  for (long long f = 0; f < faces; ++f) {
    lines.require(lines.next(t), "the file ends after " + std::to_string(f) + " of " + std::to_string(faces) +
                                     " faces");
    long long n = 0;
    lines.require(parseInteger(t[0], n) && n >= 1 && n <= kMaxFaceVertices,
                  "face " + std::to_string(f) + ": expected its vertex count (1 to 1000), got '" + t[0] + "'");
    lines.require(t.size() >= size_t(n) + 1, "face " + std::to_string(f) + ": expected " + std::to_string(n) +
                                                 " vertex indices");
    for (long long k = 1; k <= n; ++k) {
      long long index = -1;
      lines.require(parseInteger(t[size_t(k)], index) && index >= 0 && index < vertices,
                    "face " + std::to_string(f) + ": vertex index '" + t[size_t(k)] + "' is not one of the " +
                        std::to_string(vertices) + " vertices");
    }
    for (size_t k = size_t(n) + 1; k < t.size(); ++k) {
      double colour = 0.0;
      lines.require(parseNumber(t[k], colour), "face " + std::to_string(f) + ": unexpected '" + t[k] + "'");
    }
  }
}

}  // namespace farfield::scene
