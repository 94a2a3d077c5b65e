// The bake journal (store/bake_journal.h): what was appended reads back; a cut last line (the crash hit its write)
// is dropped and counted; any other damage, in the header or in the middle, is an error naming the line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "farfield/core/error.h"
#include "farfield/store/bake_journal.h"
#include "farfield/store/impostor_store.h"
#include "support/expect_error.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
void spill(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
}

using test::expectErrorMentions;

TEST(BakeJournalTest, ReadsBackWhatWasAppendedAndDropsOnlyACutLastLine) {
  const fs::path dir = test::scratchDir("journal");
  EXPECT_FALSE(readJournal(dir.string()));
  const nlohmann::json header = {{"index", {{"generation", 3}}}, {"todo", {1, 5, 9}}};
  {
    JournalWriter w(dir.string(), header, {{{"half_edge", 1}}});
    w.append({{"half_edge", 5}, {"x", 0.25}});
    w.append({{"half_edge", 9}});
  }
  auto j = readJournal(dir.string());
  ASSERT_TRUE(j);
  EXPECT_EQ(j->header, header);
  ASSERT_EQ(j->cells.size(), 3u);
  EXPECT_EQ(j->cells[1]["x"].get<double>(), 0.25);
  EXPECT_EQ(j->torn_lines, 0u);

  const fs::path file = dir / kJournalFile;
  const std::string text = slurp(file);
  const size_t last_start = text.rfind('\n', text.size() - 2) + 1;
  // Every cut inside the last line: that cell is lost, the others kept.
  for (size_t cut = last_start + 1; cut + 1 < text.size(); cut += 3) {
    spill(file, text.substr(0, cut));
    j = readJournal(dir.string());
    ASSERT_TRUE(j);
    EXPECT_EQ(j->cells.size(), 2u) << "cut at " << cut;
    EXPECT_EQ(j->torn_lines, 1u);
  }
  // Only the newline lost: the record is whole and kept.
  spill(file, text.substr(0, text.size() - 1));
  EXPECT_EQ(readJournal(dir.string())->cells.size(), 3u);
  // A byte flipped in a middle line, or in the header: errors naming the line.
  std::string flipped = text;
  flipped[last_start - 5] ^= 0x01;
  spill(file, flipped);
  expectErrorMentions([&] { readJournal(dir.string()); }, {kJournalFile, "line 3", "damaged"});
  flipped = text;
  flipped[text.find("generation") + 2] ^= 0x01;
  spill(file, flipped);
  expectErrorMentions([&] { readJournal(dir.string()); }, {kJournalFile, "line 1", "without --resume"});
  spill(file, "");
  expectErrorMentions([&] { readJournal(dir.string()); }, {kJournalFile, "line 1"});
  // A resumed writer keeps the cells it is given and drops the rest.
  { JournalWriter w(dir.string(), header, {{{"half_edge", 9}}}); }
  j = readJournal(dir.string());
  ASSERT_TRUE(j);
  ASSERT_EQ(j->cells.size(), 1u);
  removeJournal(dir.string());
  EXPECT_FALSE(readJournal(dir.string()));
}

}  // namespace
}  // namespace farfield::store
