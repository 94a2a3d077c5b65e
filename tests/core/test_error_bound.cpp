#include "farfield/core/error_bound.h"

#include <cmath>

#include <gtest/gtest.h>

#include "farfield/core/camera.h"
#include "farfield/core/error.h"

namespace farfield {
namespace {

// Hand computation for 512 x 512 at 60 degrees: f = 256 / tan(30 deg) = 443.405 px; half diagonal 362.039 px;
// cos^2 = f^2 / (f^2 + r^2) = 196608 / (196608 + 131072) = 0.6; corner pixel = 0.6 / 443.405 = 1.35316e-3 rad.
TEST(ErrorBound, SquareFrameByHand) {
  ErrorBound b{10.0, 512, 512, degToRad(60.0)};
  EXPECT_NEAR(b.focalPixels(), 443.4050, 1e-3);
  EXPECT_NEAR(b.fovX(), degToRad(60.0), 1e-12);
  EXPECT_NEAR(b.centrePixelAngle(), 1.0 / 443.4050, 1e-8);
  EXPECT_NEAR(b.cornerPixelAngle(), 0.6 / 443.4050, 1e-8);
  EXPECT_NEAR(b.angle(), 10.0 * 0.6 / 443.4050, 1e-7);
  EXPECT_NEAR(b.pixelsOf(b.angle()), 10.0, 1e-9);
}

// 640 x 360 at 60 degrees vertical: f = 180 / tan(30 deg) = 311.769 px; half diagonal = 367.151 px;
// cos^2 = 97200 / (97200 + 134800) = 0.418966; horizontal fov = 2 atan(320 / 311.769) = 91.4934 deg.
TEST(ErrorBound, WideFrameByHand) {
  ErrorBound b{2.0, 640, 360, degToRad(60.0)};
  EXPECT_NEAR(b.focalPixels(), 311.7691, 1e-3);
  EXPECT_NEAR(radToDeg(b.fovX()), 91.4934, 1e-3);
  EXPECT_NEAR(b.cornerPixelAngle(), 0.418966 / 311.7691, 1e-8);
  EXPECT_NEAR(b.angle(), 2.0 * 0.418966 / 311.7691, 1e-7);
  // The old square-frame conversion (px * fov_x / width) was 1.9x too loose at the corners of this frame.
  EXPECT_GT(2.0 * b.fovX() / 640.0, 1.8 * b.angle());
}

// The corner pixel really is the smallest angle a pixel spans: project two world directions one corner-pixel angle
// apart and check no pixel step anywhere is smaller, and that the corner step equals cornerPixelAngle().
TEST(ErrorBound, CornerPixelIsTheSmallestAgainstProjection) {
  Camera cam;
  cam.eye = Vec3(0.0f);
  cam.at = Vec3(0.0f, 1.0f, 0.0f);
  cam.up = Vec3(0.0f, 0.0f, 1.0f);
  cam.width = 640;
  cam.height = 360;
  cam.fov_y = float(degToRad(60.0));
  const ErrorBound b = ErrorBound::forCamera(1.0, cam);
  // Angle per pixel of a step from pixel corner (x, y) by (dx, dy), along the radius at the image corner.
  const auto step_angle = [&](double x, double y, double dx, double dy) {
    const DVec3 a = glm::normalize(DVec3(cam.unproject(float(x), float(y), 0.5f)));
    const DVec3 c = glm::normalize(DVec3(cam.unproject(float(x + dx), float(y + dy), 0.5f)));
    return std::acos(std::clamp(glm::dot(a, c), -1.0, 1.0)) / std::hypot(dx, dy);
  };
  double smallest = 1e9;
  for (int py = 0; py < cam.height; py += 9)
    for (int px = 0; px < cam.width; px += 8)
      for (auto [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}, std::pair{1, 1}})
        smallest = std::min(smallest, step_angle(px, py, dx, dy));
  EXPECT_GE(smallest, b.cornerPixelAngle() * 0.98);
  // The last step into the corner, along the diagonal (the radius there): the corner's own pixel angle.
  const double r = std::hypot(320.0, 180.0);
  EXPECT_NEAR(step_angle(640.0 - 320.0 / r, 360.0 - 180.0 / r, 320.0 / r, 180.0 / r), b.cornerPixelAngle(),
              0.01 * b.cornerPixelAngle());
}

TEST(ErrorBound, Validate) {
  EXPECT_NO_THROW((ErrorBound{1.0, 640, 360, 1.0}).validate());
  EXPECT_THROW((ErrorBound{-1.0, 640, 360, 1.0}).validate(), Error);
  EXPECT_THROW((ErrorBound{NAN, 640, 360, 1.0}).validate(), Error);
  EXPECT_THROW((ErrorBound{1.0, 0, 360, 1.0}).validate(), Error);
  EXPECT_THROW((ErrorBound{1.0, 640, 360, 0.0}).validate(), Error);
  EXPECT_THROW((ErrorBound{1.0, 640, 360, kPi}).validate(), Error);
}

}  // namespace
}  // namespace farfield
