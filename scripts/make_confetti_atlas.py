#!/usr/bin/env python3
"""samples/images/confetti.png: a 2 × 2 flip-book of white shapes on transparency (a
square, a triangle, a disc, a five-pointed star; 32 × 32 pixels each), antialiased, for
samples/confetti.psys. Only the standard library: zlib and struct write the PNG.

    python3 scripts/make_confetti_atlas.py"""
import math, struct, zlib, os

TILE = 32
def inside(shape, x, y):
    # x, y in [-1, 1]
    if shape == 0: return abs(x) < 0.7 and abs(y) < 0.7
    if shape == 1: return y > -0.65 and abs(x) < (0.75 - y) * 0.62 and y < 0.8
    if shape == 2: return x * x + y * y < 0.75 * 0.75
    r = math.hypot(x, y); a = math.atan2(y, x) + math.pi / 2
    k = (a % (2 * math.pi / 5)) / (2 * math.pi / 5)
    edge = 0.38 + (0.85 - 0.38) * abs(1 - 2 * k)
    return r < edge

rows = []
for py in range(2 * TILE):
    row = bytearray([0])
    for px in range(2 * TILE):
        shape = (py // TILE) * 2 + (px // TILE)
        cover = 0
        for sy in range(4):
            for sx in range(4):
                x = ((px % TILE) + (sx + 0.5) / 4) / TILE * 2 - 1
                y = 1 - ((py % TILE) + (sy + 0.5) / 4) / TILE * 2
                cover += inside(shape, x, y)
        row += bytes([255, 255, 255, int(255 * cover / 16)])
    rows.append(bytes(row))
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2 * TILE, 2 * TILE, 8, 6, 0, 0, 0))
png += chunk(b"IDAT", zlib.compress(b"".join(rows), 9)) + chunk(b"IEND", b"")
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "samples", "images", "confetti.png")
open(out, "wb").write(png)
print(os.path.normpath(out))
