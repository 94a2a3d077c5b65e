#include "support/test_support.h"

#include <unistd.h>

#include <cstdlib>

namespace farfield::test {

std::filesystem::path sharedDataDir() {
  const char* dir = std::getenv("FF_SHARED_DATA");
  if (dir && *dir) return std::filesystem::path(dir);
  return std::filesystem::path(FF_SOURCE_DIR) / ".." / "shared" / "data";
}

std::string missingSharedFile(const std::string& relative) {
  return "needs ../shared/data/" + relative + " (real data beside the repository; absent in this checkout: no " +
         (sharedDataDir() / relative).string() + ")";
}

std::filesystem::path testDataDir() { return std::filesystem::path(FF_TEST_DATA_DIR); }

std::filesystem::path scratchDir(const std::string& name) {
  // ctest runs every test in its own process, several at once: a directory per process keeps tests that share a
  // name (or a fixture that writes once per process) from deleting each other's files.
  auto dir = std::filesystem::path(FF_BINARY_DIR) / "test_scratch" / (name + "." + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace farfield::test
