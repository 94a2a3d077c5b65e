// A headless OpenGL context for the OpenSceneGraph peer where there is no X server (a GPU machine): an EGL pbuffer
// surface of the frame's size, current on the calling thread, with a compatibility-profile context (OpenSceneGraph
// 3.6 as Debian builds it uses the fixed-function matrices and vertex attributes). The peer's viewer renders into it
// as into an embedded window (osgViewer::Viewer::setUpViewerAsEmbeddedInWindow): the pbuffer is its framebuffer 0.
#pragma once

#include <memory>
#include <string>

namespace osg_peer {

class EglPbuffer {
 public:
  // The first that works of: each EGL device (EGL_EXT_platform_device; a GPU before Mesa's software device), Mesa's
  // surfaceless platform, the default display. Throws std::runtime_error listing what each refused.
  EglPbuffer(int width, int height);
  ~EglPbuffer();
  EglPbuffer(const EglPbuffer&) = delete;
  EglPbuffer& operator=(const EglPbuffer&) = delete;

  // Which display it took, e.g. "egl-device 0 (/dev/dri/card0)".
  const std::string& source() const { return source_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string source_;
};

}  // namespace osg_peer
