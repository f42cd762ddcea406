#!/usr/bin/env python3
"""Writes the bundled images into assets/scenes: emblem.png, the image profile's mask, a
five-pointed star in a ring, dark on a transparent ground, 256 x 256 grey and alpha, antialiased
by 4 x 4 samples a pixel; and terrain.png, the heightmap's heights, hills and a valley in 128 x
128 grey levels. Only the standard library (zlib), so that they can be made again anywhere.
Usage: python3 scripts/make-images.py [FOLDER]"""
import math
import os
import struct
import sys
import zlib

N = 256


def segment_distance(px, py, ax, ay, bx, by):
    dx, dy = bx - ax, by - ay
    t = max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy)))
    return math.hypot(px - ax - t * dx, py - ay - t * dy)


# A star of five points (radius 0.66 at the points, 0.27 at the notches), one point up.
STAR = [((0.66 if k % 2 == 0 else 0.27) * math.sin(k * math.pi / 5),
         (0.66 if k % 2 == 0 else 0.27) * math.cos(k * math.pi / 5)) for k in range(10)]


def in_star(x, y):
    """Even-odd rule over the star's edges."""
    inside = False
    for (ax, ay), (bx, by) in zip(STAR, STAR[1:] + STAR[:1]):
        if (ay > y) != (by > y) and x < ax + (y - ay) * (bx - ax) / (by - ay):
            inside = not inside
    return inside


def inside(x, y):
    """Whether (x, y), in [-1, 1] with y up, is ink: the ring, or the star within it with its
    points rounded (the star grown by 0.05), so that no corner is sharper than a few pixels."""
    r = math.hypot(x, y)
    if 0.80 <= r <= 0.95:
        return True
    if r > 0.75:
        return False
    if in_star(x, y):
        return True
    return min(segment_distance(x, y, *a, *b)
               for a, b in zip(STAR, STAR[1:] + STAR[:1])) <= 0.05


def chunk(kind, data):
    return (struct.pack(">I", len(data)) + kind + data +
            struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))


def png(path, width, height, colour_type, rows):
    """colour_type 0: grey, 4: grey and alpha; rows: the filtered scanlines."""
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" +
                chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(bytes(rows), 9)) + chunk(b"IEND", b""))


def terrain(x, z):
    """Heights from 0 to 1 over [-1, 1]^2: two hills and a ridge, a valley between them."""
    hill = lambda cx, cz, r: math.exp(-((x - cx) ** 2 + (z - cz) ** 2) / (r * r))
    ridge = 0.35 * math.exp(-((x + z - 0.9) ** 2) / 0.08) * (0.6 + 0.4 * math.sin(4 * x))
    h = 0.95 * hill(-0.4, -0.3, 0.45) + 0.7 * hill(0.5, 0.45, 0.35) + ridge
    valley = 0.25 * math.exp(-((x - z) ** 2) / 0.05)
    return min(max(0.12 + 0.8 * h - valley, 0.0), 1.0)


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(__file__), "..", "assets", "scenes")
    rows = bytearray()
    for j in range(N):
        rows.append(0)  # filter: none
        for i in range(N):
            hits = sum(inside((2 * (i + (u + 0.5) / 4) / N - 1), 1 - 2 * (j + (v + 0.5) / 4) / N)
                       for u in range(4) for v in range(4))
            rows += bytes((0, round(255 * hits / 16)))  # black, its coverage as alpha
    png(os.path.join(folder, "emblem.png"), N, N, 4, rows)

    M = 128
    rows = bytearray()
    for j in range(M):
        rows.append(0)
        for i in range(M):
            rows.append(round(255 * terrain(2 * (i + 0.5) / M - 1, 2 * (j + 0.5) / M - 1)))
    png(os.path.join(folder, "terrain.png"), M, M, 0, rows)


if __name__ == "__main__":
    main()
