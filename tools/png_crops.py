#!/usr/bin/env python3
"""Side-by-side crops of PNG frames, magnified, for docs/BENCHMARKS.md's pictures (no imaging library needed).

Usage: tools/png_crops.py OUT.png X Y W H SCALE A.png [B.png ...]
Each input's W x H region at (X, Y) (pixels from the top left) is magnified SCALE times (nearest texel) and the
crops are laid left to right with a 4-pixel white gap. Reads 8-bit greyscale, RGB and RGBA PNGs, not interlaced.
"""
import struct
import sys
import zlib


def read_png(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            channels = {0: 1, 2: 3, 6: 4}.get(colour)
            if depth != 8 or channels is None or interlace:
                sys.exit(f"{path}: only 8-bit grey, RGB or RGBA, not interlaced (depth {depth}, colour {colour})")
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * channels:x * channels + 3]) if channels >= 3 else (line[x],) * 3
                     for x in range(width)])
        prev = line
    return rows


def write_png(path, rows):
    height, width = len(rows), len(rows[0])
    raw = b"".join(b"\x00" + bytes(v for px in row for v in px) for row in rows)
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    if len(sys.argv) < 8:
        sys.exit(__doc__)
    out = sys.argv[1]
    x, y, w, h, scale = (int(v) for v in sys.argv[2:7])
    crops = []
    for path in sys.argv[7:]:
        rows = read_png(path)
        if y + h > len(rows) or x + w > len(rows[0]) or x < 0 or y < 0:
            sys.exit(f"{path}: the region {w}x{h} at ({x}, {y}) is outside its {len(rows[0])}x{len(rows)} pixels")
        crops.append([[rows[y + j // scale][x + i // scale] for i in range(w * scale)] for j in range(h * scale)])
    gap = [(255, 255, 255)] * 4
    out_rows = []
    for j in range(h * scale):
        row = []
        for k, c in enumerate(crops):
            row += (gap if k else []) + c[j]
        out_rows.append(row)
    write_png(out, out_rows)


if __name__ == "__main__":
    main()
