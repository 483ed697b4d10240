#!/usr/bin/env python3
"""Writes texels-4x2.png, the 4×2 8-bit sRGB test image of radiant-textures'
tests (standard library only). Top row first."""
import struct, zlib

TEXELS = [
    [(0, 0, 0), (255, 255, 255), (128, 64, 32), (10, 200, 30)],
    [(255, 0, 0), (0, 255, 0), (0, 0, 255), (50, 100, 150)],
]

def chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in TEXELS)
png = (b"\x89PNG\r\n\x1a\n"
       + chunk(b"IHDR", struct.pack(">IIBBBBB", 4, 2, 8, 2, 0, 0, 0))
       + chunk(b"IDAT", zlib.compress(raw, 9))
       + chunk(b"IEND", b""))
open(__file__.replace("make_texels_png.py", "texels-4x2.png"), "wb").write(png)
