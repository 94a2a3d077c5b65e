#include "farfield/image/png_io.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <functional>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "support/test_support.h"

using namespace farfield;
using namespace farfield::image;

namespace {

// The formulas tests/data/image/make_test_images.py used to write the files.
int v(int x, int y) { return (x * 30 + y * 7) % 256; }
int a(int x, int y) { return (x * 20 + y * 40 + 5) % 256; }

std::string dataFile(const std::string& name) { return (test::testDataDir() / "image" / name).string(); }

void expectPixels(const ColorImage& img, const std::function<Rgba8(int, int)>& expected, const std::string& what) {
  ASSERT_EQ(img.width(), 9) << what;
  ASSERT_EQ(img.height(), 7) << what;
  for (int y = 0; y < 7; ++y)
    for (int x = 0; x < 9; ++x) {
      Rgba8 e = expected(x, y), g = img.at(x, y);
      ASSERT_EQ(g, e) << what << " at (" << x << "," << y << "): got " << int(g.r) << " " << int(g.g) << " "
                      << int(g.b) << " " << int(g.a) << ", expected " << int(e.r) << " " << int(e.g) << " "
                      << int(e.b) << " " << int(e.a);
    }
}

Rgba8 rgba(int r, int g, int b, int al) { return Rgba8(uint8_t(r), uint8_t(g), uint8_t(b), uint8_t(al)); }

// Expects farfield::Error whose message names the file.
void expectFileError(const std::function<void()>& fn, const std::string& path) {
  try {
    fn();
    ADD_FAILURE() << "no error for " << path;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(std::filesystem::path(path).filename().string()), std::string::npos)
        << e.what();
  }
}

ColorImage randomImage(int w, int h, unsigned seed) {
  std::mt19937 rng(seed);
  ColorImage img(w, h);
  for (Rgba8& p : img.pixels()) p = rgba(rng() & 255, rng() & 255, rng() & 255, rng() & 255);
  return img;
}

}  // namespace

TEST(PngIo, ReadsAllFormatsIntoRgba8) {
  auto grey = [](int x, int y) { return rgba(v(x, y), v(x, y), v(x, y), 255); };
  expectPixels(readPng(dataFile("grey8.png")), grey, "grey8");
  expectPixels(readPng(dataFile("grey16.png")), grey, "grey16");
  auto grey_alpha = [](int x, int y) { return rgba(v(x, y), v(x, y), v(x, y), a(x, y)); };
  expectPixels(readPng(dataFile("grey_alpha8.png")), grey_alpha, "grey_alpha8");
  expectPixels(readPng(dataFile("grey_alpha16.png")), grey_alpha, "grey_alpha16");
  expectPixels(readPng(dataFile("grey8_trns.png")),
               [](int x, int y) { return rgba(v(x, y), v(x, y), v(x, y), v(x, y) == 37 ? 0 : 255); }, "grey8_trns");
  expectPixels(readPng(dataFile("grey1.png")),
               [](int x, int y) {
                 int g = (x + y) % 2 ? 255 : 0;
                 return rgba(g, g, g, 255);
               },
               "grey1");
  auto rgb = [](int x, int y) { return rgba(v(x, y), a(x, y), 255 - v(x, y), 255); };
  expectPixels(readPng(dataFile("rgb8.png")), rgb, "rgb8");
  expectPixels(readPng(dataFile("rgb16.png")), rgb, "rgb16");
  expectPixels(readPng(dataFile("rgb8_interlaced.png")), rgb, "rgb8_interlaced");
  expectPixels(readPng(dataFile("rgba8.png")),
               [](int x, int y) { return rgba(v(x, y), a(x, y), 255 - v(x, y), a(x, y)); }, "rgba8");
  expectPixels(readPng(dataFile("palette4.png")),
               [](int x, int y) {
                 int i = (x + 2 * y) % 16;
                 return rgba(16 * i, 255 - 16 * i, 7 * i, i < 8 ? 17 * i : 255);
               },
               "palette4");
}

TEST(PngIo, WriteReadRoundTrip) {
  auto dir = test::scratchDir("png_round_trip");
  for (auto [w, h] : {std::pair{1, 1}, std::pair{37, 23}, std::pair{256, 3}}) {
    ColorImage img = randomImage(w, h, unsigned(w * 100 + h));
    std::string path = (dir / ("img_" + std::to_string(w) + ".png")).string();
    writePng(path, img);
    ColorImage back = readPng(path);
    ASSERT_EQ(back.width(), w);
    ASSERT_EQ(back.height(), h);
    EXPECT_TRUE(back.pixels() == img.pixels());
  }
  // Row 0 is the top row: the file's first row.
  ColorImage img(2, 2, rgba(0, 0, 0, 255));
  img.at(0, 0) = rgba(255, 0, 0, 255);
  writePng((dir / "top.png").string(), img);
  EXPECT_EQ(readPng((dir / "top.png").string()).at(0, 0), rgba(255, 0, 0, 255));
}

TEST(PngIo, BrokenFilesGiveErrorsNamingTheFile) {
  expectFileError([] { readPng(dataFile("truncated.png")); }, "truncated.png");
  expectFileError([] { readPng(dataFile("garbage.png")); }, "garbage.png");
  expectFileError([] { readPng(dataFile("huge_header.png")); }, "huge_header.png");
  expectFileError([] { readPng(dataFile("does_not_exist.png")); }, "does_not_exist.png");
  expectFileError([] { readPng(dataFile("small.pfm")); }, "small.pfm");  // not a PNG
  auto dir = test::scratchDir("png_errors");
  expectFileError([&] { writePng((dir / "no_such_dir" / "out.png").string(), ColorImage(2, 2)); }, "out.png");
  expectFileError([&] { writePng((dir / "empty.png").string(), ColorImage()); }, "empty.png");
}

TEST(PngIo, EveryTruncationAndCorruptionIsAnError) {
  // A real, compressible image so that the file has a few hundred bytes of image data to cut into.
  auto dir = test::scratchDir("png_truncations");
  ColorImage img(40, 30);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) img.at(x, y) = rgba(x * 6, y * 8, (x * y) % 256, 255);
  std::string full_path = (dir / "full.png").string();
  writePng(full_path, img);
  std::ifstream in(full_path, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 100u);
  std::string cut_path = (dir / "cut.png").string();
  for (size_t len = 0; len < bytes.size(); len += 1 + len / 16) {
    std::ofstream(cut_path, std::ios::binary).write(bytes.data(), std::streamsize(len));
    expectFileError([&] { readPng(cut_path); }, "cut.png");
  }
  // Flipping a byte anywhere after the signature breaks a CRC or the data: an error, never a crash.
  std::mt19937 rng(1);
  int errors = 0;
  for (int i = 0; i < 60; ++i) {
    std::vector<char> bad = bytes;
    size_t at = 8 + rng() % (bytes.size() - 8);
    bad[at] = char(bad[at] ^ (1 + rng() % 255));
    std::ofstream(cut_path, std::ios::binary).write(bad.data(), std::streamsize(bad.size()));
    try {
      readPng(cut_path);
    } catch (const Error&) {
      ++errors;
    }
  }
  EXPECT_GT(errors, 50);  // a flip in an ancillary field may be tolerated; almost all must be caught
}

TEST(PngIo, PfmReadsHandWrittenFiles) {
  for (const char* name : {"small.pfm", "small_be.pfm"}) {
    DepthImage d = readPfm(dataFile(name));
    ASSERT_EQ(d.width(), 3) << name;
    ASSERT_EQ(d.height(), 2) << name;
    // Stored bottom row first: row 0 (top) is 1 2 3.
    EXPECT_EQ(d.at(0, 0), 1.0f);
    EXPECT_EQ(d.at(2, 0), 3.0f);
    EXPECT_EQ(d.at(0, 1), 4.0f);
    EXPECT_EQ(d.at(2, 1), 6.0f);
  }
  expectFileError([] { readPfm(dataFile("truncated.pfm")); }, "truncated.pfm");
  expectFileError([] { readPfm(dataFile("bad_header.pfm")); }, "bad_header.pfm");
  expectFileError([] { readPfm(dataFile("grey8.png")); }, "grey8.png");
  expectFileError([] { readPfm(dataFile("missing.pfm")); }, "missing.pfm");
}

TEST(PngIo, PfmRoundTripAndLayout) {
  auto dir = test::scratchDir("pfm");
  DepthImage d(5, 4);
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-1e6f, 1e6f);
  for (float& f : d.pixels()) f = u(rng);
  d.at(1, 1) = std::numeric_limits<float>::infinity();
  std::string path = (dir / "d.pfm").string();
  writePfm(path, d);
  DepthImage back = readPfm(path);
  ASSERT_EQ(back.width(), 5);
  ASSERT_EQ(back.height(), 4);
  EXPECT_TRUE(back.pixels() == d.pixels());
  // Byte layout checked by hand: header, then the bottom row first, little-endian.
  std::ifstream in(path, std::ios::binary);
  std::string header;
  for (int lines = 0; lines < 3;) {
    char c = char(in.get());
    header.push_back(c);
    if (c == '\n') ++lines;
  }
  EXPECT_EQ(header.substr(0, 7), "Pf\n5 4\n");
  EXPECT_EQ(header[7], '-');
  unsigned char first[4];
  in.read(reinterpret_cast<char*>(first), 4);
  uint32_t bits = uint32_t(first[0]) | uint32_t(first[1]) << 8 | uint32_t(first[2]) << 16 | uint32_t(first[3]) << 24;
  float f;
  std::memcpy(&f, &bits, 4);
  EXPECT_EQ(f, d.at(0, 3));
}

TEST(PngIo, IdColours) {
  EXPECT_EQ(idColor(0), rgba(0, 0, 0, 255));
  std::set<uint32_t> colours;
  for (uint32_t id = 1; id <= 2000; ++id) {
    Rgba8 c = idColor(id);
    EXPECT_EQ(c, idColor(id));  // stable
    EXPECT_EQ(c.a, 255);
    EXPECT_GE(std::max({c.r, c.g, c.b}), 40);  // never black-looking
    colours.insert(uint32_t(c.r) << 16 | uint32_t(c.g) << 8 | c.b);
  }
  EXPECT_GE(colours.size(), 1990u);  // hashing: at most a handful of collisions among 2000 ids
  // Neighbouring ids look different.
  for (uint32_t id = 1; id < 100; ++id) {
    Rgba8 p = idColor(id), q = idColor(id + 1);
    int diff = std::abs(p.r - q.r) + std::abs(p.g - q.g) + std::abs(p.b - q.b);
    EXPECT_GT(diff, 0);
  }
  auto dir = test::scratchDir("ids");
  IdImage ids(3, 2);
  ids.at(0, 0) = 0;
  ids.at(1, 0) = 7;
  ids.at(2, 0) = 7;
  ids.at(0, 1) = 123456;
  std::string path = (dir / "ids.png").string();
  writeIdPng(path, ids);
  ColorImage back = readPng(path);
  EXPECT_EQ(back.at(0, 0), rgba(0, 0, 0, 255));
  EXPECT_EQ(back.at(1, 0), idColor(7));
  EXPECT_EQ(back.at(2, 0), idColor(7));
  EXPECT_EQ(back.at(0, 1), idColor(123456));
  EXPECT_EQ(back.at(1, 1), rgba(0, 0, 0, 255));
}
