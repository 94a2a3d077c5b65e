// Pinhole camera and view frustum.
//
// World frame: right-handed, Z up (x east, y north, z up), metres. Images have row 0 at the top.
// Projection: reversed Z with a [0,1] depth range (glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE)): window depth 1 at
// the near plane, 0 at the far plane and for the background. With a 32-bit float depth buffer this keeps depth
// precision roughly constant in relative terms from the near plane to kilometres away.
#pragma once

#include <array>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"

namespace farfield {

struct Camera {
  Vec3 eye{0.0f, -10.0f, 2.0f};
  Vec3 at{0.0f, 0.0f, 0.0f};
  Vec3 up{0.0f, 0.0f, 1.0f};
  float fov_y = float(degToRad(60.0));  // vertical field of view, radians
  int width = 512;                      // pixels
  int height = 512;
  float near_plane = 0.5f;  // metres
  float far_plane = 20000.0f;

  float aspect() const { return float(width) / float(height); }
  // Horizontal field of view, radians.
  float fovX() const;
  Mat4 view() const;
  // Reversed-Z projection (see the file comment).
  Mat4 projection() const;
  Mat4 viewProjection() const { return projection() * view(); }
  Vec3 forward() const { return glm::normalize(at - eye); }
  // The same view on a w x h image at the same pixel density (the field of view grown or shrunk with the height):
  // a guard band around the image, or a part of it.
  Camera resized(int w, int h) const;

  // Distance along the view axis (metres) of a window depth value in [0,1] (reversed Z).
  float linearDepth(float window_depth) const;
  // World-space point seen at pixel (px, py) (row 0 at the top, pixel centre at +0.5) with the given window depth.
  Vec3 unproject(float px, float py, float window_depth) const;
  // Pixel position (x right, y down, in pixels) and window depth of a world point; w <= 0 means behind the camera.
  Vec3 project(const Vec3& world, float* w = nullptr) const;

  // Throws farfield::Error when the camera is unusable (eye == at, up parallel to the view, bad fov or size).
  void validate(const char* what = "camera") const;
};

// Six planes (a, b, c, d) with a*x + b*y + c*z + d >= 0 inside: left, right, bottom, top, far, near.
struct Frustum {
  std::array<Vec4, 6> planes;

  static Frustum fromMatrix(const Mat4& view_projection);
  // Conservative: false only when the box is certainly outside.
  bool intersects(const Box3& box) const;
  bool contains(const Vec3& p) const;
};

}  // namespace farfield
