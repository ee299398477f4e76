#!/usr/bin/env python3
"""Writes building.png and building.yaml: the yard around one large building, a
ROS map_server map (0.1 m cells) for the CPS-VIII-like campaign of
experiments/cps-viii.toml. Standard library only; the output is deterministic.

The yard is 100 m x 70 m inside a fence. The building (an L: a 48 m x 24 m hall
with a 16 m x 14 m wing) stands in its middle; parked cars, trees and a
container stand around it, as around a real survey object.
"""
import struct
import zlib
from pathlib import Path

RES = 0.1
W, H = 1000, 700  # cells
FREE, OCC = 254, 0

img = [[FREE] * W for _ in range(H)]


def rect(x0, y0, x1, y1):
    """Fills [x0, x1) x [y0, y1) metres (y up) with obstacle."""
    for y in range(int(y0 / RES), int(y1 / RES)):
        for x in range(int(x0 / RES), int(x1 / RES)):
            img[H - 1 - y][x] = OCC


def disc(cx, cy, r):
    for y in range(int((cy - r) / RES), int((cy + r) / RES) + 1):
        for x in range(int((cx - r) / RES), int((cx + r) / RES) + 1):
            if ((x + 0.5) * RES - cx) ** 2 + ((y + 0.5) * RES - cy) ** 2 <= r * r:
                img[H - 1 - y][x] = OCC


# Fence.
rect(0, 0, 100, 0.3)
rect(0, 69.7, 100, 70)
rect(0, 0, 0.3, 70)
rect(99.7, 0, 100, 70)
# The building: hall and wing.
rect(26, 23, 74, 47)
rect(58, 47, 74, 61)
# Cars along the south side, a container to the west, trees to the north.
for x in (30, 36, 42, 48):
    rect(x, 12, x + 1.9, 16.5)
rect(8, 30, 10.5, 42)
for x, y in ((20, 56), (30, 60), (40, 57), (85, 20), (88, 50)):
    disc(x, y, 0.6)


def png(rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(kind, data):
        c = kind + data
        return struct.pack(">I", len(data)) + c + struct.pack(">I", zlib.crc32(c))

    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 0, 0, 0, 0))
        + chunk(b"IDAT", zlib.compress(raw, 9))
        + chunk(b"IEND", b"")
    )


here = Path(__file__).resolve().parent
(here / "building.png").write_bytes(png(img))
(here / "building.yaml").write_text(
    "image: building.png\n"
    f"resolution: {RES}\n"
    "origin: [0.0, 0.0, 0.0]\n"
    "negate: 0\n"
    "occupied_thresh: 0.65\n"
    "free_thresh: 0.196\n"
)
