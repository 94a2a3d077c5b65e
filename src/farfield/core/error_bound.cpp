#include "farfield/core/error_bound.h"

#include <algorithm>
#include <cmath>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/core/error.h"

namespace farfield {

ErrorBound ErrorBound::forCamera(double pixels, const Camera& camera) {
  ErrorBound bound;
  bound.pixels = pixels;
  bound.width = camera.width;
  bound.height = camera.height;
  bound.fov_y = double(camera.fov_y);
  return bound;
}

double ErrorBound::focalPixels() const { return 0.5 * double(height) / std::tan(0.5 * fov_y); }

double ErrorBound::fovX() const { return 2.0 * std::atan(0.5 * double(width) / focalPixels()); }

double ErrorBound::centrePixelAngle() const { return 1.0 / focalPixels(); }

double ErrorBound::cornerPixelAngle() const { return pixelAngleWithin(0.5 * std::hypot(double(width), double(height))); }

double ErrorBound::pixelAngleWithin(double radius_px) const {
  const double f = focalPixels();
  const double r = std::clamp(radius_px, 0.0, 0.5 * std::hypot(double(width), double(height)));
  // cos^2(beta) with tan(beta) = r / f.
  return (f * f) / (f * f + r * r) / f;
}

double ErrorBound::angle() const { return pixels * cornerPixelAngle(); }

double ErrorBound::pixelsOf(double radians) const { return radians / cornerPixelAngle(); }

void ErrorBound::validate(const std::string& what) const {
  if (!std::isfinite(pixels) || pixels < 0.0)
    throw Error(what, "pixels must be a finite number >= 0, got " + std::to_string(pixels));
  if (width < 1 || height < 1)
    throw Error(what, "frame size must be at least 1 x 1, got " + std::to_string(width) + " x " +
                          std::to_string(height));
  if (!(fov_y > 0.0 && fov_y < kPi))
    throw Error(what, "field of view must be between 0 and 180 degrees, got " + std::to_string(radToDeg(fov_y)));
}

double frameRadius(const Camera& camera, const Box3& box) {
  const double w = double(camera.width), h = double(camera.height);
  const double half_diagonal = 0.5 * std::hypot(w, h);
  if (box.empty()) return 0.0;
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y, (c & 4) ? box.hi.z : box.lo.z);
    float depth_w = 0.0f;
    const Vec3 p = camera.project(corner, &depth_w);
    if (!(depth_w > 0.0f)) return half_diagonal;
    x0 = std::min(x0, double(p.x));
    x1 = std::max(x1, double(p.x));
    y0 = std::min(y0, double(p.y));
    y1 = std::max(y1, double(p.y));
  }
  x0 = std::clamp(x0, 0.0, w);
  x1 = std::clamp(x1, 0.0, w);
  y0 = std::clamp(y0, 0.0, h);
  y1 = std::clamp(y1, 0.0, h);
  const double dx = std::max(std::abs(x0 - 0.5 * w), std::abs(x1 - 0.5 * w));
  const double dy = std::max(std::abs(y0 - 0.5 * h), std::abs(y1 - 0.5 * h));
  return std::min(half_diagonal, std::hypot(dx, dy));
}

}  // namespace farfield
