#!/usr/bin/env python3
"""Checks a `dominoes --screenshot FILE` image against FILE.json, the rows'
state the example wrote when it took it: the image is not blank, and along
each row's scan line (85 % of a block's height) the number of runs of the
upright colour equals the number of upright blocks; toppled blocks show in
their row's colour exactly when the row has some. Standard library only (PNG
decoded with zlib)."""
import json
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, width = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), f"unsupported PNG {depth}/{colour}"
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
        rows.append(line)
        prev = line
    return width, height, channels, rows


def near(px, rgb, tol=40):
    return all(abs(px[k] - rgb[k]) <= tol for k in range(3))


def main(path):
    state = json.load(open(path + ".json"))
    width, height, ch, rows = read_png(path)
    assert (width, height) == (state["width"], state["height"]), (width, height)
    pixel = lambda x, y: rows[y][x * ch:x * ch + 3]
    colours = {tuple(pixel(x, y)) for y in range(0, height, 8) for x in range(0, width, 8)}
    assert len(colours) > 3, f"blank image ({len(colours)} colours)"
    failures = []
    for row in state["rows"]:
        y = int(row["scan_y"])
        runs, inside = 0, False
        for x in range(int(row["x_min"]), int(row["x_max"]) + 1):
            on = near(pixel(x, y), state["upright_rgb"])
            runs += on and not inside
            inside = on
        toppled_px = sum(
            near(pixel(x, yy), row["toppled_rgb"])
            for yy in range(int(row["band_top"]), int(row["band_bottom"]) + 1)
            for x in range(int(row["x_min"]), int(row["x_max"]) + 1, 2)
        )
        print(f"{row['row']}: upright blocks {row['upright']} (runs on the scan line {runs}), "
              f"toppled {row['toppled']} ({toppled_px} pixels of its colour)")
        if runs != row["upright"]:
            failures.append(f"{row['row']}: {runs} upright runs, expected {row['upright']}")
        if (toppled_px > 0) != (row["toppled"] > 0):
            failures.append(f"{row['row']}: toppled colour {toppled_px} px, toppled blocks {row['toppled']}")
    if failures:
        sys.exit("screenshot check failed: " + "; ".join(failures))
    print("screenshot check passed")


if __name__ == "__main__":
    main(sys.argv[1])
