// Impostor store rewrites: one killed (a child process, _exit) or failing at any file operation leaves the old or
// the new store, readable, and a later bake over the debris leaves the new store alone in the directory.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/store/impostor_store.h"
#include "store/impostor_store_fixture.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

using impostor_store_test::expectedContent;
using impostor_store_test::filesIn;
using impostor_store_test::makeContent;
using impostor_store_test::namedFiles;
using impostor_store_test::StoreContent;
using impostor_store_test::storedContent;
using impostor_store_test::writeStore;

TEST(StoreIntegrityTest, ARewriteKilledAtAnyFileOperationLeavesTheOldOrTheNewStore) {
  const StoreContent old_content = makeContent(1), new_content = makeContent(2);
  const std::string old_expected = expectedContent(old_content), new_expected = expectedContent(new_content);
  ASSERT_NE(old_expected, new_expected);
  const std::string dir = test::scratchDir("store_killed_rewrite").string();
  const std::string old_store = test::scratchDir("store_killed_rewrite_old").string();
  writeStore(old_store, old_content);

  // The file operations of a complete rewrite, in order.
  std::vector<std::pair<std::string, std::string>> operations;
  fs::copy(old_store, dir, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  EXPECT_EQ(storedContent(dir), old_expected);
  setFileOperationHook([&](const char* op, const std::string& path) {
    operations.emplace_back(op, fs::relative(path, dir).generic_string());
  });
  const StoreIndex rewritten = writeStore(dir, new_content);
  setFileOperationHook({});
  EXPECT_EQ(storedContent(dir), new_expected);
  EXPECT_EQ(rewritten.generation, 2u);
  EXPECT_EQ(filesIn(dir), namedFiles(rewritten)) << "files of generation 1 left behind";
  std::set<std::string> kinds;
  for (const auto& [op, path] : operations) kinds.insert(op);
  EXPECT_EQ(kinds, (std::set<std::string>{"create", "write", "fsync", "rename", "sync-dir", "remove"}));
  ASSERT_GT(operations.size(), 50u);

  // Kill a child process doing the same rewrite (_exit: no unwinding, no cleanup) before each operation in turn.
  size_t saw_old = 0, saw_new = 0;
  for (size_t kill_at = 1; kill_at <= operations.size(); ++kill_at) {
    const std::string where = "killed before operation " + std::to_string(kill_at) + " (" +
                              operations[kill_at - 1].first + " " + operations[kill_at - 1].second + ")";
    fs::remove_all(dir);
    fs::copy(old_store, dir, fs::copy_options::recursive);  // the old store, as written (no fsyncs: faster)
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      size_t count = 0;
      setFileOperationHook([&](const char*, const std::string&) {
        if (++count == kill_at) _exit(0);
      });
      try {
        writeStore(dir, new_content);
      } catch (...) {
        _exit(3);
      }
      _exit(1);
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status)) << where;
    ASSERT_EQ(WEXITSTATUS(status), 0) << where << ": the rewrite was not killed there";
    std::string read;
    try {
      read = storedContent(dir);
    } catch (const Error& e) {
      ADD_FAILURE() << where << ": the store is not readable: " << e.what();
      continue;
    }
    const bool is_old = read == old_expected, is_new = read == new_expected;
    EXPECT_TRUE(is_old || is_new) << where << ": the store holds neither the old nor the new content";
    saw_old += is_old;
    saw_new += is_new;
    // The index is replaced by one rename: before it the old store, after it the new one.
    const auto rename_index = std::find(operations.begin(), operations.end(),
                                        std::pair<std::string, std::string>("rename", kIndexFile));
    ASSERT_NE(rename_index, operations.end());
    EXPECT_EQ(is_new, kill_at > size_t(rename_index - operations.begin()) + 1) << where;
    // A later bake over the debris completes and leaves the new store alone in the directory.
    const StoreIndex again = writeStore(dir, new_content);
    EXPECT_EQ(storedContent(dir), new_expected) << where;
    EXPECT_EQ(filesIn(dir), namedFiles(again)) << where;
  }
  EXPECT_GT(saw_old, 0u);
  EXPECT_GT(saw_new, 0u);
  std::printf("killed rewrites: %zu file operations, %zu left the old store, %zu the new one\n", operations.size(),
              saw_old, saw_new);
}

TEST(StoreIntegrityTest, WriterErrorsLeaveTheOldStoreReadable) {
  // The same points as an I/O error (an exception) instead of a kill: the writer unwinds, the old store stays.
  const StoreContent old_content = makeContent(1), new_content = makeContent(2);
  const std::string dir = test::scratchDir("store_failed_rewrite").string();
  writeStore(dir, old_content);
  size_t total = 0;
  setFileOperationHook([&](const char*, const std::string&) { ++total; });
  writeStore(dir, new_content);
  setFileOperationHook({});
  for (size_t fail_at = 1; fail_at <= total; fail_at += 3) {
    fs::remove_all(dir);
    writeStore(dir, old_content);
    size_t count = 0;
    setFileOperationHook([&](const char* op, const std::string& path) {
      if (++count == fail_at) throw Error(path, std::string("injected failure before ") + op);
    });
    EXPECT_THROW(writeStore(dir, new_content), Error) << fail_at;
    setFileOperationHook({});
    const std::string read = storedContent(dir);
    EXPECT_TRUE(read == expectedContent(old_content) || read == expectedContent(new_content)) << fail_at;
  }
}

}  // namespace
}  // namespace farfield::store
