// Image error metrics against a reference frame. All compare the RGB channels of two images of the same size
// (alpha is ignored) and throw farfield::Error when the sizes differ.
#pragma once

#include "farfield/image/image.h"

namespace farfield::image {

// Peak signal-to-noise ratio in dB over RGB with peak 255; identical images give +infinity.
double psnr(const ColorImage& a, const ColorImage& b);
// Mean absolute difference over RGB, in 8-bit units (0..255).
double meanAbsoluteError(const ColorImage& a, const ColorImage& b);
// Share (0..1) of pixels whose largest channel difference exceeds threshold (8-bit units; default 8/255).
double shareOverThreshold(const ColorImage& a, const ColorImage& b, int threshold = 8);
// Structural similarity (Wang et al. 2004) on luma (BT.601), 11x11 Gaussian window with sigma 1.5,
// K1 = 0.01, K2 = 0.03, L = 255; mean over the valid windows. SSIM(x, x) = 1. An image narrower or shorter than
// 11 pixels uses the largest odd window that fits in that direction (Gaussian renormalised); empty images give 1.
double ssim(const ColorImage& a, const ColorImage& b);

struct ImageMetrics {
  double psnr_db = 0.0;
  double mae = 0.0;
  double ssim = 0.0;
  double bad_pixel_share = 0.0;  // share over threshold
};
ImageMetrics compareImages(const ColorImage& a, const ColorImage& b, int threshold = 8);

// Difference heat map: per pixel the largest channel difference mapped through a perceptual colour ramp
// (black = equal, then blue, red, yellow, white at full_scale and above).
ColorImage diffHeatmap(const ColorImage& a, const ColorImage& b, int full_scale = 64);

}  // namespace farfield::image
