// Helpers shared by the test suites.
#pragma once

#include <filesystem>
#include <string>

namespace farfield::test {

// ../shared/data relative to the repository root (real data; read-only).
std::filesystem::path sharedDataDir();
// tests/data (small hand-made files, malformed inputs).
std::filesystem::path testDataDir();
// A fresh, empty directory under the build tree for this test's outputs, unique to this process.
std::filesystem::path scratchDir(const std::string& name);

}  // namespace farfield::test
