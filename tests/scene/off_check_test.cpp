#include "farfield/scene/off_check.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "farfield/scene/import.h"
#include "support/expect_error.h"
#include "support/test_support.h"

namespace farfield::scene {
namespace {

std::string writeOff(const std::string& name, const std::string& text) {
  const std::string path = (test::scratchDir("off_check") / name).string();
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

const char* kQuad = "OFF\n# a unit quad as two triangles\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3 0.5 0.5 0.5\n";

TEST(OffCheck, AWellFormedFileIsAcceptedAndImported) {
  const std::string path = writeOff("quad.off", kQuad);
  EXPECT_NO_THROW(checkOffFile(path));
  const Scene scene = importScene(path);
  size_t triangles = 0;
  for (const Mesh& m : scene.meshes) triangles += m.triangleCount();
  EXPECT_EQ(triangles, 2u);
  // Counts on the header's line, blank lines and a prefixed header are accepted too.
  EXPECT_NO_THROW(checkOffFile(writeOff("inline.off", "COFF 3 1 0\n\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")));
}

TEST(OffCheck, DamagedFilesAreErrorsNamingTheLine) {
  // The fuzz finding: a face line in another format, which assimp's reader crashed on.
  test::expectErrorMentions(
      [] { checkOffFile(writeOff("slashes.off", "OFF\n4 2 0\n0 0 0\n2 0 0\n1 1 0\n0 1 0\n3/1 4/4/1\no x\n")); },
      {"slashes.off:7", "face 0", "'3/1'"});
  test::expectErrorMentions([] { checkOffFile(writeOff("range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n")); },
                            {"range.off:6", "vertex index '3'"});
  test::expectErrorMentions([] { checkOffFile(writeOff("short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n")); },
                            {"short.off", "2 of 3 vertices"});
  test::expectErrorMentions([] { checkOffFile(writeOff("nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n")); },
                            {"nan.off:4", "vertex 1"});
  test::expectErrorMentions([] { checkOffFile(writeOff("header.off", "PLY\n3 1 0\n")); }, {"header.off:1", "OFF"});
  test::expectErrorMentions([] { checkOffFile(writeOff("counts.off", "OFF\n-3 1 0\n")); }, {"counts.off:2", "counts"});
  test::expectErrorMentions(
      [] { checkOffFile(writeOff("faces.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")); },
      {"faces.off", "1 of 2 faces"});
  test::expectErrorMentions([] { checkOffFile(writeOff("empty.off", "")); }, {"empty.off", "empty"});
  // Through the importer: an error, not a crash.
  test::expectErrorMentions(
      [] { importScene(writeOff("import.off", "OFF\n4 2 0\n0 0 0\n2 0 0\n1 1 0\n0 1 0\n3/1 4/4/1\no x\n")); },
      {"import.off:7"});
}

}  // namespace
}  // namespace farfield::scene
