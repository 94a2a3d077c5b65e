#include "farfield/eval/temporal_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::eval {
namespace {

constexpr int kW = 48, kH = 32;

// A scene that changes every frame on its own: a diagonal gradient sliding one pixel per frame.
image::ColorImage sliding(int frame) {
  image::ColorImage img(kW, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const uint8_t v = uint8_t((x * 5 + y * 3 + frame * 5) % 256);
      img.pixels()[size_t(y) * kW + x] = image::Rgba8(v, uint8_t(255 - v), uint8_t(v / 2), 255);
    }
  return img;
}

std::vector<image::ColorImage> slidingSequence(int n) {
  std::vector<image::ColorImage> frames;
  for (int k = 0; k < n; ++k) frames.push_back(sliding(k));
  return frames;
}

void paintBlock(image::ColorImage& img, int x0, int y0, int size, image::Rgba8 colour) {
  for (int y = y0; y < y0 + size; ++y)
    for (int x = x0; x < x0 + size; ++x) img.pixels()[size_t(y) * kW + x] = colour;
}

TEST(PoppingError, IdenticalSequencesGiveZero) {
  const std::vector<image::ColorImage> reference = slidingSequence(8);
  const std::vector<double> popping = poppingSeries(reference, reference);
  ASSERT_EQ(popping.size(), 8u);
  EXPECT_TRUE(std::isnan(popping[0]));  // no previous frame
  for (size_t k = 1; k < popping.size(); ++k) EXPECT_EQ(popping[k], 0.0) << k;
}

TEST(PoppingError, ARepresentationSwitchPeaksAtItsFrame) {
  // The mode shows the reference, except that from frame 5 on a block of wrong colour covers part of it (an impostor
  // switched in): one pop at frame 5, none before, none after (the block then changes less than the scene under it).
  const std::vector<image::ColorImage> reference = slidingSequence(10);
  std::vector<image::ColorImage> mode = reference;
  for (size_t k = 5; k < mode.size(); ++k) paintBlock(mode[k], 10, 8, 12, image::Rgba8(255, 255, 255, 255));
  const std::vector<double> popping = poppingSeries(mode, reference);
  ASSERT_EQ(popping.size(), 10u);
  for (size_t k = 1; k < popping.size(); ++k) {
    if (k == 5)
      EXPECT_GT(popping[k], 5.0);  // 144 of 1536 pixels jump by about 100 on average
    else
      EXPECT_EQ(popping[k], 0.0) << k;
  }
  // The peak is the only maximum.
  size_t peak = 1;
  for (size_t k = 1; k < popping.size(); ++k)
    if (popping[k] > popping[peak]) peak = k;
  EXPECT_EQ(peak, 5u);
}

TEST(PoppingError, AConstantErrorDoesNotPop) {
  // A mode that is off by the same amount on every frame (a colour shift) changes as the reference does.
  std::vector<image::ColorImage> reference;
  std::vector<image::ColorImage> mode;
  for (int k = 0; k < 6; ++k) {
    image::ColorImage r(kW, kH, image::Rgba8(uint8_t(40 + 10 * k), 90, 120, 255));
    image::ColorImage m(kW, kH, image::Rgba8(uint8_t(60 + 10 * k), 90, 120, 255));
    reference.push_back(r);
    mode.push_back(m);
  }
  const std::vector<double> popping = poppingSeries(mode, reference);
  for (size_t k = 1; k < popping.size(); ++k) EXPECT_EQ(popping[k], 0.0) << k;
}

TEST(PoppingError, AFrozenImageCountsWhenItJumps) {
  // A stale impostor: the mode keeps frame 0 for frames 0-3 (less change than the scene: no popping), then catches up
  // at frame 4 with a jump larger than the scene's own change between frames 3 and 4.
  const std::vector<image::ColorImage> reference = slidingSequence(7);
  std::vector<image::ColorImage> mode = reference;
  for (size_t k = 1; k < 4; ++k) mode[k] = reference[0];
  const std::vector<double> popping = poppingSeries(mode, reference);
  EXPECT_EQ(popping[1], 0.0);
  EXPECT_EQ(popping[2], 0.0);
  EXPECT_EQ(popping[3], 0.0);
  EXPECT_GT(popping[4], 1.0);
  EXPECT_EQ(popping[5], 0.0);
  EXPECT_EQ(popping[6], 0.0);
  // One pair directly: the jump is the change from frame 0 to 4 minus the scene's change from 3 to 4.
  EXPECT_DOUBLE_EQ(popping[4], poppingError(mode[3], mode[4], reference[3], reference[4]));
}

TEST(PoppingError, SizesAndLengthsMustMatch) {
  const image::ColorImage a(kW, kH), b(kW + 1, kH);
  EXPECT_THROW(poppingError(a, a, a, b), Error);
  EXPECT_THROW(poppingError(a, b, a, a), Error);
  const std::vector<image::ColorImage> three = slidingSequence(3), two = slidingSequence(2);
  EXPECT_THROW(poppingSeries(three, two), Error);
  EXPECT_TRUE(poppingSeries(std::vector<image::ColorImage>{}, std::vector<image::ColorImage>{}).empty());
}

}  // namespace
}  // namespace farfield::eval
