#include "farfield/core/error_bound.h"

#include <cmath>

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

double ErrorBound::cornerPixelAngle() const {
  const double f = focalPixels();
  const double r = 0.5 * std::hypot(double(width), double(height));  // centre to corner, pixels
  // cos^2(beta) with tan(beta) = r / f.
  const double cos2 = (f * f) / (f * f + r * r);
  return cos2 / f;
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

}  // namespace farfield
