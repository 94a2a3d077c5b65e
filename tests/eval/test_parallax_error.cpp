#include "farfield/eval/parallax_error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/eval/frame_stats.h"

namespace farfield::eval {
namespace {

struct Rect {
  uint32_t id;
  int x0, y0, x1, y1;  // [x0, x1) x [y0, y1), clipped when drawn
};

image::IdImage draw(int w, int h, const std::vector<Rect>& rects) {
  image::IdImage img(w, h, 0u);
  for (const Rect& r : rects)  // later rectangles cover earlier ones (nearer)
    for (int y = std::max(0, r.y0); y < std::min(h, r.y1); ++y)
      for (int x = std::max(0, r.x0); x < std::min(w, r.x1); ++x) img.at(x, y) = r.id;
  return img;
}

// Brute force of the documented definition: every pixel against every pixel, no distance transform.
struct Brute {
  std::vector<double> px;      // displacement per mismatching pixel, row-major
  std::vector<int> positions;  // their pixel indices
};
Brute bruteForce(const image::IdImage& ref, const image::IdImage& tst, const std::vector<uint32_t>& ignore) {
  const auto eff = [&](uint32_t id) {
    return std::find(ignore.begin(), ignore.end(), id) != ignore.end() ? 0u : id;
  };
  const int w = ref.width(), h = ref.height();
  const long long diag2 = (long long)w * w + (long long)h * h;
  // Nearest pixel of `id` in `img` (squared), diag2 when absent.
  const auto nearest = [&](const image::IdImage& img, uint32_t id, int px, int py) {
    long long best = -1;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (eff(img.at(x, y)) == id) {
          const long long d = (long long)(x - px) * (x - px) + (long long)(y - py) * (y - py);
          if (best < 0 || d < best) best = d;
        }
    return best < 0 ? diag2 : best;
  };
  Brute out;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint32_t r = eff(ref.at(x, y)), t = eff(tst.at(x, y));
      if (r == t) continue;
      long long d2 = 0;
      if (t != 0) d2 = std::max(d2, nearest(ref, t, x, y));
      if (r != 0) d2 = std::max(d2, nearest(tst, r, x, y));
      out.px.push_back(std::sqrt(double(d2)));
      out.positions.push_back(y * w + x);
    }
  return out;
}

// Type-7 percentile written out again (sorted, linear interpolation between closest ranks).
double percentile7(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const double r = p * double(v.size() - 1);
  const size_t lo = size_t(std::floor(r));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (r - double(lo)) * (v[hi] - v[lo]);
}

TEST(ParallaxError, IdenticalImagesGiveZero) {
  const image::IdImage a = draw(40, 30, {{1, 0, 20, 40, 30}, {3, 5, 5, 15, 25}, {4, 10, 8, 30, 12}});
  const ParallaxError e = parallaxError(a, a);
  EXPECT_EQ(e.mismatched, 0u);
  EXPECT_EQ(e.max_px, 0.0);
  EXPECT_EQ(e.mean_px, 0.0);
  EXPECT_EQ(e.percentile_px, 0.0);
  EXPECT_EQ(e.share, 0.0);
  EXPECT_EQ(e.worst_x, -1);
}

TEST(ParallaxError, ShiftedObjectGivesItsShift) {
  for (int d = 1; d <= 7; ++d) {
    const image::IdImage ref = draw(64, 48, {{5, 10, 10, 30, 40}});
    const image::IdImage tst = draw(64, 48, {{5, 10 + d, 10, 30 + d, 40}});
    const ParallaxError e = parallaxError(ref, tst);
    EXPECT_NEAR(e.max_px, double(d), 1e-12) << "shift " << d;
    EXPECT_EQ(e.mismatched, size_t(2 * d * 30));  // d columns uncovered, d columns covered, 30 rows each
    // Columns at distance 1..d on each side: mean (d + 1) / 2.
    EXPECT_NEAR(e.mean_px, (d + 1) / 2.0, 1e-12);
  }
  // Diagonal shift (3, 4): only the corner pixels are the full shift away from the other silhouette.
  const image::IdImage ref = draw(64, 48, {{5, 10, 10, 30, 30}});
  const image::IdImage tst = draw(64, 48, {{5, 13, 14, 33, 34}});
  const ParallaxError e = parallaxError(ref, tst);
  const Brute b = bruteForce(ref, tst, {});
  EXPECT_EQ(e.max_px, *std::max_element(b.px.begin(), b.px.end()));
  EXPECT_NEAR(e.max_px, 5.0, 1e-12);  // the corner pixel (32, 33) is (3, 4) from (29, 29)
}

TEST(ParallaxError, AbsentObjectCostsTheDiagonal) {
  const image::IdImage ref = draw(40, 30, {{2, 5, 5, 10, 10}});
  const image::IdImage tst = draw(40, 30, {{7, 20, 20, 22, 21}});
  const ParallaxError e = parallaxError(ref, tst);
  EXPECT_EQ(e.mismatched, 25u + 2u);
  EXPECT_NEAR(e.max_px, 50.0, 1e-12);  // sqrt(40^2 + 30^2)
  EXPECT_NEAR(e.mean_px, 50.0, 1e-12);
  // skip_absent: both objects are absent from the other image, so no pixel is measured.
  ParallaxOptions skip;
  skip.skip_absent = true;
  const ParallaxError s = parallaxError(ref, tst, skip);
  EXPECT_EQ(s.mismatched, 0u);
  EXPECT_EQ(s.absent, 25u + 2u);
  EXPECT_EQ(s.max_px, 0.0);
  // An object present in both but shifted by 3 still counts; the absent one is left out.
  const image::IdImage ref2 = draw(40, 30, {{2, 5, 5, 10, 10}, {4, 30, 5, 32, 7}});
  const image::IdImage tst2 = draw(40, 30, {{2, 8, 5, 13, 10}});
  const ParallaxError s2 = parallaxError(ref2, tst2, skip);
  EXPECT_EQ(s2.absent, 4u);
  EXPECT_EQ(s2.mismatched, 3u * 5u * 2u);
  EXPECT_NEAR(s2.max_px, 3.0, 1e-12);
}

TEST(ParallaxError, IgnoredIdsCountAsBackground) {
  // Ground (1) in the reference, sky in the test: does not count. An object over the ground in the test does.
  image::IdImage ref = draw(40, 30, {{1, 0, 15, 40, 30}, {3, 10, 10, 14, 20}});
  image::IdImage tst = draw(40, 30, {{3, 12, 10, 16, 20}});
  ParallaxOptions opt;
  opt.ignore_ids = {1};
  const ParallaxError e = parallaxError(ref, tst, opt);
  const Brute b = bruteForce(ref, tst, {1});
  EXPECT_EQ(e.mismatched, b.px.size());
  EXPECT_EQ(e.mismatched, 2u * 2u * 10u);
  EXPECT_NEAR(e.max_px, 2.0, 1e-12);
  // Without ignoring the ground, the ground missing from the test costs the diagonal.
  const ParallaxError all = parallaxError(ref, tst);
  EXPECT_NEAR(all.max_px, 50.0, 1e-12);
}

TEST(ParallaxError, MatchesBruteForceOnRandomImages) {
  std::mt19937 rng(1234);
  std::uniform_int_distribution<int> coin(0, 99);
  size_t checked = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const int w = 40, h = 30;
    std::vector<Rect> rects;
    if (coin(rng) < 50) rects.push_back({1, 0, 10 + coin(rng) % 15, w, h});  // a ground band
    const int count = 1 + coin(rng) % 6;
    for (int i = 0; i < count; ++i) {
      const int x0 = coin(rng) % w - 5, y0 = coin(rng) % h - 5;
      rects.push_back({uint32_t(2 + coin(rng) % 5), x0, y0, x0 + 1 + coin(rng) % 18, y0 + 1 + coin(rng) % 14});
    }
    // The test: the same rectangles shifted (parallax), some dropped, one maybe added with a new id.
    std::vector<Rect> moved;
    for (Rect r : rects) {
      if (r.id != 1) {
        if (coin(rng) < 10) continue;
        const int dx = coin(rng) % 9 - 4, dy = coin(rng) % 5 - 2;
        r.x0 += dx, r.x1 += dx, r.y0 += dy, r.y1 += dy;
      }
      moved.push_back(r);
    }
    if (coin(rng) < 20) moved.push_back({9, coin(rng) % w, coin(rng) % h, w, h});
    if (coin(rng) < 30) std::shuffle(moved.begin() + (moved.size() > 1 && moved[0].id == 1), moved.end(), rng);
    const image::IdImage ref = draw(w, h, rects), tst = draw(w, h, moved);

    std::vector<uint32_t> ignore;
    if (coin(rng) < 50) ignore.push_back(1);
    if (coin(rng) < 20) ignore.push_back(uint32_t(2 + coin(rng) % 5));
    ParallaxOptions opt;
    opt.ignore_ids = ignore;
    opt.percentile = coin(rng) < 50 ? 0.99 : 0.9;

    const Brute b = bruteForce(ref, tst, ignore);
    const ParallaxError e = parallaxError(ref, tst, opt);
    const image::Image<float> map = parallaxErrorMap(ref, tst, opt);
    ASSERT_EQ(e.mismatched, b.px.size()) << "trial " << trial;
    if (b.px.empty()) {
      EXPECT_EQ(e.max_px, 0.0);
      continue;
    }
    ++checked;
    double sum = 0.0;
    for (double v : b.px) sum += v;
    EXPECT_EQ(e.max_px, *std::max_element(b.px.begin(), b.px.end())) << "trial " << trial;
    EXPECT_DOUBLE_EQ(e.mean_px, sum / double(b.px.size())) << "trial " << trial;
    EXPECT_DOUBLE_EQ(e.percentile_px, percentile7(b.px, opt.percentile)) << "trial " << trial;
    EXPECT_DOUBLE_EQ(e.share, double(b.px.size()) / double(w * h));
    for (size_t k = 0; k < b.px.size(); ++k)
      ASSERT_EQ(map.data()[b.positions[k]], float(b.px[k])) << "trial " << trial << " pixel " << b.positions[k];
    ASSERT_GE(e.worst_x, 0);
    EXPECT_EQ(double(map.at(e.worst_x, e.worst_y)), float(e.max_px));
  }
  EXPECT_GT(checked, 100u);
}

// 512 x 512 with about 100 ids (the size the bench uses): pixels sampled from the map against brute force. The time
// is printed for information only (speed is not asserted in unit tests).
TEST(ParallaxError, LargeImageWithManyIdsAgreesOnSampledPixels) {
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> coord(-20, 511), size(4, 80), shift(-6, 6);
  const int w = 512, h = 512;
  std::vector<Rect> rects{{1, 0, 300, w, h}};
  for (uint32_t id = 2; id < 102; ++id) {
    const int x0 = coord(rng), y0 = coord(rng) % 320;
    rects.push_back({id, x0, y0, x0 + size(rng), y0 + size(rng)});
  }
  std::vector<Rect> moved = rects;
  for (size_t i = 1; i < moved.size(); ++i) {
    const int dx = shift(rng), dy = shift(rng) / 3;
    moved[i].x0 += dx, moved[i].x1 += dx, moved[i].y0 += dy, moved[i].y1 += dy;
  }
  const image::IdImage ref = draw(w, h, rects), tst = draw(w, h, moved);
  ParallaxOptions opt;
  opt.ignore_ids = {1};
  const auto t0 = std::chrono::steady_clock::now();
  const ParallaxError e = parallaxError(ref, tst, opt);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("512x512, 100 ids: %zu mismatched pixels, max %.2f px, p99 %.2f px, mean %.2f px in %.1f ms\n",
              e.mismatched, e.max_px, e.percentile_px, e.mean_px, ms);
  ASSERT_GT(e.mismatched, 1000u);

  const image::Image<float> map = parallaxErrorMap(ref, tst, opt);
  const auto eff = [](uint32_t id) { return id == 1 ? 0u : id; };
  const auto nearest = [&](const image::IdImage& img, uint32_t id, int px, int py) {
    long long best = (long long)w * w + (long long)h * h;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (eff(img.at(x, y)) == id)
          best = std::min(best, (long long)(x - px) * (x - px) + (long long)(y - py) * (y - py));
    return best;
  };
  std::uniform_int_distribution<int> pix(0, w * h - 1);
  int sampled = 0;
  for (int tries = 0; sampled < 60 && tries < 100000; ++tries) {
    const int p = pix(rng), x = p % w, y = p / w;
    const uint32_t r = eff(ref.at(x, y)), t = eff(tst.at(x, y));
    if (r == t) {
      ASSERT_EQ(map.at(x, y), 0.0f);
      continue;
    }
    long long d2 = 0;
    if (t != 0) d2 = std::max(d2, nearest(ref, t, x, y));
    if (r != 0) d2 = std::max(d2, nearest(tst, r, x, y));
    ASSERT_EQ(map.at(x, y), float(std::sqrt(double(d2)))) << x << "," << y;
    ++sampled;
  }
  EXPECT_EQ(sampled, 60);
  // The worst pixel, too.
  const uint32_t r = eff(ref.at(e.worst_x, e.worst_y)), t = eff(tst.at(e.worst_x, e.worst_y));
  long long d2 = 0;
  if (t != 0) d2 = std::max(d2, nearest(ref, t, e.worst_x, e.worst_y));
  if (r != 0) d2 = std::max(d2, nearest(tst, r, e.worst_x, e.worst_y));
  EXPECT_EQ(e.max_px, std::sqrt(double(d2)));
}

TEST(ParallaxError, RejectsBadInput) {
  const image::IdImage a(10, 10, 0u), b(10, 11, 0u);
  EXPECT_THROW(parallaxError(a, b), Error);
  ParallaxOptions opt;
  opt.percentile = 0.0;
  EXPECT_THROW(parallaxError(a, a, opt), Error);
  opt.percentile = 1.5;
  EXPECT_THROW(parallaxError(a, a, opt), Error);
  const image::IdImage empty;
  EXPECT_EQ(parallaxError(empty, empty).mismatched, 0u);
}

}  // namespace
}  // namespace farfield::eval

namespace farfield::eval {
namespace {

// The percentile over object pixels: a 10x10 object shifted by 2 has 20 + 20 mismatching pixels among 120 object
// pixels; its 99th percentile is 2 while a single far-off stray pixel in a large correct image hardly moves it.
TEST(ParallaxError, ObjectPercentileCountsAgreeingPixelsAsZero) {
  const image::IdImage ref = draw(60, 40, {{3, 10, 10, 20, 20}});
  const image::IdImage tst = draw(60, 40, {{3, 12, 10, 22, 20}});
  const ParallaxError e = parallaxError(ref, tst);
  EXPECT_EQ(e.object_pixels, 120u);
  EXPECT_EQ(e.mismatched, 40u);
  EXPECT_NEAR(e.object_percentile_px, 2.0, 1e-12);
  // Brute force of the rank rule: 80 zeros and 40 twos, 99th percentile by linear interpolation.
  std::vector<double> all(80, 0.0);
  all.insert(all.end(), 40, 2.0);
  EXPECT_DOUBLE_EQ(e.object_percentile_px, percentile(all, 99.0));

  // A big correct object plus one stray pixel of it 30 px away: percentile_px (mismatched only) is the stray's,
  // the object percentile stays 0.
  image::IdImage big_ref = draw(60, 40, {{5, 0, 0, 30, 40}});
  image::IdImage big_tst = big_ref;
  big_tst.at(59, 0) = 5;
  const ParallaxError s = parallaxError(big_ref, big_tst);
  EXPECT_EQ(s.mismatched, 1u);
  EXPECT_NEAR(s.percentile_px, 30.0, 1e-12);
  EXPECT_EQ(s.object_percentile_px, 0.0);
}

}  // namespace
}  // namespace farfield::eval
