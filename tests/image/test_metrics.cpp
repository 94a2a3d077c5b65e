#include "farfield/image/metrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "farfield/core/error.h"

using namespace farfield;
using namespace farfield::image;

namespace {

Rgba8 rgba(int r, int g, int b, int a = 255) { return Rgba8(uint8_t(r), uint8_t(g), uint8_t(b), uint8_t(a)); }

ColorImage randomImage(int w, int h, unsigned seed, int lo = 0, int hi = 255) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> u(lo, hi);
  ColorImage img(w, h);
  for (Rgba8& p : img.pixels()) p = rgba(u(rng), u(rng), u(rng), 255);
  return img;
}

// A smooth image (gradients and a disc) so that SSIM reacts to noise as on rendered frames.
ColorImage smoothImage(int w, int h) {
  ColorImage img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool disc = (x - w / 2) * (x - w / 2) + (y - h / 2) * (y - h / 2) < (w / 4) * (w / 4);
      img.at(x, y) = rgba(disc ? 220 : x * 200 / w, y * 200 / h, disc ? 30 : 120);
    }
  return img;
}

ColorImage addNoise(const ColorImage& img, int amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> u(-amplitude, amplitude);
  ColorImage out = img;
  for (Rgba8& p : out.pixels())
    for (int c = 0; c < 3; ++c) p[c] = uint8_t(std::clamp(int(p[c]) + u(rng), 0, 255));
  return out;
}

// Brute-force SSIM straight from the paper's definition: for every window position fully inside the image, the
// 2D Gaussian weights w(i, j) = exp(-(i^2 + j^2) / (2 sigma^2)) / sum, the weighted means, variances and
// covariance summed directly over the (2 rx + 1) x (2 ry + 1) window.
double bruteForceSsim(const ColorImage& a, const ColorImage& b, int rx, int ry) {
  const double c1 = std::pow(0.01 * 255, 2), c2 = std::pow(0.03 * 255, 2);
  std::vector<double> wts;
  double wsum = 0;
  for (int j = -ry; j <= ry; ++j)
    for (int i = -rx; i <= rx; ++i) {
      wts.push_back(std::exp(-(i * i + j * j) / (2 * 1.5 * 1.5)));
      wsum += wts.back();
    }
  auto lum = [](Rgba8 p) { return 0.299 * p.r + 0.587 * p.g + 0.114 * p.b; };
  double total = 0;
  int count = 0;
  for (int cy = ry; cy < a.height() - ry; ++cy)
    for (int cx = rx; cx < a.width() - rx; ++cx) {
      double mx = 0, my = 0;
      size_t k = 0;
      for (int j = -ry; j <= ry; ++j)
        for (int i = -rx; i <= rx; ++i, ++k) {
          mx += wts[k] / wsum * lum(a.at(cx + i, cy + j));
          my += wts[k] / wsum * lum(b.at(cx + i, cy + j));
        }
      double sx = 0, sy = 0, sxy = 0;
      k = 0;
      for (int j = -ry; j <= ry; ++j)
        for (int i = -rx; i <= rx; ++i, ++k) {
          double dx = lum(a.at(cx + i, cy + j)) - mx, dy = lum(b.at(cx + i, cy + j)) - my;
          sx += wts[k] / wsum * dx * dx;
          sy += wts[k] / wsum * dy * dy;
          sxy += wts[k] / wsum * dx * dy;
        }
      total += ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sx + sy + c2));
      ++count;
    }
  return total / count;
}

}  // namespace

TEST(Metrics, PsnrOfKnownNoise) {
  ColorImage a = randomImage(31, 17, 1, 4, 251);
  ColorImage b = a;
  int k = 0;
  for (Rgba8& p : b.pixels())
    for (int c = 0; c < 3; ++c) p[c] = uint8_t(p[c] + ((k++ % 2) ? 4 : -4));
  EXPECT_NEAR(psnr(a, b), 10.0 * std::log10(255.0 * 255.0 / 16.0), 1e-9);
  // Alpha is ignored; identical RGB gives +infinity.
  ColorImage c = a;
  for (Rgba8& p : c.pixels()) p.a = 0;
  EXPECT_EQ(psnr(a, c), std::numeric_limits<double>::infinity());
  // One channel of one pixel off by 255 in a 10x10 image: MSE = 255^2 / 300.
  ColorImage d(10, 10, rgba(0, 0, 0)), e = d;
  e.at(3, 4).g = 255;
  EXPECT_NEAR(psnr(d, e), 10.0 * std::log10(300.0), 1e-9);
}

TEST(Metrics, MeanAbsoluteErrorHandComputed) {
  ColorImage a(2, 1), b(2, 1);
  a.at(0, 0) = rgba(10, 20, 30, 0);
  b.at(0, 0) = rgba(11, 18, 33, 255);  // 1 + 2 + 3
  a.at(1, 0) = rgba(100, 5, 5);
  b.at(1, 0) = rgba(90, 5, 5);  // 10
  EXPECT_DOUBLE_EQ(meanAbsoluteError(a, b), 16.0 / 6.0);
  EXPECT_DOUBLE_EQ(meanAbsoluteError(a, a), 0.0);
}

TEST(Metrics, ShareOverThreshold) {
  ColorImage a(10, 10, rgba(100, 100, 100)), b = a;
  // 20 pixels off by exactly 8 in one channel (not counted), 30 off by 9 (counted), 5 off by 8 in every channel.
  for (int i = 0; i < 20; ++i) b.pixels()[size_t(i)].r = 108;
  for (int i = 20; i < 50; ++i) b.pixels()[size_t(i)].b = 91;
  for (int i = 50; i < 55; ++i) b.pixels()[size_t(i)] = rgba(92, 108, 92);
  EXPECT_DOUBLE_EQ(shareOverThreshold(a, b), 0.30);
  EXPECT_DOUBLE_EQ(shareOverThreshold(a, b, 7), 0.55);
  EXPECT_DOUBLE_EQ(shareOverThreshold(a, b, 9), 0.0);
  EXPECT_DOUBLE_EQ(shareOverThreshold(a, a, 0), 0.0);
}

TEST(Metrics, SsimIdentityAndNoise) {
  ColorImage a = smoothImage(64, 48);
  EXPECT_NEAR(ssim(a, a), 1.0, 1e-12);
  double prev = 1.0;
  for (int amp : {2, 8, 24, 64}) {
    double s = ssim(a, addNoise(a, amp, unsigned(amp)));
    EXPECT_LT(s, prev) << "noise amplitude " << amp;
    prev = s;
  }
  EXPECT_LT(prev, 0.5);
  // Symmetric.
  ColorImage b = addNoise(a, 10, 5);
  EXPECT_NEAR(ssim(a, b), ssim(b, a), 1e-12);
}

TEST(Metrics, SsimMatchesBruteForce) {
  ColorImage a = randomImage(29, 23, 7);
  ColorImage b = addNoise(a, 40, 8);
  EXPECT_NEAR(ssim(a, b), bruteForceSsim(a, b, 5, 5), 1e-6);
  ColorImage s = smoothImage(40, 33), t = addNoise(s, 12, 3);
  EXPECT_NEAR(ssim(s, t), bruteForceSsim(s, t, 5, 5), 1e-6);
  // Exactly one valid window.
  ColorImage u = randomImage(11, 11, 9), v = randomImage(11, 11, 10);
  EXPECT_NEAR(ssim(u, v), bruteForceSsim(u, v, 5, 5), 1e-6);
  // Smaller than the window in one direction: the largest odd window that fits (here 11 x 5).
  ColorImage p = randomImage(20, 6, 11), q = addNoise(p, 30, 12);
  EXPECT_NEAR(ssim(p, q), bruteForceSsim(p, q, 5, 2), 1e-6);
}

TEST(Metrics, CompareImagesAgreesWithSingleMetrics) {
  ColorImage a = smoothImage(50, 40), b = addNoise(a, 12, 4);
  ImageMetrics m = compareImages(a, b, 5);
  EXPECT_DOUBLE_EQ(m.psnr_db, psnr(a, b));
  EXPECT_DOUBLE_EQ(m.mae, meanAbsoluteError(a, b));
  EXPECT_DOUBLE_EQ(m.ssim, ssim(a, b));
  EXPECT_DOUBLE_EQ(m.bad_pixel_share, shareOverThreshold(a, b, 5));
  EXPECT_GT(m.bad_pixel_share, 0.0);
}

TEST(Metrics, DifferentSizesThrow) {
  ColorImage a(8, 8), b(8, 9);
  EXPECT_THROW(psnr(a, b), Error);
  EXPECT_THROW(meanAbsoluteError(a, b), Error);
  EXPECT_THROW(shareOverThreshold(a, b), Error);
  EXPECT_THROW(ssim(a, b), Error);
  EXPECT_THROW(compareImages(a, b), Error);
  EXPECT_THROW(diffHeatmap(a, b), Error);
  EXPECT_THROW(diffHeatmap(a, a, 0), Error);
}

TEST(Metrics, HeatmapRamp) {
  // Column x has its red channel off by x: check the ramp stops with full scale 64.
  ColorImage a(256, 2, rgba(0, 0, 0)), b = a;
  for (int x = 0; x < 256; ++x) b.at(x, 0).r = uint8_t(x);
  ColorImage h = diffHeatmap(a, b, 64);
  ASSERT_EQ(h.width(), 256);
  for (int x = 0; x < 256; ++x) EXPECT_EQ(h.at(x, 1), rgba(0, 0, 0)) << x;  // equal row: black
  EXPECT_EQ(h.at(0, 0), rgba(0, 0, 0));
  EXPECT_EQ(h.at(16, 0), rgba(0, 0, 255));     // 1/4: blue
  EXPECT_EQ(h.at(32, 0), rgba(255, 0, 0));     // 1/2: red
  EXPECT_EQ(h.at(48, 0), rgba(255, 255, 0));   // 3/4: yellow
  EXPECT_EQ(h.at(64, 0), rgba(255, 255, 255));  // full scale: white
  EXPECT_EQ(h.at(255, 0), rgba(255, 255, 255));
  EXPECT_EQ(h.at(8, 0), rgba(0, 0, 128));  // halfway black -> blue
  // The largest channel difference counts, whichever channel.
  ColorImage c(1, 1, rgba(10, 10, 10)), d(1, 1, rgba(12, 42, 0));
  EXPECT_EQ(diffHeatmap(c, d, 64).at(0, 0), h.at(32, 0));
}
