// The bindings a GLSL source declares: what the barrier check (gl_barrier_check.h) reads from each shader it is given,
// to know which buffers, images and textures a dispatch or draw accesses, and which it may write.
#pragma once

#include <set>
#include <string_view>

namespace farfield::gpu {

// The bindings a GLSL source declares with layout(binding = N): storage buffers, images and samplers, and the
// storage buffers and images it may write (not declared readonly). Comments are skipped, and so are the lines its
// preprocessor conditionals leave out (#ifdef, #ifndef, #if and #elif over defined(), !, &&, || and the macros the
// source #defines; a condition it cannot read counts as true).
struct GlslBindings {
  std::set<int> buffers, written_buffers;
  std::set<int> images, written_images;
  std::set<int> samplers;
  GlslBindings& operator|=(const GlslBindings& o);
};
GlslBindings glslBindings(std::string_view source);

}  // namespace farfield::gpu
