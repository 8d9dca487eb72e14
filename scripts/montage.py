#!/usr/bin/env python3
"""Crops the same rectangle from several PPM images (synthvis render -o x.ppm), scales each by an
integer factor (nearest neighbour) and writes them side by side, 4 px apart, as one PNG — the
comparison pictures of docs/quality.md.

    scripts/montage.py OUT.png X Y W H SCALE IMAGE.ppm...
"""
import struct
import sys
import zlib


def read_ppm(path):
    with open(path, "rb") as f:
        data = f.read()
    fields, pos = [], 0
    while len(fields) < 4:  # magic, width, height, maxval; '#' comments skipped
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    if fields[0] != b"P6" or fields[3] != b"255":
        sys.exit(f"montage: {path}: not an 8-bit binary PPM")
    w, h = int(fields[1]), int(fields[2])
    return w, h, data[pos + 1:pos + 1 + w * h * 3]


def write_png(path, w, h, rgb):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    raw = b"".join(b"\x00" + rgb[y * w * 3:(y + 1) * w * 3] for y in range(h))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    if len(sys.argv) < 8:
        sys.exit(__doc__)
    out = sys.argv[1]
    x, y, cw, ch, k = (int(v) for v in sys.argv[2:7])
    images = [read_ppm(p) for p in sys.argv[7:]]
    gap = 4
    W = len(images) * cw * k + (len(images) - 1) * gap
    H = ch * k
    canvas = bytearray(b"\xff" * (W * H * 3))
    for i, (w, h, rgb) in enumerate(images):
        if x + cw > w or y + ch > h:
            sys.exit(f"montage: the crop does not fit image {i + 1} ({w}x{h})")
        ox = i * (cw * k + gap)
        for yy in range(H):
            src = (y + yy // k) * w
            row = canvas[yy * W * 3:]
            for xx in range(cw * k):
                s = (src + x + xx // k) * 3
                d = (ox + xx) * 3
                row[d:d + 3] = rgb[s:s + 3]
            canvas[yy * W * 3:(yy + 1) * W * 3] = row[:W * 3]
    write_png(out, W, H, bytes(canvas))


if __name__ == "__main__":
    main()
