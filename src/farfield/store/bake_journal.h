// The journal of a bake in progress (DIR/bake.journal): what `farfield bake --resume` continues from after a crash.
//
// The store's index (impostor_store.h) is written once, when the bake is complete, so the database in DIR stays
// the previous complete one (or none) at every moment. Beside it, the bake appends one line per finished cell to
// the journal, after that cell's data files are durable (fsync'ed and their directory synced); a killed bake thus
// loses at most the cells in progress. The journal is removed once the index that holds its cells is in place.
//
// Format: JSON lines. The first line is the header {"format": "farfield-bake-journal", "version": 1, "crc32": C,
// "header": H}; every other line {"crc32": C, "cell": R} holds one finished cell, R being the cell's record as the
// index writes it (the index's "cells" element). C is the CRC-32 of H's (R's) compact dump. A last line cut short
// (the crash hit its write) is dropped and counted; a damaged line elsewhere, or a damaged header, is an error
// naming the journal and the line.
#pragma once

#include <cstddef>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace farfield::store {

inline constexpr char kJournalFile[] = "bake.journal";

struct JournalContents {
  nlohmann::json header;
  std::vector<nlohmann::json> cells;  // in the order they finished
  size_t torn_lines = 0;              // a cut last line, dropped
};

// Reads DIR/bake.journal; none when there is no journal. Throws farfield::Error (file, line) for a damaged one.
std::optional<JournalContents> readJournal(const std::string& dir);
// Removes DIR/bake.journal (nothing when absent).
void removeJournal(const std::string& dir);

// Appends finished cells to a journal. Thread-safe.
class JournalWriter {
 public:
  // Writes a new journal holding `header` and `cells` (a resumed bake keeps the cells it read and drops a torn line)
  // atomically over any old one, then opens it for appending.
  JournalWriter(const std::string& dir, const nlohmann::json& header, const std::vector<nlohmann::json>& cells);
  ~JournalWriter();
  JournalWriter(const JournalWriter&) = delete;
  JournalWriter& operator=(const JournalWriter&) = delete;
  // Appends one cell record and fsyncs the journal. The caller has made the cell's files durable first.
  void append(const nlohmann::json& cell);

 private:
  std::string path_;
  int fd_ = -1;
  std::mutex mutex_;
};

}  // namespace farfield::store
