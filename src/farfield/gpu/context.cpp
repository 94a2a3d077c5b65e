#include "farfield/gpu/context.h"
#include "farfield/gpu/egl_device_choice.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#endif

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/gpu/gl_barrier_check.h"

namespace farfield::gpu {

namespace {
// The X11/GLX driver stack behind a GLFW window keeps a few hundred bytes it never frees, reported by LeakSanitizer
// from a library already unloaded at exit ("unknown module"), where no suppression can name it. Sanitizer builds
// ignore the allocations made on the window's thread from its creation to its destruction (windows are short-lived
// in tests and made and destroyed on one thread); everything else stays checked.
struct IgnoreDriverLeaks {
#if defined(__SANITIZE_ADDRESS__)
  IgnoreDriverLeaks() { __lsan_disable(); }
  ~IgnoreDriverLeaks() { __lsan_enable(); }
  IgnoreDriverLeaks(const IgnoreDriverLeaks&) = delete;
  IgnoreDriverLeaks& operator=(const IgnoreDriverLeaks&) = delete;
#endif
};
}  // namespace
namespace {

std::mutex& glfwMutex() {
  static std::mutex mutex;
  return mutex;
}
int glfw_windows = 0;               // guarded by glfwMutex(); glfwTerminate when the last window goes
thread_local std::string glfw_error;  // last GLFW error on this thread, for messages

// A GLFW (GLX) context current on this thread blocks making an EGL context current through libglvnd; release it.
void releaseGlfwContext() {
  std::lock_guard<std::mutex> lock(glfwMutex());
  if (glfw_windows > 0 && glfwGetCurrentContext()) glfwMakeContextCurrent(nullptr);
}

// Whole-word search in a space-separated extension string.
bool hasExtension(const char* list, const char* name) {
  if (!list) return false;
  const size_t len = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += len) {
    const bool starts = p == list || p[-1] == ' ';
    const bool ends = p[len] == '\0' || p[len] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

std::string eglErrorName(EGLint error) {
  switch (error) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    default: {
      std::ostringstream s;
      s << "EGL error 0x" << std::hex << error;
      return s.str();
    }
  }
}

bool wantDebug(const ContextOptions& options) {
#ifndef NDEBUG
  (void)options;
  return true;
#else
  return options.debug;
#endif
}

void GLAPIENTRY debugCallback(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                              const GLchar* message, const void* user) {
  (void)user;
  std::string text(message, length >= 0 ? size_t(length) : std::strlen(message));
  while (!text.empty() && (text.back() == '\n' || text.back() == '\0')) text.pop_back();
  // Errors and high/medium severity reports point at bugs; the rest (performance hints, notifications) is noise
  // unless one asks for debug output. Shader compiler messages become farfield::Error (program.cpp) already.
  const bool serious =
      type == GL_DEBUG_TYPE_ERROR || severity == GL_DEBUG_SEVERITY_HIGH || severity == GL_DEBUG_SEVERITY_MEDIUM;
  if (serious && source != GL_DEBUG_SOURCE_SHADER_COMPILER)
    FF_WARN("GL debug [" << id << "]: " << text);
  else
    FF_DEBUG("GL debug [" << id << "]: " << text);
}

// State every Farfield context starts with: reversed Z with a [0,1] depth range (core/camera.h), the debug
// callback when asked for, and queries filling ContextInfo. Returns an empty string when the context is usable,
// else why not.
std::string initializeCurrentContext(ContextInfo& info, bool debug) {
  auto str = [](GLenum name) {
    const GLubyte* s = glGetString(name);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
  };
  info.vendor = str(GL_VENDOR);
  info.renderer = str(GL_RENDERER);
  info.version = str(GL_VERSION);
  info.major = epoxy_gl_version() / 10;
  info.minor = epoxy_gl_version() % 10;
  GLint mask = 0;
  if (info.major >= 3) glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
  info.core_profile = (mask & GL_CONTEXT_CORE_PROFILE_BIT) != 0;
  if (info.major * 10 + info.minor < 45 || !info.core_profile)
    return "got OpenGL " + std::to_string(info.major) + "." + std::to_string(info.minor) +
           (info.core_profile ? " core" : " (not core)") + " from '" + info.renderer + "', need 4.5 core";
  if (debug) {
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(debugCallback, nullptr);
  }
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glClearDepth(0.0);
  glDepthFunc(GL_GREATER);
  return {};
}

bool isSoftwareRenderer(const std::string& renderer) {
  return renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos ||
         renderer.find("swrast") != std::string::npos;
}

// ---------------------------------------------------------------------------------------------------------------
// Headless EGL.

class EglContext final : public Context {
 public:
  EglContext(EGLDisplay display, EGLContext context, std::string platform, const ContextInfo& info)
      : display_(display), context_(context) {
    info_ = info;
    info_.platform = std::move(platform);
  }
  ~EglContext() override {
    if (eglGetCurrentContext() == context_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    // The display is left initialised: EGL displays are shared per platform and device, and terminating one
    // would destroy other contexts made on it.
  }
  void makeCurrent() override {
    if (eglGetCurrentContext() == context_) return;
    releaseGlfwContext();
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      throw Error("OpenGL context", "eglMakeCurrent failed: " + eglErrorName(eglGetError()));
  }

 private:
  EGLDisplay display_;
  EGLContext context_;
};

// Tries to make a current 4.5 core context on an initialised display. On failure returns null and appends why to
// `why`; the display stays initialised (see ~EglContext).
std::unique_ptr<Context> tryEglDisplay(EGLDisplay display, const std::string& platform, const ContextOptions& options,
                                       bool reject_software, std::string& why) {
  EGLint egl_major = 0, egl_minor = 0;
  if (!eglInitialize(display, &egl_major, &egl_minor)) {
    why = "eglInitialize failed (" + eglErrorName(eglGetError()) + ")";
    return nullptr;
  }
  const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
  if (!hasExtension(extensions, "EGL_KHR_surfaceless_context")) {
    why = "no EGL_KHR_surfaceless_context";
    return nullptr;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    why = "eglBindAPI(EGL_OPENGL_API) failed (" + eglErrorName(eglGetError()) + ")";
    return nullptr;
  }
  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!hasExtension(extensions, "EGL_KHR_no_config_context")) {
    // Any config that can render with desktop OpenGL; surface type 0 matches every config (surfaceless
    // platforms have no window configs).
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display, config_attribs, &config, 1, &count) || count == 0) {
      why = "no EGL config with EGL_OPENGL_BIT";
      return nullptr;
    }
  }
  const bool debug = wantDebug(options);
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION_KHR,
                                    4,
                                    EGL_CONTEXT_MINOR_VERSION_KHR,
                                    5,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK_KHR,
                                    EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT_KHR,
                                    EGL_CONTEXT_FLAGS_KHR,
                                    debug ? EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR : 0,
                                    EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
  if (context == EGL_NO_CONTEXT) {
    why = "eglCreateContext(4.5 core) failed (" + eglErrorName(eglGetError()) + ")";
    return nullptr;
  }
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    why = "eglMakeCurrent(EGL_NO_SURFACE) failed (" + eglErrorName(eglGetError()) + ")";
    eglDestroyContext(display, context);
    return nullptr;
  }
  ContextInfo info;
  std::string problem = initializeCurrentContext(info, debug);
  if (problem.empty() && reject_software && isSoftwareRenderer(info.renderer))
    problem = "software renderer '" + info.renderer + "'";
  if (!problem.empty()) {
    why = problem;
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display, context);
    return nullptr;
  }
  enableGlBarrierCheckFromEnvironment();  // FF_GL_BARRIER_CHECK (gl_barrier_check.h)
  return std::make_unique<EglContext>(display, context, platform, info);
}

const char* clientExtensions() {
  // With EGL_EXT_client_extensions, EGL_NO_DISPLAY gives the client (display-independent) extensions.
  const char* s = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  return s ? s : "";
}

// EGL devices (EGL_EXT_platform_device): the NVIDIA driver exposes its GPUs here; Mesa adds a software device.
// With skip_software, devices advertising EGL_MESA_device_software and contexts reporting a software renderer are
// passed over (Auto prefers the surfaceless platform then, which also finds Mesa hardware drivers).
std::unique_ptr<Context> tryDevicePlatform(const ContextOptions& options, bool skip_software,
                                           std::vector<std::string>& tried) {
  const char* client = clientExtensions();
  if (!hasExtension(client, "EGL_EXT_device_enumeration") && !hasExtension(client, "EGL_EXT_device_base")) {
    tried.push_back("egl-device: no EGL_EXT_device_enumeration");
    return nullptr;
  }
  if (!hasExtension(client, "EGL_EXT_device_query") && !hasExtension(client, "EGL_EXT_device_base")) {
    tried.push_back("egl-device: no EGL_EXT_device_query");
    return nullptr;
  }
  if (!hasExtension(client, "EGL_EXT_platform_device")) {
    tried.push_back("egl-device: no EGL_EXT_platform_device");
    return nullptr;
  }
  EGLint count = 0;
  if (!eglQueryDevicesEXT(0, nullptr, &count) || count <= 0) {
    tried.push_back("egl-device: no EGL devices");
    return nullptr;
  }
  std::vector<EGLDeviceEXT> devices(static_cast<size_t>(count));
  eglQueryDevicesEXT(count, devices.data(), &count);
  devices.resize(size_t(count));
  {  // The GPU a scheduler assigned first (gpu/egl_device_choice.h).
    std::vector<int> cuda_ids;
    for (EGLDeviceEXT d : devices) {
      EGLAttrib id = -1;
      const bool cuda = hasExtension(eglQueryDeviceStringEXT(d, EGL_EXTENSIONS), "EGL_NV_device_cuda") &&
                        eglQueryDeviceAttribEXT(d, EGL_CUDA_DEVICE_NV, &id);
      cuda_ids.push_back(cuda ? int(id) : -1);
    }
    std::vector<EGLDeviceEXT> ordered;
    for (size_t i : eglDeviceOrder(cuda_ids, assignedGpu(std::getenv("SLURM_STEP_GPUS"), std::getenv("SLURM_JOB_GPUS"),
                                                         std::getenv("CUDA_VISIBLE_DEVICES"))))
      ordered.push_back(devices[i]);
    devices = std::move(ordered);
  }
  for (size_t i = 0; i < devices.size(); ++i) {
    const char* device_extensions = eglQueryDeviceStringEXT(devices[i], EGL_EXTENSIONS);
    std::string label = "egl-device " + std::to_string(i);
    if (hasExtension(device_extensions, "EGL_EXT_device_drm")) {
      const char* file = eglQueryDeviceStringEXT(devices[i], EGL_DRM_DEVICE_FILE_EXT);
      if (file) label += std::string(" (") + file + ")";
    }
    if (skip_software && hasExtension(device_extensions, "EGL_MESA_device_software")) {
      tried.push_back(label + ": software device, skipped");
      continue;
    }
    EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    if (display == EGL_NO_DISPLAY) {
      tried.push_back(label + ": eglGetPlatformDisplayEXT failed (" + eglErrorName(eglGetError()) + ")");
      continue;
    }
    std::string why;
    if (auto context = tryEglDisplay(display, "egl-device", options, skip_software, why)) return context;
    tried.push_back(label + ": " + why);
  }
  return nullptr;
}

std::unique_ptr<Context> trySurfacelessPlatform(const ContextOptions& options, std::vector<std::string>& tried) {
  const char* client = clientExtensions();
  if (!hasExtension(client, "EGL_MESA_platform_surfaceless")) {
    tried.push_back("egl-surfaceless: no EGL_MESA_platform_surfaceless");
    return nullptr;
  }
  EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) {
    tried.push_back("egl-surfaceless: eglGetPlatformDisplayEXT failed (" + eglErrorName(eglGetError()) + ")");
    return nullptr;
  }
  std::string why;
  if (auto context = tryEglDisplay(display, "egl-surfaceless", options, false, why)) return context;
  tried.push_back("egl-surfaceless: " + why);
  return nullptr;
}

// ---------------------------------------------------------------------------------------------------------------
// GLFW window.


void glfwErrorCallback(int code, const char* description) {
  glfw_error = std::string(description ? description : "unknown") + " (GLFW error " + std::to_string(code) + ")";
}

class GlfwContext final : public Context {
 public:
  explicit GlfwContext(GLFWwindow* window) : window_(window) {}
  void setInfo(const ContextInfo& info) { info_ = info; }
  ~GlfwContext() override {
    std::lock_guard<std::mutex> lock(glfwMutex());
    if (glfwGetCurrentContext() == window_) glfwMakeContextCurrent(nullptr);
    glfwDestroyWindow(window_);
    if (--glfw_windows == 0) glfwTerminate();
  }
  void makeCurrent() override {
    if (glfwGetCurrentContext() != window_ || eglGetCurrentContext() != EGL_NO_CONTEXT) {
      // A current headless EGL context must be released first, or GL calls would keep going to it.
      if (eglGetCurrentContext() != EGL_NO_CONTEXT)
        eglMakeCurrent(eglGetCurrentDisplay(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      glfwMakeContextCurrent(window_);
    }
  }
  void* nativeWindow() override { return window_; }
  void swapBuffers() override { glfwSwapBuffers(window_); }
  bool shouldClose() const override {
    glfwPollEvents();
    return glfwWindowShouldClose(window_) != 0;
  }
  void framebufferSize(int& width, int& height) const override { glfwGetFramebufferSize(window_, &width, &height); }

 private:
  [[maybe_unused]] IgnoreDriverLeaks ignore_driver_leaks_;  // first member: constructed first, destroyed after the window
  GLFWwindow* window_;
};

GLFWwindow* openGlfwWindow(const ContextOptions& options, bool debug) {
  std::lock_guard<std::mutex> lock(glfwMutex());
  [[maybe_unused]] IgnoreDriverLeaks ignore_driver_leaks;
  glfwSetErrorCallback(glfwErrorCallback);
  glfw_error.clear();
  if (glfw_windows == 0 && !glfwInit())
    throw Error("OpenGL context", "glfw-window: glfwInit failed: " + glfw_error + " (is DISPLAY set?)");
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, debug ? GLFW_TRUE : GLFW_FALSE);
  glfwWindowHint(GLFW_VISIBLE, options.window_visible ? GLFW_TRUE : GLFW_FALSE);
  glfwWindowHint(GLFW_DEPTH_BITS, 24);
  // glfwCreateWindow makes the new context current for a moment; libglvnd refuses that (an X BadAccess error that
  // ends the process) while an EGL context is current on this thread, so release it first.
  if (eglGetCurrentContext() != EGL_NO_CONTEXT)
    eglMakeCurrent(eglGetCurrentDisplay(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  GLFWwindow* window =
      glfwCreateWindow(options.window_width, options.window_height, options.window_title.c_str(), nullptr, nullptr);
  if (!window) {
    if (glfw_windows == 0) glfwTerminate();
    throw Error("OpenGL context", "glfw-window: glfwCreateWindow(4.5 core) failed: " + glfw_error);
  }
  ++glfw_windows;
  return window;
}

std::unique_ptr<Context> createWindow(const ContextOptions& options) {
  if (options.window_width <= 0 || options.window_height <= 0)
    throw Error("OpenGL context", "glfw-window: window size must be positive, got " +
                                      std::to_string(options.window_width) + "x" +
                                      std::to_string(options.window_height));
  const bool debug = wantDebug(options);
  auto context = std::make_unique<GlfwContext>(openGlfwWindow(options, debug));  // owns the window from here on
  context->makeCurrent();
  glfwSwapInterval(options.vsync ? 1 : 0);
  ContextInfo info;
  const std::string problem = initializeCurrentContext(info, debug);
  if (!problem.empty()) throw Error("OpenGL context", "glfw-window: " + problem);
  info.platform = "glfw-window";
  context->setInfo(info);
  enableGlBarrierCheckFromEnvironment(true);  // FF_GL_BARRIER_CHECK, in a viewer's window too (gl_barrier_check.h)
  return context;
}

}  // namespace

std::string Context::description() const {
  return info_.renderer + " / OpenGL " + info_.version + " via " + info_.platform;
}

std::unique_ptr<Context> Context::create(const ContextOptions& options) {
  Platform platform = options.platform;
  std::string forced;
  if (platform == Platform::Auto) {
    if (const char* env = std::getenv("FF_GL_PLATFORM"); env && *env) {
      forced = env;
      if (forced == "device")
        platform = Platform::Device;
      else if (forced == "surfaceless")
        platform = Platform::Surfaceless;
      else
        throw Error("FF_GL_PLATFORM", "unknown platform '" + forced + "', expected 'device' or 'surfaceless'");
    }
  }
  if (platform == Platform::Window) return createWindow(options);

  std::vector<std::string> tried;
  std::unique_ptr<Context> context;
  switch (platform) {
    case Platform::Device: context = tryDevicePlatform(options, false, tried); break;
    case Platform::Surfaceless: context = trySurfacelessPlatform(options, tried); break;
    default:
      context = tryDevicePlatform(options, true, tried);
      if (!context) context = trySurfacelessPlatform(options, tried);
      break;
  }
  if (!context) {
    std::string message = "no OpenGL 4.5 core context could be created";
    if (!forced.empty()) message += " (FF_GL_PLATFORM=" + forced + ")";
    message += "; tried:";
    for (const auto& t : tried) message += "\n  " + t;
    throw Error("OpenGL context", message);
  }
  FF_DEBUG("OpenGL context: " << context->description());
  return context;
}

Context& sharedHeadlessContext() {
  // Created on first use and deliberately never destroyed: GL objects held by other static objects may outlive
  // any destruction order we could pick, and the driver releases everything at process exit.
  static Context* context = Context::create().release();
  context->makeCurrent();
  return *context;
}

}  // namespace farfield::gpu
