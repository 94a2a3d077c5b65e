#include "farfield/view/camera_controller.h"

#include <algorithm>
#include <cmath>

namespace farfield::view {
namespace {
// Short of straight up or down, so that +z stays a valid up vector.
constexpr float kMaxPitch = float(degToRad(89.0));
}  // namespace

const char* navigationName(Navigation navigation) { return navigation == Navigation::Walk ? "walk" : "fly"; }

void CameraController::setPose(const Camera& camera) {
  setPose(camera.eye, camera.at);
  settings_.fov_deg = float(radToDeg(camera.fov_y));
}

void CameraController::setPose(const Vec3& eye, const Vec3& at) {
  eye_ = eye;
  const Vec3 d = at - eye;
  const float len = glm::length(d);
  if (!(len > 0.0f)) return;
  yaw_ = std::atan2(d.y, d.x);
  pitch_ = std::clamp(std::asin(std::clamp(d.z / len, -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
}

Vec3 CameraController::forward() const {
  return Vec3(std::cos(pitch_) * std::cos(yaw_), std::cos(pitch_) * std::sin(yaw_), std::sin(pitch_));
}

void CameraController::update(const ControlInput& input, Navigation navigation, const GroundFunction& ground) {
  yaw_ -= input.look_x * settings_.radians_per_pixel;
  yaw_ = std::remainder(yaw_, float(2.0 * kPi));
  pitch_ = std::clamp(pitch_ - input.look_y * settings_.radians_per_pixel, -kMaxPitch, kMaxPitch);

  const float step = float(input.dt) * settings_.speed * (input.fast ? settings_.fast_factor : 1.0f);
  const Vec3 flat_forward(std::cos(yaw_), std::sin(yaw_), 0.0f);
  const Vec3 right(std::sin(yaw_), -std::cos(yaw_), 0.0f);
  if (navigation == Navigation::Fly) {
    eye_ += step * (input.forward * forward() + input.right * right + input.up * Vec3(0.0f, 0.0f, 1.0f));
    return;
  }
  eye_ += step * (input.forward * flat_forward + input.right * right);
  snapToGround(ground);
}

void CameraController::snapToGround(const GroundFunction& ground) {
  if (!ground) return;
  eye_.z = ground(eye_.x, eye_.y, eye_.z - kWalkEyeHeight) + kWalkEyeHeight;
}

Camera CameraController::camera(int width, int height, float near_plane, float far_plane) const {
  Camera c;
  c.eye = eye_;
  c.at = eye_ + forward();
  c.up = Vec3(0.0f, 0.0f, 1.0f);
  c.fov_y = float(degToRad(double(settings_.fov_deg)));
  c.width = width;
  c.height = height;
  c.near_plane = near_plane;
  c.far_plane = far_plane;
  return c;
}

}  // namespace farfield::view
