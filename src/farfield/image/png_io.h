// PNG and PFM input/output. Errors (missing, truncated or corrupt file) raise farfield::Error naming the file.
#pragma once

#include <string>

#include "farfield/image/image.h"

namespace farfield::image {

// Reads 8- or 16-bit grey, grey+alpha, RGB, RGBA or palette PNGs into RGBA8 (16-bit is reduced to 8).
ColorImage readPng(const std::string& path);
void writePng(const std::string& path, const ColorImage& image);

// Single-channel float image as PFM ("Pf", little-endian, rows stored bottom to top as the format says).
void writePfm(const std::string& path, const DepthImage& image);
DepthImage readPfm(const std::string& path);

// Object ids as a false-colour PNG: each id gets a distinct, stable colour; 0 (background) is black.
void writeIdPng(const std::string& path, const IdImage& ids);
Rgba8 idColor(uint32_t id);

}  // namespace farfield::image
