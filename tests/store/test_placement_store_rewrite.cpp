// Placement database rewrites: a write failing at any file operation leaves the previous database (and a later
// write over the debris completes), and new generations skip those of files left by a killed write.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/store/placement_store.h"
#include "store/placement_store_fixture.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

using placement_test::Content;
using placement_test::filesIn;
using placement_test::makeContent;
using placement_test::namedFiles;
using placement_test::storedContent;
using placement_test::writeBytes;
using placement_test::writeDatabase;

TEST(PlacementStoreIntegrityTest, AWriteFailingAtAnyFileOperationLeavesThePreviousDatabase) {
  const Content old_content = makeContent(31), new_content = makeContent(32, {1, 2, 3, 8});
  const std::string dir = test::scratchDir("placement_failed_rewrite").string();
  const std::string old_db = test::scratchDir("placement_failed_rewrite_old").string();
  writeDatabase(old_db, old_content);
  const std::string old_expected = storedContent(old_db);
  const std::string new_expected = [&] {
    const std::string fresh = test::scratchDir("placement_failed_rewrite_new").string();
    writeDatabase(fresh, new_content);
    return storedContent(fresh);
  }();
  ASSERT_NE(old_expected, new_expected);

  // The file operations of a complete rewrite, in order.
  std::vector<std::pair<std::string, std::string>> operations;
  fs::copy(old_db, dir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  setFileOperationHook([&](const char* op, const std::string& path) {
    operations.emplace_back(op, fs::relative(path, dir).generic_string());
  });
  const PlacementIndex rewritten = writeDatabase(dir, new_content);
  setFileOperationHook({});
  EXPECT_EQ(rewritten.generation, 2u);
  EXPECT_EQ(storedContent(dir), new_expected);
  EXPECT_EQ(filesIn(dir), namedFiles(rewritten)) << "files of generation 1 left behind";
  std::set<std::string> kinds;
  for (const auto& [op, path] : operations) kinds.insert(op);
  EXPECT_EQ(kinds, (std::set<std::string>{"create", "write", "fsync", "rename", "sync-dir"}));
  const auto rename_index = std::find(operations.begin(), operations.end(),
                                      std::pair<std::string, std::string>("rename", kPlacementIndexFile));
  ASSERT_NE(rename_index, operations.end());
  const size_t rename_at = size_t(rename_index - operations.begin()) + 1;  // 1-based
  ASSERT_GT(operations.size(), 40u);

  size_t saw_old = 0, saw_new = 0;
  for (size_t fail_at = 1; fail_at <= operations.size(); ++fail_at) {
    const std::string where = "failed before operation " + std::to_string(fail_at) + " (" +
                              operations[fail_at - 1].first + " " + operations[fail_at - 1].second + ")";
    fs::remove_all(dir);
    fs::copy(old_db, dir, fs::copy_options::recursive);
    size_t count = 0;
    setFileOperationHook([&](const char* op, const std::string& path) {
      if (++count == fail_at) throw Error(path, std::string("injected failure before ") + op);
    });
    EXPECT_THROW(writeDatabase(dir, new_content), Error) << where;
    setFileOperationHook({});
    std::string read;
    try {
      read = storedContent(dir);
    } catch (const Error& e) {
      ADD_FAILURE() << where << ": the database is not readable: " << e.what();
      continue;
    }
    // Before the index's rename the old database, after it the new one (only the index's directory sync is left).
    const bool expect_new = fail_at > rename_at;
    EXPECT_EQ(read, expect_new ? new_expected : old_expected) << where;
    (expect_new ? saw_new : saw_old) += 1;
    if (!expect_new) {
      EXPECT_EQ(readPlacementIndex(dir).generation, 1u) << where;
    }
    // A later write over the debris completes and leaves the new database alone in the directory.
    const PlacementIndex again = writeDatabase(dir, new_content);
    EXPECT_EQ(storedContent(dir), new_expected) << where;
    EXPECT_EQ(filesIn(dir), namedFiles(again)) << where;
  }
  EXPECT_GT(saw_old, 40u);
  EXPECT_GT(saw_new, 0u);
}

TEST(PlacementStoreIntegrityTest, GenerationsSkipThoseOfFilesLeftByAKilledWrite) {
  const std::string dir = test::scratchDir("placement_generations").string();
  EXPECT_EQ(nextPlacementGeneration(dir), 1u);
  const Content c = makeContent(41);
  EXPECT_EQ(writeDatabase(dir, c).generation, 1u);
  EXPECT_EQ(nextPlacementGeneration(dir), 2u);
  // A killed write of generation 7 left a layer file (and a temporary) behind.
  writeBytes((fs::path(dir) / placedLayerFileName(7, 1, 0, false)).string(), "debris");
  writeBytes((fs::path(dir) / placedLayerFileName(7, 1, 1, false)).string() + ".tmp", "debris");
  EXPECT_EQ(nextPlacementGeneration(dir), 8u);
  const PlacementIndex index = writeDatabase(dir, c);
  EXPECT_EQ(index.generation, 8u);
  EXPECT_EQ(filesIn(dir), namedFiles(index));
  EXPECT_EQ(placedLayerFileName(8, 12, 3, true), "impostors/g000008.i000012.03.ids.png");
}

}  // namespace
}  // namespace farfield::store
