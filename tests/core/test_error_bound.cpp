#include "farfield/core/error_bound.h"

#include <cmath>

#include <gtest/gtest.h>

#include "farfield/core/bounds.h"
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

// Inside a circle around the centre a pixel spans more angle: from 1 / f at the centre down to the corner's value.
TEST(ErrorBound, PixelAngleWithinARadius) {
  const ErrorBound b{10.0, 640, 360, degToRad(60.0)};
  EXPECT_DOUBLE_EQ(b.pixelAngleWithin(0.0), b.centrePixelAngle());
  EXPECT_DOUBLE_EQ(b.pixelAngleWithin(1e9), b.cornerPixelAngle());
  const double f = b.focalPixels();
  EXPECT_NEAR(b.pixelAngleWithin(f), 0.5 / f, 1e-12);  // 45 degrees off axis: cos^2 = 1/2
  EXPECT_GT(b.angleWithin(100.0), b.angleWithin(200.0));
  EXPECT_GT(b.angleWithin(200.0), b.angle());
}

TEST(ErrorBound, FrameRadiusOfABox) {
  Camera cam;
  cam.eye = Vec3(0.0f);
  cam.at = Vec3(0.0f, 1.0f, 0.0f);
  cam.width = 640;
  cam.height = 360;
  // A small box straight ahead: near the centre.
  EXPECT_LT(frameRadius(cam, Box3{Vec3(-0.5f, 99.5f, -0.5f), Vec3(0.5f, 100.5f, 0.5f)}), 3.0);
  // A box across the whole view: the half diagonal (clamped to the frame).
  EXPECT_NEAR(frameRadius(cam, Box3{Vec3(-500, 10, -500), Vec3(500, 20, 500)}), std::hypot(320.0, 180.0), 1e-6);
  // Part of it behind the eye: the half diagonal.
  EXPECT_NEAR(frameRadius(cam, Box3{Vec3(-1, -1, -1), Vec3(1, 1, 1)}), std::hypot(320.0, 180.0), 1e-6);
  // Brute force: the farthest projected sample point of the box inside the frame is never beyond the radius.
  const Box3 box{Vec3(20, 60, -3), Vec3(35, 80, 12)};
  const double r = frameRadius(cam, box);
  double farthest = 0.0;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j)
      for (int k = 0; k <= 10; ++k) {
        const Vec3 p = cam.project(box.lo + Vec3(i, j, k) * 0.1f * box.extent());
        if (p.x >= 0 && p.x <= 640 && p.y >= 0 && p.y <= 360)
          farthest = std::max(farthest, std::hypot(double(p.x) - 320.0, double(p.y) - 180.0));
      }
  EXPECT_GT(farthest, 0.0);
  EXPECT_LE(farthest, r + 1e-3);
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
