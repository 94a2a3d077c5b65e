// Fly and walk cameras of the interactive viewer: keyboard and mouse input in, a camera out. Pure math, no window:
// the viewer turns GLFW's keys and mouse into a ControlInput, tests feed them directly.
//
// Fly: W/S move along the view direction, A/D sideways, Q/E down/up along world z. Walk: W/S/A/D move in the ground
// plane and the eye is held kWalkEyeHeight above the ground under it (a ground function, e.g. extract::GroundHeight
// over the scene's objects: the lowest walkable surface, so that roofs and bridges do not lift the walker). Dragging
// the mouse turns the view (yaw about world z, pitch clamped short of straight up and down).
#pragma once

#include <functional>

#include "farfield/core/camera.h"
#include "farfield/core/math.h"

namespace farfield::view {

enum class Navigation { Fly, Walk };
const char* navigationName(Navigation navigation);

inline constexpr float kWalkEyeHeight = 1.7f;  // metres above the ground

struct ControlInput {
  float forward = 0.0f;  // -1..1: W = +1, S = -1
  float right = 0.0f;    // -1..1: D = +1, A = -1
  float up = 0.0f;       // -1..1: E = +1, Q = -1 (fly only)
  float look_x = 0.0f;   // pixels the mouse moved while dragging (right positive)
  float look_y = 0.0f;   // (down positive)
  bool fast = false;     // shift
  double dt = 0.0;       // seconds since the last update
};

struct ControllerSettings {
  float speed = 10.0f;            // metres per second
  float fast_factor = 5.0f;       // speed multiplier with shift
  float radians_per_pixel = 0.004f;
  float fov_deg = 60.0f;          // vertical field of view
};

// Ground height z at (x, y), `fallback` where it knows no ground.
using GroundFunction = std::function<float(float x, float y, float fallback)>;

class CameraController {
 public:
  CameraController() = default;
  // Pose from a camera (a replayed path's frame): its eye and view direction; fov from the camera.
  void setPose(const Camera& camera);
  void setPose(const Vec3& eye, const Vec3& at);
  // Advances by one input. Walk needs a ground function (without one it moves like fly, in the ground plane).
  void update(const ControlInput& input, Navigation navigation, const GroundFunction& ground = {});
  // Puts the eye kWalkEyeHeight above the ground under it (when switching to walk).
  void snapToGround(const GroundFunction& ground);

  ControllerSettings& settings() { return settings_; }
  const ControllerSettings& settings() const { return settings_; }
  const Vec3& eye() const { return eye_; }
  float yaw() const { return yaw_; }      // radians from +x towards +y
  float pitch() const { return pitch_; }  // radians above the horizon
  Vec3 forward() const;
  // The camera: eye, at = eye + forward, up = +z, the settings' field of view, the given size.
  Camera camera(int width, int height, float near_plane = 0.5f, float far_plane = 20000.0f) const;

 private:
  Vec3 eye_{0.0f, 0.0f, 10.0f};
  float yaw_ = 0.0f;
  float pitch_ = 0.0f;
  ControllerSettings settings_;
};

}  // namespace farfield::view
