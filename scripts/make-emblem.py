#!/usr/bin/env python3
"""Writes assets/scenes/emblem.png, the bundled image profile's mask: a five-pointed star in a
ring, dark on a transparent ground, 256 x 256 grey and alpha, antialiased by 4 x 4 samples a
pixel. Only the standard library (zlib), so that the picture can be made again anywhere.
Usage: python3 scripts/make-emblem.py [OUTPUT]"""
import math
import os
import struct
import sys
import zlib

N = 256


def inside(x, y):
    """Whether (x, y), in [-1, 1] with y up, is ink: the ring, or the star within it."""
    r = math.hypot(x, y)
    if 0.80 <= r <= 0.95:
        return True
    # A star of five points: the angle folded into one point's half sector, then the edge from
    # the point (radius 0.72) to the notch (radius 0.30) between two points.
    a = (math.atan2(x, y) + math.pi / 5) % (2 * math.pi / 5) - math.pi / 5
    px, py = r * math.sin(abs(a)), r * math.cos(a)
    ax, ay = 0.0, 0.72
    bx, by = 0.30 * math.sin(math.pi / 5), 0.30 * math.cos(math.pi / 5)
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax) <= 0.0


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "assets", "scenes", "emblem.png")
    rows = bytearray()
    for j in range(N):
        rows.append(0)  # filter: none
        for i in range(N):
            hits = sum(inside((2 * (i + (u + 0.5) / 4) / N - 1), 1 - 2 * (j + (v + 0.5) / 4) / N)
                       for u in range(4) for v in range(4))
            rows += bytes((0, round(255 * hits / 16)))  # black, its coverage as alpha

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", N, N, 8, 4, 0, 0, 0)) +
           chunk(b"IDAT", zlib.compress(bytes(rows), 9)) + chunk(b"IEND", b""))
    with open(out, "wb") as f:
        f.write(png)


if __name__ == "__main__":
    main()
