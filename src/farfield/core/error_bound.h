// The image-error bound a user states once (DESIGN.md, "the two promises"): at most `pixels` pixels of error in
// frames `width` x `height` with the vertical field of view `fov_y`. Every bake and the runtime turn it into an
// angle with the same function, so the bound the bake computes validity regions for and the parallax bench measures
// are in one unit.
//
// The angle of a pixel is not the same over a pinhole image: with the focal length f = (height / 2) / tan(fov_y / 2)
// in pixels, a point at angle beta from the view axis lies r = f tan(beta) pixels from the centre, and a small angular
// motion d(beta) moves it by dr = f d(beta) / cos^2(beta) pixels along the radius (f d(beta) / cos(beta) across it).
// So one pixel is the largest angle at the centre (1 / f) and the smallest at the image corners (cos^2(beta_c) / f,
// beta_c the half diagonal field of view). angle() uses the corner: an angular error of at most angle() is at most
// `pixels` pixels anywhere in the frame, whatever the frame's shape. This is what makes the bound a promise rather
// than an average; for 640 x 360 at 60 degrees the corner pixel is 0.42 times the centre one.
#pragma once

#include <string>

#include "farfield/core/math.h"

namespace farfield {

struct Camera;
template <typename V>
struct BoxT;

struct ErrorBound {
  double pixels = 10.0;
  int width = 640;                      // frame size, pixels
  int height = 360;
  double fov_y = degToRad(60.0);        // vertical field of view, radians

  // The bound of a frame drawn with this camera (its size and field of view).
  static ErrorBound forCamera(double pixels, const Camera& camera);

  double focalPixels() const;           // f = (height / 2) / tan(fov_y / 2)
  double fovX() const;                  // horizontal field of view, radians
  double centrePixelAngle() const;      // 1 / f, radians
  double cornerPixelAngle() const;      // cos^2(half diagonal field of view) / f, radians: the smallest pixel
  // The smallest pixel angle within `radius_px` pixels of the image centre: cos^2(atan(r / f)) / f (r clamped to the
  // half diagonal). What lies inside a smaller circle may move by a larger angle for the same pixel count.
  double pixelAngleWithin(double radius_px) const;
  // The angle no impostor error may exceed: pixels * cornerPixelAngle().
  double angle() const;
  // The same for something that covers only the part of the frame within `radius_px` of its centre.
  double angleWithin(double radius_px) const { return pixels * pixelAngleWithin(radius_px); }
  // Pixels that an angular error `radians` can span at most anywhere in the frame: radians / cornerPixelAngle().
  double pixelsOf(double radians) const;

  // Throws farfield::Error naming `what` for a non-finite or negative pixel count, a size below 1 or a field of view
  // outside (0, 180) degrees.
  void validate(const std::string& what = "error bound") const;
};

// Distance in pixels from the centre of the camera's frame to the farthest point of the frame that `box` can cover
// (its projected corners' rectangle clamped to the frame); the half diagonal when part of the box is behind the eye
// plane. With ErrorBound::angleWithin() it gives the bound of an impostor where it is drawn.
double frameRadius(const Camera& camera, const BoxT<Vec3>& box);

}  // namespace farfield
