// The journal of a bake in progress: append-only JSON lines, each with its CRC-32, fsync'ed per line.
#include "farfield/store/bake_journal.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "farfield/core/error.h"
#include "farfield/store/impostor_store.h"

namespace fs = std::filesystem;

namespace farfield::store {

namespace {

constexpr char kJournalFormat[] = "farfield-bake-journal";

std::string lineFor(const char* key, const nlohmann::json& value, bool header) {
  nlohmann::json line;
  if (header) {
    line["format"] = kJournalFormat;
    line["version"] = 1;
  }
  line["crc32"] = fileCheck(value.dump()).crc32;
  line[key] = value;
  return line.dump() + "\n";
}

// The value under `key` of a line whose CRC-32 matches, else none.
std::optional<nlohmann::json> checkedValue(const std::string& text, const char* key) {
  nlohmann::json line = nlohmann::json::parse(text, nullptr, false);
  if (line.is_discarded() || !line.is_object() || !line.contains(key) || !line.contains("crc32") ||
      !line["crc32"].is_number_unsigned())
    return std::nullopt;
  if (fileCheck(line[key].dump()).crc32 != line["crc32"].get<uint64_t>()) return std::nullopt;
  return line[key];
}

}  // namespace

std::optional<JournalContents> readJournal(const std::string& dir) {
  const std::string path = (fs::path(dir) / kJournalFile).string();
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::nullopt;
  const std::string text = readCheckedFile(path, FileCheck{}, "");
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  const bool ends_cleanly = !text.empty() && text.back() == '\n';
  JournalContents out;
  if (lines.empty()) throw Error(path, "line 1: empty journal (no header): start the bake without --resume");
  const std::optional<nlohmann::json> header = checkedValue(lines[0], "header");
  const nlohmann::json first = nlohmann::json::parse(lines[0], nullptr, false);
  if (!header || !first.is_object() || first.value("format", "") != kJournalFormat || first.value("version", 0) != 1)
    throw Error(path, "line 1: not a version 1 bake journal header, or damaged: start the bake without --resume");
  out.header = *header;
  for (size_t k = 1; k < lines.size(); ++k) {
    const std::optional<nlohmann::json> cell = checkedValue(lines[k], "cell");
    if (cell) {
      out.cells.push_back(*cell);
      continue;
    }
    if (k + 1 == lines.size() && !ends_cleanly) {  // the write the crash interrupted
      ++out.torn_lines;
      continue;
    }
    throw Error(path, "line " + std::to_string(k + 1) + ": damaged cell record (checksum or form)");
  }
  return out;
}

void removeJournal(const std::string& dir) {
  std::error_code ec;
  fs::remove(fs::path(dir) / kJournalFile, ec);
  if (ec) throw Error((fs::path(dir) / kJournalFile).string(), "cannot remove: " + ec.message());
}

JournalWriter::JournalWriter(const std::string& dir, const nlohmann::json& header,
                             const std::vector<nlohmann::json>& cells)
    : path_((fs::path(dir) / kJournalFile).string()) {
  std::string text = lineFor("header", header, true);
  for (const nlohmann::json& c : cells) text += lineFor("cell", c, false);
  writeFileAtomic(path_, text, true);
  fd_ = ::open(path_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd_ < 0) throw Error(path_, std::string("cannot open for appending: ") + std::strerror(errno));
}

JournalWriter::~JournalWriter() {
  if (fd_ >= 0) ::close(fd_);
}

void JournalWriter::append(const nlohmann::json& cell) {
  const std::string line = lineFor("cell", cell, false);
  std::lock_guard lock(mutex_);
  size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw Error(path_, std::string("cannot append: ") + std::strerror(errno));
    done += size_t(n);
  }
  if (::fsync(fd_) != 0) throw Error(path_, std::string("fsync failed: ") + std::strerror(errno));
}

}  // namespace farfield::store
