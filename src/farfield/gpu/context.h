// OpenGL 4.5 core context: headless through EGL (the NVIDIA EGL device platform when one is present, else Mesa's
// surfaceless platform, llvmpipe on machines without a GPU), or a GLFW window. This module is the only place with
// gl*/egl* calls.
#pragma once

#include <memory>
#include <string>

namespace farfield::gpu {

enum class Platform {
  Auto,         // FF_GL_PLATFORM=device|surfaceless in the environment, else device if an EGL device with a
                // non-software renderer is found, else surfaceless
  Device,       // EGL_EXT_platform_device: the first EGL device giving 4.5 core (software devices included)
  Surfaceless,  // EGL_MESA_platform_surfaceless
  Window,       // GLFW window (needs a display)
};

struct ContextOptions {
  Platform platform = Platform::Auto;
  bool debug = false;     // KHR_debug messages to the log (on by default in debug builds)
  int window_width = 1280;  // Window platform only
  int window_height = 720;
  std::string window_title = "Farfield";
  bool window_visible = true;
  bool vsync = false;
};

struct ContextInfo {
  std::string platform;  // "egl-device", "egl-surfaceless", "glfw-window"
  std::string vendor;    // GL_VENDOR
  std::string renderer;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string version;   // GL_VERSION
  int major = 0;
  int minor = 0;
  bool core_profile = false;
};

class Context {
 public:
  // Throws farfield::Error when no OpenGL 4.5 core context can be made (with what was tried).
  static std::unique_ptr<Context> create(const ContextOptions& options = {});
  virtual ~Context() = default;
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  virtual void makeCurrent() = 0;
  const ContextInfo& info() const { return info_; }
  // "llvmpipe (LLVM 15.0.6, 256 bits) / OpenGL 4.5 (Core Profile) Mesa 22.3.6 via egl-surfaceless"
  std::string description() const;

  // Window platform only (no-ops headless): the GLFWwindow*, buffer swap, close request, framebuffer size.
  virtual void* nativeWindow() { return nullptr; }
  virtual void swapBuffers() {}
  virtual bool shouldClose() const { return false; }
  virtual void framebufferSize(int& width, int& height) const { width = height = 0; }

 protected:
  Context() = default;
  ContextInfo info_;
};

// One process-wide headless context, created on first use (tests and tools that render a few frames). Every call
// makes it current on the calling thread (a GL context is current on one thread at a time), so calling it again
// after using another context (a window) switches back. Throws farfield::Error when no context can be made.
Context& sharedHeadlessContext();

}  // namespace farfield::gpu
