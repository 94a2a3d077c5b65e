#include "farfield/image/png_io.h"

#include <png.h>

#include <bit>
#include <cctype>
#include <cerrno>
#include <csetjmp>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::image {

namespace {

// libpng reports errors through a callback that must not return. We longjmp back to the setjmp in the function
// that drives libpng and turn the message into a farfield::Error there. longjmp must not skip C++ destructors,
// so every piece of state that libpng calls touch lives in a struct owned by the caller (not an automatic object
// of the setjmp function), and the functions between setjmp and the libpng calls hold no objects with
// destructors.
struct PngErrorState {
  char message[256] = "unknown libpng error";
};

void pngErrorFn(png_structp png, png_const_charp msg) {
  auto* state = static_cast<PngErrorState*>(png_get_error_ptr(png));
  if (state) {
    std::snprintf(state->message, sizeof(state->message), "%s", msg ? msg : "libpng error");
  }
  png_longjmp(png, 1);
}

// Warnings (e.g. about ancillary chunks such as colour profiles) do not affect the pixels Farfield reads.
void pngWarningFn(png_structp, png_const_charp) {}

// In-memory source: reading the whole file first makes truncation an ordinary "ran out of bytes" error raised
// inside the read callback, and lets the header sanity checks see the file size.
struct MemorySource {
  const unsigned char* data = nullptr;
  size_t size = 0;
  size_t pos = 0;
};

void pngReadFn(png_structp png, png_bytep out, png_size_t length) {
  auto* src = static_cast<MemorySource*>(png_get_io_ptr(png));
  if (length > src->size - src->pos) png_error(png, "file is truncated (unexpected end of data)");
  std::memcpy(out, src->data + src->pos, length);
  src->pos += length;
}

struct ReadJob {
  PngErrorState err;
  MemorySource src;
  // Results.
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  unsigned char* pixels = nullptr;  // width * height * 4 bytes, owned by the caller
  std::vector<png_bytep>* rows = nullptr;
  bool header_only = false;
  const char* fail_reason = nullptr;  // non-libpng failure found while decoding the header
};

// Deflate cannot expand data by more than about 1032:1; an image whose raw size exceeds that bound for the file's
// size is corrupt or truncated, and rejecting it early avoids allocating gigabytes for a garbage header.
constexpr double kMaxDeflateRatio = 1100.0;
constexpr png_uint_32 kMaxSide = 1u << 15;

// Pass 1 (header_only) decodes the header and sets up the transforms; pass 2 reads the rows. Both run between
// setjmp and the libpng calls. Returns false when libpng reported an error (message in job->err).
bool runRead(ReadJob* job, png_structp png, png_infop info) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_read_fn(png, &job->src, pngReadFn);
  png_set_user_limits(png, kMaxSide, kMaxSide);
  png_read_info(png, info);

  job->width = png_get_image_width(png, info);
  job->height = png_get_image_height(png, info);
  const int bit_depth = png_get_bit_depth(png, info);
  const int color_type = png_get_color_type(png, info);
  const int channels = png_get_channels(png, info);
  const double raw_bytes =
      double(job->height) * (1.0 + std::ceil(double(job->width) * bit_depth * channels / 8.0));
  if (raw_bytes > kMaxDeflateRatio * double(job->src.size) + 4096.0) {
    job->fail_reason = "image data is far too short for the size in the header (truncated or corrupt)";
    return true;
  }

  // Everything becomes 8-bit RGBA: palette and low-bit grey expand, tRNS becomes alpha, 16 bits scale down,
  // grey replicates to RGB, and an opaque alpha is added where there is none.
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (color_type == PNG_COLOR_TYPE_GRAY && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
  if (bit_depth == 16) png_set_scale_16(png);
  if (color_type == PNG_COLOR_TYPE_GRAY || color_type == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
  if (!(color_type & PNG_COLOR_MASK_ALPHA) && !png_get_valid(png, info, PNG_INFO_tRNS))
    png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != size_t(job->width) * 4) {
    job->fail_reason = "unsupported pixel layout after conversion to RGBA8";
    return true;
  }
  return true;
}

bool runReadRows(ReadJob* job, png_structp png, png_infop info) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, job->rows->data());
  png_read_end(png, nullptr);
  (void)info;
  return true;
}

struct WriteJob {
  PngErrorState err;
  std::FILE* file = nullptr;
  const unsigned char* pixels = nullptr;
  int width = 0;
  int height = 0;
  std::vector<png_bytep>* rows = nullptr;
};

bool runWrite(WriteJob* job, png_structp png, png_infop info) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_init_io(png, job->file);
  png_set_IHDR(png, info, png_uint_32(job->width), png_uint_32(job->height), 8, PNG_COLOR_TYPE_RGBA,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // Frames are written often (benchmarks, debugging); a moderate level keeps most of the size gain of the
  // default at a fraction of its time.
  png_set_compression_level(png, 4);
  png_write_info(png, info);
  png_write_image(png, job->rows->data());
  png_write_end(png, nullptr);
  return true;
}

std::vector<unsigned char> readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, std::string("cannot open file: ") + std::strerror(errno));
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(path, "read error");
  return bytes;
}

}  // namespace

ColorImage readPng(const std::string& path) {
  const std::vector<unsigned char> bytes = readWholeFile(path);
  if (bytes.size() < 8 || png_sig_cmp(bytes.data(), 0, 8) != 0)
    throw Error(path, "not a PNG file (missing PNG signature)");

  ReadJob job;
  job.src = {bytes.data(), bytes.size(), 0};
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &job.err, pngErrorFn, pngWarningFn);
  if (!png) throw Error(path, "cannot initialise libpng");
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    throw Error(path, "cannot initialise libpng");
  }
  auto fail = [&](const std::string& what) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw Error(path, what);
  };

  if (!runRead(&job, png, info)) fail("invalid PNG: " + std::string(job.err.message));
  if (job.fail_reason) fail(job.fail_reason);

  ColorImage image;
  std::vector<png_bytep> rows;
  try {
    image = ColorImage(int(job.width), int(job.height));
    rows.resize(job.height);
  } catch (const std::bad_alloc&) {
    fail("not enough memory for a " + std::to_string(job.width) + "x" + std::to_string(job.height) + " image");
  }
  static_assert(sizeof(Rgba8) == 4);
  for (png_uint_32 y = 0; y < job.height; ++y)
    rows[y] = reinterpret_cast<png_bytep>(image.data() + size_t(y) * job.width);
  job.rows = &rows;
  if (!runReadRows(&job, png, info)) fail("invalid PNG: " + std::string(job.err.message));
  png_destroy_read_struct(&png, &info, nullptr);
  return image;
}

void writePng(const std::string& path, const ColorImage& image) {
  if (image.empty()) throw Error(path, "cannot write an empty image as PNG");
  WriteJob job;
  job.file = std::fopen(path.c_str(), "wb");
  if (!job.file) throw Error(path, std::string("cannot open for writing: ") + std::strerror(errno));
  std::vector<png_bytep> rows(size_t(image.height()));
  for (int y = 0; y < image.height(); ++y)
    rows[size_t(y)] = const_cast<png_bytep>(reinterpret_cast<const unsigned char*>(image.data()) +
                                            size_t(y) * size_t(image.width()) * 4);
  job.rows = &rows;
  job.width = image.width();
  job.height = image.height();

  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &job.err, pngErrorFn, pngWarningFn);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  const bool ok = png && info && runWrite(&job, png, info);
  if (png) png_destroy_write_struct(&png, info ? &info : nullptr);
  const bool io_ok = std::ferror(job.file) == 0;
  const bool close_ok = std::fclose(job.file) == 0;
  if (!ok) throw Error(path, std::string("cannot write PNG: ") + job.err.message);
  if (!io_ok || !close_ok) throw Error(path, "write error (disk full?)");
}

// ---- PFM ----------------------------------------------------------------------------------------------------

namespace {

// Reads one whitespace-delimited header token starting at pos.
bool headerToken(const std::vector<unsigned char>& bytes, size_t& pos, std::string& token) {
  while (pos < bytes.size() && std::isspace(bytes[pos])) ++pos;
  token.clear();
  while (pos < bytes.size() && !std::isspace(bytes[pos]) && token.size() < 64) token.push_back(char(bytes[pos++]));
  return !token.empty();
}

bool parseInt(const std::string& s, long& out) {
  if (s.empty() || s.size() > 9) return false;
  out = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    out = out * 10 + (c - '0');
  }
  return true;
}

uint32_t byteSwap32(uint32_t v) {
  return (v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24);
}

}  // namespace

void writePfm(const std::string& path, const DepthImage& image) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) throw Error(path, std::string("cannot open for writing: ") + std::strerror(errno));
  // Negative scale = little-endian samples.
  std::fprintf(file, "Pf\n%d %d\n-1.0\n", image.width(), image.height());
  std::vector<float> row(size_t(image.width()));
  for (int y = image.height() - 1; y >= 0; --y) {  // PFM stores the bottom row first
    const float* src = image.data() + size_t(y) * size_t(image.width());
    if constexpr (std::endian::native == std::endian::little) {
      std::fwrite(src, sizeof(float), row.size(), file);
    } else {
      for (size_t x = 0; x < row.size(); ++x) {
        uint32_t bits = byteSwap32(std::bit_cast<uint32_t>(src[x]));
        row[x] = std::bit_cast<float>(bits);
      }
      std::fwrite(row.data(), sizeof(float), row.size(), file);
    }
  }
  const bool io_ok = std::ferror(file) == 0;
  if (std::fclose(file) != 0 || !io_ok) throw Error(path, "write error (disk full?)");
}

DepthImage readPfm(const std::string& path) {
  const std::vector<unsigned char> bytes = readWholeFile(path);
  size_t pos = 0;
  std::string token;
  if (!headerToken(bytes, pos, token) || token != "Pf") {
    if (token == "PF") throw Error(path, "colour PFM ('PF') found; expected single-channel 'Pf'");
    throw Error(path, "not a single-channel PFM file (expected 'Pf' header)");
  }
  long width = 0, height = 0;
  if (!headerToken(bytes, pos, token) || !parseInt(token, width) || width <= 0 || width > long(kMaxSide))
    throw Error(path, "PFM header: bad width '" + token + "' (expected 1.." + std::to_string(kMaxSide) + ")");
  if (!headerToken(bytes, pos, token) || !parseInt(token, height) || height <= 0 || height > long(kMaxSide))
    throw Error(path, "PFM header: bad height '" + token + "' (expected 1.." + std::to_string(kMaxSide) + ")");
  if (!headerToken(bytes, pos, token)) throw Error(path, "PFM header: missing scale");
  char* end = nullptr;
  const double scale = std::strtod(token.c_str(), &end);
  if (end != token.c_str() + token.size() || scale == 0.0 || !std::isfinite(scale))
    throw Error(path, "PFM header: bad scale '" + token + "' (expected a non-zero number)");
  // Exactly one whitespace character separates the header from the samples.
  if (pos >= bytes.size() || !std::isspace(bytes[pos])) throw Error(path, "PFM header: missing end of header");
  ++pos;
  const bool little = scale < 0.0;
  const size_t count = size_t(width) * size_t(height);
  const size_t needed = count * 4;
  if (bytes.size() - pos < needed)
    throw Error(path, "PFM is truncated: expected " + std::to_string(needed) + " bytes of samples for " +
                          std::to_string(width) + "x" + std::to_string(height) + ", found " +
                          std::to_string(bytes.size() - pos));
  DepthImage image(static_cast<int>(width), static_cast<int>(height));
  const bool swap = little != (std::endian::native == std::endian::little);
  for (long row = 0; row < height; ++row) {
    float* dst = image.data() + size_t(height - 1 - row) * size_t(width);
    const unsigned char* src = bytes.data() + pos + size_t(row) * size_t(width) * 4;
    std::memcpy(dst, src, size_t(width) * 4);
    if (swap)
      for (long x = 0; x < width; ++x) dst[x] = std::bit_cast<float>(byteSwap32(std::bit_cast<uint32_t>(dst[x])));
  }
  return image;
}

// ---- ids ------------------------------------------------------------------------------------------------------

Rgba8 idColor(uint32_t id) {
  if (id == 0) return Rgba8(0, 0, 0, 255);
  // A bijective 32-bit mix (xorshift-multiply): neighbouring ids get unrelated colours, and the same id always
  // the same colour. Channels are kept at 40..255 so that no object is mistaken for the black background.
  uint32_t h = id;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  auto channel = [](uint32_t v) { return uint8_t(40 + (v & 0xffu) * 215u / 255u); };
  return Rgba8(channel(h), channel(h >> 8), channel(h >> 16), 255);
}

void writeIdPng(const std::string& path, const IdImage& ids) {
  ColorImage colour(ids.width(), ids.height());
  const uint32_t* src = ids.data();
  Rgba8* dst = colour.data();
  // Ids come in runs (one object covers many neighbouring pixels): reuse the last colour.
  uint32_t last_id = 0;
  Rgba8 last_colour = idColor(0);
  for (size_t i = 0; i < ids.pixelCount(); ++i) {
    if (src[i] != last_id) {
      last_id = src[i];
      last_colour = idColor(last_id);
    }
    dst[i] = last_colour;
  }
  writePng(path, colour);
}

}  // namespace farfield::image
