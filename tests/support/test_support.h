// Helpers shared by the test suites.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace farfield::test {

// ../shared/data relative to the repository root (real data; read-only), or the directory FF_SHARED_DATA names when
// that variable is set (FF_SHARED_DATA=/nonexistent runs the tests as a clone without ../shared would).
std::filesystem::path sharedDataDir();
// Why a test that needs sharedDataDir() / relative is skipped: the file named, as ../shared/data/<relative>.
std::string missingSharedFile(const std::string& relative);
// tests/data (small hand-made files, malformed inputs).
std::filesystem::path testDataDir();
// A fresh, empty directory under the build tree for this test's outputs, unique to this process.
std::filesystem::path scratchDir(const std::string& name);

}  // namespace farfield::test

// FF_SHARED_FILE_OR_SKIP(var, "models/CesiumMan.glb"): declares `const std::filesystem::path var`, the file under
// sharedDataDir(), and skips the test (GTEST_SKIP, naming the file) when it is missing. GTEST_SKIP returns from the
// enclosing function: use it in a test's body or in a fixture's SetUp, before anything built from the file.
#define FF_SHARED_FILE_OR_SKIP(var, relative)                                      \
  const std::filesystem::path var = ::farfield::test::sharedDataDir() / (relative); \
  if (!std::filesystem::exists(var)) GTEST_SKIP() << ::farfield::test::missingSharedFile(relative)
