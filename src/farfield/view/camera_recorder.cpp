#include "farfield/view/camera_recorder.h"

#include <cmath>

#include "farfield/core/error.h"
#include "farfield/eval/frame_runner.h"

namespace farfield::view {

CameraRecorder::CameraRecorder(float fps) {
  path_.kind = "view";
  path_.fps = fps;
}

void CameraRecorder::add(const Camera& camera) {
  gen::PathFrame frame;
  frame.eye = camera.eye;
  frame.at = camera.at;
  frame.up = camera.up;
  frame.fov_y = camera.fov_y;
  path_.frames.push_back(frame);
}

void CameraRecorder::save(const std::string& file) const {
  if (path_.frames.empty()) throw Error(file, "no cameras recorded");
  gen::saveCameraPath(path_, file);
}

PathPlayer::PathPlayer(gen::CameraPath path, bool real_time) : path_(std::move(path)), real_time_(real_time) {}

Camera PathPlayer::camera(int width, int height) const { return eval::pathCamera(path_, frame_, width, height); }

void PathPlayer::advance(double dt) {
  if (!active() || paused_) return;
  if (!real_time_) {
    if (++frame_ >= path_.frames.size()) {
      frame_ = path_.frames.size() - 1;
      finished_ = true;
    }
    return;
  }
  time_ += dt;
  const double fps = path_.fps > 0.0f ? double(path_.fps) : 30.0;
  frame_ = size_t(std::floor(time_ * fps)) % path_.frames.size();
}

}  // namespace farfield::view
