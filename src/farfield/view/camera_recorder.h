// Recording the cameras the viewer shows into a camera path (gen/camera_path.h) that `farfield bench --path` and
// `farfield walk --path` read, and playing a path back.
#pragma once

#include <cstddef>
#include <string>

#include "farfield/core/camera.h"
#include "farfield/gen/camera_path.h"

namespace farfield::view {

class CameraRecorder {
 public:
  explicit CameraRecorder(float fps = 30.0f);
  void add(const Camera& camera);  // eye, at, up, field of view
  void clear() { path_.frames.clear(); }
  size_t size() const { return path_.frames.size(); }
  const gen::CameraPath& path() const { return path_; }
  // Writes the path (gen::saveCameraPath); throws farfield::Error naming the file when it cannot be written or
  // holds no frames.
  void save(const std::string& file) const;

 private:
  gen::CameraPath path_;
};

// Playback of a path: one path frame per shown frame (replay), or at the path's frame rate in real time (play).
class PathPlayer {
 public:
  PathPlayer() = default;
  PathPlayer(gen::CameraPath path, bool real_time);
  bool active() const { return !path_.frames.empty() && !finished_; }
  bool finished() const { return finished_; }
  bool paused() const { return paused_; }
  bool realTime() const { return real_time_; }
  void setPaused(bool paused) { paused_ = paused; }
  size_t frame() const { return frame_; }
  size_t frameCount() const { return path_.frames.size(); }
  // The camera of the current path frame at the given size (eval::pathCamera's checks).
  Camera camera(int width, int height) const;
  // Moves on after a shown frame (dt seconds): replay one frame; play by the path's fps. Past the last frame: replay
  // finishes, play loops.
  void advance(double dt);

 private:
  gen::CameraPath path_;
  bool real_time_ = false;
  bool paused_ = false;
  bool finished_ = false;
  size_t frame_ = 0;
  double time_ = 0.0;
};

}  // namespace farfield::view
