#include "egl_pbuffer.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <stdexcept>
#include <vector>

namespace osg_peer {
namespace {

bool hasExtension(const char* list, const char* name) {
  if (!list) return false;
  const size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

template <class F>
F proc(const char* name) {
  return reinterpret_cast<F>(eglGetProcAddress(name));
}

}  // namespace

struct EglPbuffer::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLSurface surface = EGL_NO_SURFACE;
  EGLContext context = EGL_NO_CONTEXT;

  // A pbuffer and a compatibility context on `d`, made current; the reason it failed otherwise.
  std::string tryDisplay(EGLDisplay d, int width, int height) {
    EGLint major = 0, minor = 0;
    if (d == EGL_NO_DISPLAY) return "no display";
    if (!eglInitialize(d, &major, &minor)) return "eglInitialize failed";
    const std::string why = onDisplay(d, width, height);
    if (!why.empty()) eglTerminate(d);
    return why;
  }
  std::string onDisplay(EGLDisplay d, int width, int height) {
    if (!eglBindAPI(EGL_OPENGL_API)) return "no desktop OpenGL";
    const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                     EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8,
                                     EGL_DEPTH_SIZE, 24, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!eglChooseConfig(d, config_attribs, &config, 1, &count) || count == 0) return "no pbuffer config";
    const EGLint surface_attribs[] = {EGL_WIDTH, width, EGL_HEIGHT, height, EGL_NONE};
    EGLSurface s = eglCreatePbufferSurface(d, config, surface_attribs);
    if (s == EGL_NO_SURFACE) return "eglCreatePbufferSurface failed";
    const EGLint context_attribs[] = {EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT,
                                      EGL_NONE};
    EGLContext c = eglCreateContext(d, config, EGL_NO_CONTEXT, context_attribs);
    if (c == EGL_NO_CONTEXT) {
      eglDestroySurface(d, s);
      return "no compatibility-profile context";
    }
    if (!eglMakeCurrent(d, s, s, c)) {
      eglDestroyContext(d, c);
      eglDestroySurface(d, s);
      return "eglMakeCurrent failed";
    }
    display = d;
    surface = s;
    context = c;
    return "";
  }
};

EglPbuffer::EglPbuffer(int width, int height) : impl_(std::make_unique<Impl>()) {
  std::string refused;
  auto attempt = [&](EGLDisplay d, const std::string& label) {
    const std::string why = impl_->tryDisplay(d, width, height);
    if (why.empty()) {
      source_ = label;
      return true;
    }
    refused += (refused.empty() ? "" : "; ") + label + ": " + why;
    return false;
  };
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const auto get_display = proc<PFNEGLGETPLATFORMDISPLAYEXTPROC>("eglGetPlatformDisplayEXT");
  const auto query_devices = proc<PFNEGLQUERYDEVICESEXTPROC>("eglQueryDevicesEXT");
  const auto device_string = proc<PFNEGLQUERYDEVICESTRINGEXTPROC>("eglQueryDeviceStringEXT");
  if (get_display && query_devices && device_string && hasExtension(client, "EGL_EXT_platform_device")) {
    EGLint count = 0;
    if (query_devices(0, nullptr, &count) && count > 0) {
      std::vector<EGLDeviceEXT> devices(size_t(count), nullptr);
      query_devices(count, devices.data(), &count);
      // GPUs first, Mesa's software device last.
      for (const bool software : {false, true})
        for (EGLint i = 0; i < count; ++i) {
          const char* extensions = device_string(devices[size_t(i)], EGL_EXTENSIONS);
          if (hasExtension(extensions, "EGL_MESA_device_software") != software) continue;
          std::string label = "egl-device " + std::to_string(i);
          if (hasExtension(extensions, "EGL_EXT_device_drm"))
            if (const char* file = device_string(devices[size_t(i)], EGL_DRM_DEVICE_FILE_EXT))
              label += std::string(" (") + file + ")";
          if (attempt(get_display(EGL_PLATFORM_DEVICE_EXT, devices[size_t(i)], nullptr), label)) return;
        }
    }
  }
  if (get_display && hasExtension(client, "EGL_MESA_platform_surfaceless") &&
      attempt(get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr), "egl-surfaceless"))
    return;
  if (attempt(eglGetDisplay(EGL_DEFAULT_DISPLAY), "egl-default")) return;
  throw std::runtime_error("no EGL pbuffer with a compatibility-profile OpenGL context (" + refused + ")");
}

EglPbuffer::~EglPbuffer() {
  if (impl_->display == EGL_NO_DISPLAY) return;
  eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(impl_->display, impl_->context);
  eglDestroySurface(impl_->display, impl_->surface);
}

}  // namespace osg_peer
