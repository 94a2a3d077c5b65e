#!/usr/bin/env python3
"""Writes the small PNG/PFM files used by tests/image/test_png_io.cpp, without libpng (plain zlib + struct), so
the reader is checked against an independent encoder. Pixel values follow the formulas repeated in the test:
  v(x, y) = (x * 30 + y * 7) % 256,  a(x, y) = (x * 20 + y * 40 + 5) % 256
Run from this directory: python3 make_test_images.py"""
import struct
import zlib

W, H = 9, 7


def v(x, y):
    return (x * 30 + y * 7) % 256


def a(x, y):
    return (x * 20 + y * 40 + 5) % 256


def chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)


def png(path, color_type, bit_depth, rows, extra=b"", interlace=0):
    """rows: list of packed scanline bytes (without filter byte), or for interlace=1 a function
    (x, y) -> pixel bytes for bit depths >= 8."""
    ihdr = struct.pack(">IIBBBBB", W, H, bit_depth, color_type, 0, 0, interlace)
    raw = bytearray()
    if interlace == 0:
        for i, r in enumerate(rows):
            # Alternate filters 0 (none) and 1 (sub) to exercise the decoder's unfiltering.
            if i % 2 == 0:
                raw += b"\x00" + r
            else:
                bpp = max(1, bit_depth * {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[color_type] // 8)
                out = bytearray(r)
                for k in range(len(r) - 1, bpp - 1, -1):
                    out[k] = (r[k] - r[k - bpp]) % 256
                raw += b"\x01" + bytes(out)
    else:
        passes = [(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]
        for x0, y0, dx, dy in passes:
            xs = list(range(x0, W, dx))
            if not xs:
                continue
            for y in range(y0, H, dy):
                raw += b"\x00" + b"".join(rows(x, y) for x in xs)
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + extra + chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(data)
    return data


def pack(values, bits):
    out = bytearray()
    acc, n = 0, 0
    for val in values:
        acc = (acc << bits) | val
        n += bits
        while n >= 8:
            n -= 8
            out.append((acc >> n) & 0xFF)
    if n:
        out.append((acc << (8 - n)) & 0xFF)
    return bytes(out)


png("grey8.png", 0, 8, [bytes(v(x, y) for x in range(W)) for y in range(H)])
png("grey16.png", 0, 16, [b"".join(struct.pack(">H", v(x, y) * 257) for x in range(W)) for y in range(H)])
png("grey_alpha8.png", 4, 8, [bytes(c for x in range(W) for c in (v(x, y), a(x, y))) for y in range(H)])
png("grey_alpha16.png", 4, 16,
    [b"".join(struct.pack(">HH", v(x, y) * 257, a(x, y) * 257) for x in range(W)) for y in range(H)])
# grey with a tRNS key: value 37 is transparent (v hits 37 at x = 1, y = 1).
png("grey8_trns.png", 0, 8, [bytes(v(x, y) for x in range(W)) for y in range(H)], chunk(b"tRNS", struct.pack(">H", 37)))
# 1-bit grey: bit = (x + y) % 2, decoded to 0 or 255.
png("grey1.png", 0, 1, [pack([(x + y) % 2 for x in range(W)], 1) for y in range(H)])
png("rgb8.png", 2, 8, [bytes(c for x in range(W) for c in (v(x, y), a(x, y), 255 - v(x, y))) for y in range(H)])
png("rgb16.png", 2, 16,
    [b"".join(struct.pack(">HHH", v(x, y) * 257, a(x, y) * 257, (255 - v(x, y)) * 257) for x in range(W))
     for y in range(H)])
png("rgba8.png", 6, 8,
    [bytes(c for x in range(W) for c in (v(x, y), a(x, y), 255 - v(x, y), a(x, y))) for y in range(H)])
# 4-bit palette of 16 entries: entry i = (16 i, 255 - 16 i, 7 i), alpha 17 i for the first 8 entries (tRNS),
# opaque after; pixel index = (x + 2 y) % 16.
palette = b"".join(bytes((16 * i, 255 - 16 * i, 7 * i)) for i in range(16))
trns = bytes(17 * i for i in range(8))
png("palette4.png", 3, 4, [pack([(x + 2 * y) % 16 for x in range(W)], 4) for y in range(H)],
    chunk(b"PLTE", palette) + chunk(b"tRNS", trns))
# Adam7-interlaced RGB.
png("rgb8_interlaced.png", 2, 8, lambda x, y: bytes((v(x, y), a(x, y), 255 - v(x, y))), interlace=1)

# Broken files: a valid PNG cut in the middle of its image data, and bytes that are not a PNG at all.
full = open("rgb8.png", "rb").read()
with open("truncated.png", "wb") as f:
    f.write(full[: len(full) - 30])
with open("garbage.png", "wb") as f:
    f.write(b"this is not an image, just some text pretending to be one\n" * 3)
# A PNG header claiming 30000 x 30000 pixels followed by almost no data.
ihdr = struct.pack(">IIBBBBB", 30000, 30000, 8, 6, 0, 0, 0)
with open("huge_header.png", "wb") as f:
    f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\x00" * 100)) + chunk(b"IEND", b""))

# PFM written by hand: 3 x 2, little-endian, bottom row first. Top row 1 2 3, bottom row 4 5 6.
with open("small.pfm", "wb") as f:
    f.write(b"Pf\n3 2\n-1.0\n" + struct.pack("<6f", 4, 5, 6, 1, 2, 3))
# The same image big-endian (positive scale).
with open("small_be.pfm", "wb") as f:
    f.write(b"Pf\n3 2\n1.0\n" + struct.pack(">6f", 4, 5, 6, 1, 2, 3))
with open("truncated.pfm", "wb") as f:
    f.write(b"Pf\n3 2\n-1.0\n" + struct.pack("<5f", 4, 5, 6, 1, 2))
with open("bad_header.pfm", "wb") as f:
    f.write(b"Pf\n3 -2\n-1.0\n" + struct.pack("<6f", 4, 5, 6, 1, 2, 3))
