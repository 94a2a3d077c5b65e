#include "farfield/image/metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::image {

namespace {

void checkSameSize(const ColorImage& a, const ColorImage& b, const char* what) {
  if (a.width() != b.width() || a.height() != b.height())
    throw Error(what, "image sizes differ: " + std::to_string(a.width()) + "x" + std::to_string(a.height()) +
                          " vs " + std::to_string(b.width()) + "x" + std::to_string(b.height()));
}

// The three per-pixel error sums every benchmark frame needs, gathered in one pass over both images. Integer
// accumulators keep the sums exact (a 16k x 16k frame of 255 errors stays far below 2^64).
struct DiffSums {
  uint64_t squared = 0;  // sum over RGB of (a - b)^2
  uint64_t absolute = 0;  // sum over RGB of |a - b|
  uint64_t over = 0;      // pixels whose largest channel difference exceeds the threshold
};

DiffSums diffSums(const ColorImage& a, const ColorImage& b, int threshold) {
  DiffSums s;
  const Rgba8* pa = a.data();
  const Rgba8* pb = b.data();
  const size_t n = a.pixelCount();
  for (size_t i = 0; i < n; ++i) {
    const int dr = std::abs(int(pa[i].r) - int(pb[i].r));
    const int dg = std::abs(int(pa[i].g) - int(pb[i].g));
    const int db = std::abs(int(pa[i].b) - int(pb[i].b));
    s.squared += uint64_t(dr * dr + dg * dg + db * db);
    s.absolute += uint64_t(dr + dg + db);
    s.over += std::max(dr, std::max(dg, db)) > threshold ? 1u : 0u;
  }
  return s;
}

double psnrFromSums(const DiffSums& s, size_t pixels) {
  if (s.squared == 0) return std::numeric_limits<double>::infinity();
  const double mse = double(s.squared) / (3.0 * double(pixels));
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

// Normalised 1D Gaussian of the given radius (sigma 1.5). The 2D SSIM window is the outer product of two of
// them, so filtering rows then columns gives exactly the 11x11 weighted means at 22 instead of 121 taps.
std::vector<double> gaussianKernel(int radius) {
  constexpr double kSigma = 1.5;
  std::vector<double> g(size_t(2 * radius + 1));
  double sum = 0.0;
  for (int i = -radius; i <= radius; ++i) sum += g[size_t(i + radius)] = std::exp(-(i * i) / (2.0 * kSigma * kSigma));
  for (double& v : g) v /= sum;
  return g;
}

// ITU-R BT.601 luma.
inline double luma(const Rgba8& p) { return 0.299 * p.r + 0.587 * p.g + 0.114 * p.b; }

}  // namespace

double psnr(const ColorImage& a, const ColorImage& b) {
  checkSameSize(a, b, "psnr");
  return psnrFromSums(diffSums(a, b, 255), a.pixelCount());
}

double meanAbsoluteError(const ColorImage& a, const ColorImage& b) {
  checkSameSize(a, b, "meanAbsoluteError");
  if (a.empty()) return 0.0;
  return double(diffSums(a, b, 255).absolute) / (3.0 * double(a.pixelCount()));
}

double shareOverThreshold(const ColorImage& a, const ColorImage& b, int threshold) {
  checkSameSize(a, b, "shareOverThreshold");
  if (a.empty()) return 0.0;
  return double(diffSums(a, b, threshold).over) / double(a.pixelCount());
}

// SSIM as in Wang, Bovik, Sheikh and Simoncelli 2004: per window the local means, variances and covariance
// of the two luma images under Gaussian weights, combined as
//   ((2 mu_a mu_b + C1) (2 s_ab + C2)) / ((mu_a^2 + mu_b^2 + C1) (s_a^2 + s_b^2 + C2)),
// averaged over every window that lies fully inside the image. The five weighted sums (a, b, a^2, b^2, ab) are
// filtered along rows into a ring of the last 11 rows, then down the columns; the work is O(pixels) with a few
// row-sized buffers and no per-pixel allocation. Images smaller than the window in a direction use the largest
// odd window that fits, with the Gaussian renormalised.
double ssim(const ColorImage& a, const ColorImage& b) {
  checkSameSize(a, b, "ssim");
  const int w = a.width(), h = a.height();
  if (w == 0 || h == 0) return 1.0;
  constexpr double kC1 = (0.01 * 255.0) * (0.01 * 255.0);
  constexpr double kC2 = (0.03 * 255.0) * (0.03 * 255.0);
  const int rx = std::min(5, (w - 1) / 2), ry = std::min(5, (h - 1) / 2);
  const int kx = 2 * rx + 1, ky = 2 * ry + 1;
  const std::vector<double> gx = gaussianKernel(rx), gy = gaussianKernel(ry);
  const int ow = w - 2 * rx, oh = h - 2 * ry;
  const size_t row_w = size_t(w), out_w = size_t(ow);

  // Input row quantities (5 x w) and the ring of row-filtered quantities (ky slots x 5 x ow).
  std::vector<double> in(5 * row_w);
  std::vector<double> ring(size_t(ky) * 5 * out_w);
  std::vector<double> col(5 * out_w);
  double total = 0.0;

  for (int y = 0; y < h; ++y) {
    double* qa = in.data();
    double* qb = qa + row_w;
    double* qaa = qb + row_w;
    double* qbb = qaa + row_w;
    double* qab = qbb + row_w;
    const Rgba8* ra = a.data() + size_t(y) * row_w;
    const Rgba8* rb = b.data() + size_t(y) * row_w;
    for (size_t x = 0; x < row_w; ++x) {
      const double la = luma(ra[x]), lb = luma(rb[x]);
      qa[x] = la;
      qb[x] = lb;
      qaa[x] = la * la;
      qbb[x] = lb * lb;
      qab[x] = la * lb;
    }
    double* slot = ring.data() + size_t(y % ky) * 5 * out_w;
    for (int q = 0; q < 5; ++q) {
      const double* src = in.data() + size_t(q) * row_w;
      double* dst = slot + size_t(q) * out_w;
      std::fill(dst, dst + out_w, 0.0);
      for (int k = 0; k < kx; ++k) {
        const double g = gx[size_t(k)];
        const double* s = src + k;
        for (size_t x = 0; x < out_w; ++x) dst[x] += g * s[x];
      }
    }
    if (y < ky - 1) continue;

    // Column pass for the output row centred on y - ry: rows y - 2 ry .. y are in the ring.
    std::fill(col.begin(), col.end(), 0.0);
    for (int k = 0; k < ky; ++k) {
      const double g = gy[size_t(k)];
      const double* s = ring.data() + size_t((y - (ky - 1) + k) % ky) * 5 * out_w;
      for (size_t i = 0; i < 5 * out_w; ++i) col[i] += g * s[i];
    }
    const double* ma = col.data();
    const double* mb = ma + out_w;
    const double* maa = mb + out_w;
    const double* mbb = maa + out_w;
    const double* mab = mbb + out_w;
    double row_sum = 0.0;
    for (size_t x = 0; x < out_w; ++x) {
      const double va = maa[x] - ma[x] * ma[x];
      const double vb = mbb[x] - mb[x] * mb[x];
      const double cov = mab[x] - ma[x] * mb[x];
      row_sum += ((2.0 * ma[x] * mb[x] + kC1) * (2.0 * cov + kC2)) /
                 ((ma[x] * ma[x] + mb[x] * mb[x] + kC1) * (va + vb + kC2));
    }
    total += row_sum;
  }
  return total / (double(ow) * double(oh));
}

ImageMetrics compareImages(const ColorImage& a, const ColorImage& b, int threshold) {
  checkSameSize(a, b, "compareImages");
  ImageMetrics m;
  const DiffSums s = diffSums(a, b, threshold);
  const double n = double(a.pixelCount());
  m.psnr_db = psnrFromSums(s, a.pixelCount());
  m.mae = a.empty() ? 0.0 : double(s.absolute) / (3.0 * n);
  m.bad_pixel_share = a.empty() ? 0.0 : double(s.over) / n;
  m.ssim = ssim(a, b);
  return m;
}

ColorImage diffHeatmap(const ColorImage& a, const ColorImage& b, int full_scale) {
  checkSameSize(a, b, "diffHeatmap");
  if (full_scale <= 0)
    throw Error("diffHeatmap", "full scale must be a positive 8-bit difference, got " + std::to_string(full_scale));
  // Ramp stops at 0, 1/4, 1/2, 3/4 and 1 of the full scale: black, blue, red, yellow, white. Brightness rises
  // along the ramp, so small errors stay dark and large ones stand out. Only 256 differences exist: tabulate.
  static constexpr std::array<glm::dvec3, 5> kStops = {glm::dvec3(0, 0, 0), glm::dvec3(0, 0, 255),
                                                       glm::dvec3(255, 0, 0), glm::dvec3(255, 255, 0),
                                                       glm::dvec3(255, 255, 255)};
  std::array<Rgba8, 256> lut;
  for (int d = 0; d < 256; ++d) {
    const double t = std::min(1.0, double(d) / double(full_scale)) * 4.0;
    const int i = std::min(3, int(t));
    const glm::dvec3 c = glm::mix(kStops[size_t(i)], kStops[size_t(i) + 1], t - i);
    lut[size_t(d)] = Rgba8(uint8_t(std::lround(c.r)), uint8_t(std::lround(c.g)), uint8_t(std::lround(c.b)), 255);
  }
  ColorImage out(a.width(), a.height());
  const Rgba8* pa = a.data();
  const Rgba8* pb = b.data();
  Rgba8* po = out.data();
  for (size_t i = 0; i < a.pixelCount(); ++i) {
    const int dr = std::abs(int(pa[i].r) - int(pb[i].r));
    const int dg = std::abs(int(pa[i].g) - int(pb[i].g));
    const int db = std::abs(int(pa[i].b) - int(pb[i].b));
    po[i] = lut[size_t(std::max(dr, std::max(dg, db)))];
  }
  return out;
}

}  // namespace farfield::image
