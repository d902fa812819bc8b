#!/usr/bin/env python3
"""Writes the examples' textures (crate.png, domino.png) next to this file.
Standard library only; run it again after changing a drawing."""
import math
import os
import struct
import zlib


def png(path, w, h, pixel):
    """A w×h RGBA PNG whose pixel (x, y) (y down) is pixel(x, y) -> (r, g, b, a)."""
    raw = bytearray()
    for y in range(h):
        raw.append(0)
        for x in range(w):
            raw.extend(bytes(max(0, min(255, int(round(c)))) for c in pixel(x, y)))
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xffffffff)
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
    data += chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(data)


def crate(x, y, n=64):
    """A wooden crate: planks with grain, a darker frame and a diagonal brace."""
    u, v = (x + 0.5) / n, (y + 0.5) / n
    plank = int(v * 4)
    grain = 0.5 + 0.5 * math.sin(40 * u + 3 * plank + 2 * math.sin(9 * v + plank))
    base = (176 + 30 * grain, 124 + 22 * grain, 70 + 14 * grain)
    seam = abs(v * 4 - round(v * 4)) < 0.04
    frame = min(u, v, 1 - u, 1 - v) < 0.1
    brace = abs(u - v) < 0.07
    k = 0.62 if frame or brace else (0.8 if seam else 1.0)
    return (base[0] * k, base[1] * k, base[2] * k, 255)


def domino(x, y, w=64, h=128):
    """A domino face (white: tinted by the sprite): a dark divider and pips."""
    u, v = (x + 0.5) / w, (y + 0.5) / h
    edge = min(u, v, 1 - u, 1 - v) < 0.045
    if edge:
        return (150, 150, 150, 255)
    if abs(v - 0.5) < 0.012:
        return (40, 40, 40, 255)
    pips = [(0.3, 0.15), (0.7, 0.35), (0.5, 0.25), (0.3, 0.65), (0.7, 0.65), (0.3, 0.85), (0.7, 0.85)]
    for px, py in pips:
        if math.hypot((u - px) * w, (v - py) * h) < 0.075 * w:
            return (40, 40, 40, 255)
    return (255, 255, 255, 255)


def brick(x, y):
    """A domino lying flat: the face turned a quarter."""
    return domino(y, 127 - x)


here = os.path.dirname(os.path.abspath(__file__))
png(os.path.join(here, "crate.png"), 64, 64, crate)
png(os.path.join(here, "domino.png"), 64, 128, domino)
png(os.path.join(here, "domino_flat.png"), 128, 64, brick)
