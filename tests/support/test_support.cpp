#include "support/test_support.h"

namespace farfield::test {

std::filesystem::path sharedDataDir() { return std::filesystem::path(FF_SOURCE_DIR) / ".." / "shared" / "data"; }

std::filesystem::path testDataDir() { return std::filesystem::path(FF_TEST_DATA_DIR); }

std::filesystem::path scratchDir(const std::string& name) {
  auto dir = std::filesystem::path(FF_BINARY_DIR) / "test_scratch" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace farfield::test
