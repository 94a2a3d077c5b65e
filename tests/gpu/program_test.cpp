#include "farfield/gpu/program.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "farfield/core/error.h"
#include "farfield/gpu/shader_dump.h"
#include "farfield/gpu/shader_source.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

const char* kVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
out vec3 v_color;
void main() {
  v_color = a_position;
  gl_Position = vec4(a_position, 1.0);
}
)";

TEST_F(GpuTest, ValidProgramLinksAndFindsUniforms) {
  const char* fragment = R"(#version 450 core
in vec3 v_color;
uniform vec4 u_tint;
out vec4 o_color;
void main() { o_color = vec4(v_color, 1.0) * u_tint; }
)";
  Program program = Program::fromSources({"ok.vert.glsl", kVertex}, {"ok.frag.glsl", fragment});
  EXPECT_NE(program.handle(), 0u);
  EXPECT_GE(program.uniformLocation("u_tint"), 0);
  EXPECT_EQ(program.uniformLocation("u_missing"), -1);
  EXPECT_EQ(program.uniformLocation("u_tint"), program.uniformLocation("u_tint"));  // cached, same answer
  Program moved = std::move(program);
  EXPECT_EQ(program.handle(), 0u);
  EXPECT_NE(moved.handle(), 0u);
}

TEST_F(GpuTest, SyntaxErrorNamesShaderAndLine) {
  // Line 5 uses an undeclared identifier.
  const char* fragment = R"(#version 450 core
in vec3 v_color;
out vec4 o_color;
void main() {
  o_color = vec4(foo, 1.0);
}
)";
  try {
    Program::fromSources({"ok.vert.glsl", kVertex}, {"broken.frag.glsl", fragment});
    FAIL() << "expected farfield::Error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("broken.frag.glsl:5:", 0), 0u) << message;
    EXPECT_NE(message.find("foo"), std::string::npos) << message;
  }
}

TEST_F(GpuTest, VertexErrorNamesTheVertexShader) {
  const char* vertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
void main() {
  gl_Position = vec4(a_position, 1.0)
}
)";
  const char* fragment = R"(#version 450 core
out vec4 o_color;
void main() { o_color = vec4(1.0); }
)";
  try {
    Program::fromSources({"broken.vert.glsl", vertex}, {"ok.frag.glsl", fragment});
    FAIL() << "expected farfield::Error";
  } catch (const Error& e) {
    const std::string message = e.what();
    // The missing ';' is reported on line 4 or, by some drivers, where the next token appears (line 5).
    EXPECT_TRUE(message.rfind("broken.vert.glsl:4:", 0) == 0 || message.rfind("broken.vert.glsl:5:", 0) == 0)
        << message;
  }
}

TEST_F(GpuTest, LinkErrorNamesBothShaders) {
  const char* fragment = R"(#version 450 core
in vec3 v_not_written;
out vec4 o_color;
void main() { o_color = vec4(v_not_written, 1.0); }
)";
  try {
    Program::fromSources({"a.vert.glsl", kVertex}, {"b.frag.glsl", fragment});
    FAIL() << "expected farfield::Error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("a.vert.glsl"), std::string::npos) << message;
    EXPECT_NE(message.find("b.frag.glsl"), std::string::npos) << message;
    EXPECT_NE(message.find("link"), std::string::npos) << message;
  }
}

TEST_F(GpuTest, EmbeddedMeshShadersCompileInEveryVariant) {
  const auto names = shaderNames();
  EXPECT_NE(std::find(names.begin(), names.end(), "mesh.vert.glsl"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "mesh.frag.glsl"), names.end());
  for (const char* defines : {"", "#define FF_TEXTURED 1", "#define FF_ITEM_BUFFER 1"}) {
    Program program = Program::fromEmbedded("mesh.vert.glsl", "mesh.frag.glsl", defines);
    EXPECT_GE(program.uniformLocation("u_object_id"), 0) << defines;
    EXPECT_GE(program.uniformLocation("u_model"), 0) << defines;
  }
}

// Programs that draw the same things and are compared pixel for pixel (the GPU-culled and frustum-culled frames'
// ids; the crowd's CPU and GPU paths and its reference) must declare their position invariant: GLSL promises equal
// positions across programs only then, and Mesa's equal frames without it prove nothing for another driver.
TEST(ShaderSources, ProgramsComparedPixelForPixelDeclareTheirPositionInvariant) {
  const std::regex invariant(R"((^|\n)\s*invariant\s+gl_Position\s*;)");
  for (const char* name : {"arena.vert.glsl", "mesh.vert.glsl", "skin.vert.glsl", "multiview.vert.glsl"})
    EXPECT_TRUE(std::regex_search(std::string(shaderSource(name)), invariant)) << name;
}

TEST(ShaderDump, AStageIsNamedAfterItsSourceAndStage) {
  EXPECT_EQ(dumpedStageName("mesh.frag.glsl", GL_FRAGMENT_SHADER), "mesh.frag");
  EXPECT_EQ(dumpedStageName("gpu_cull.comp.glsl", GL_COMPUTE_SHADER), "gpu_cull.comp");
  EXPECT_EQ(dumpedStageName("a b/c.glsl", GL_VERTEX_SHADER), "a_b_c.vert");
  EXPECT_EQ(dumpedStageName("viewer", GL_FRAGMENT_SHADER), "viewer.frag");
}

std::string fileText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Under ctest every test runs with FF_SHADER_DUMP set (tests/CMakeLists.txt), so this checks the copy the second
// compiler's check reads: a program of this run's own, written once, its stages under their names, byte for byte.
TEST_F(GpuTest, ALinkedProgramIsCopiedOnceForTheSecondCompiler) {
  const char* dir = std::getenv("FF_SHADER_DUMP");
  if (!dir || !*dir) GTEST_SKIP() << "FF_SHADER_DUMP is not set (ctest sets it)";
  const std::string marker = "// dump test " + std::to_string(::getpid()) + " " +
                             std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + "\n";
  const std::string vertex = std::string(kVertex) + marker;
  const std::string fragment = std::string(R"(#version 450 core
in vec3 v_color;
out vec4 o_color;
void main() { o_color = vec4(v_color, 1.0); }
)") + marker;
  for (int i = 0; i < 2; ++i) Program::fromSources({"dump.vert.glsl", vertex}, {"dump.frag.glsl", fragment});
  int copies = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const auto vert = entry.path() / "dump.vert";
    if (!std::filesystem::exists(vert) || fileText(vert) != vertex) continue;
    ++copies;
    EXPECT_EQ(fileText(entry.path() / "dump.frag"), fragment);
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(entry.path()), {}), 2);
  }
  EXPECT_EQ(copies, 1);
}

}  // namespace
}  // namespace farfield::gpu
