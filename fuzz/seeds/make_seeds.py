#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets (fuzz/seeds/<target>/).

Run from anywhere: python3 fuzz/seeds/make_seeds.py. Deterministic; the files it
writes are committed. Images are a few pixels; YAMLs are like the ROS map_server
files in /work/shared/maps (text only, no large images).
"""
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def out(target, name, data):
    d = os.path.join(HERE, target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)


# ---------------------------------------------------------------- images
W, H = 8, 6


def room(free=254, occ=0, unk=205):
    """A W x H room: walls around, one unknown pixel, rows from the top."""
    rows = []
    for y in range(H):
        row = []
        for x in range(W):
            if x in (0, W - 1) or y in (0, H - 1):
                row.append(occ)
            elif (x, y) == (W - 2, 1):
                row.append(unk)
            else:
                row.append(free)
        rows.append(row)
    return rows


def p2(rows, maxval=255):
    s = "P2\n# fuzz seed\n%d %d\n%d\n" % (W, H, maxval)
    return (s + "\n".join(" ".join(str(v) for v in r) for r in rows) + "\n").encode()


def p5(rows, maxval=255):
    head = b"P5\n%d %d\n%d\n" % (W, H, maxval)
    if maxval < 256:
        return head + bytes(v for r in rows for v in r)
    return head + b"".join(struct.pack(">H", v) for r in rows for v in r)


def p6(rows):
    head = b"P6\n%d %d\n255\n" % (W, H)
    return head + bytes(c for r in rows for v in r for c in (v, v, v))


def p3(rows):
    s = "P3\n%d %d\n255\n" % (W, H)
    return (s + "\n".join(" ".join("%d %d %d" % (v, v, v) for v in r) for r in rows) + "\n").encode()


def p1(rows):
    s = "P1\n%d %d\n" % (W, H)
    return (s + "\n".join(" ".join("1" if v < 128 else "0" for v in r) for r in rows) + "\n").encode()


def p4(rows):
    head = b"P4\n%d %d\n" % (W, H)
    body = bytes(sum((1 << (7 - i)) for i, v in enumerate(r) if v < 128) for r in rows)
    return head + body


def pam(rows, depth=2, tupltype="GRAYSCALE_ALPHA", maxval=255):
    head = ("P7\nWIDTH %d\nHEIGHT %d\nDEPTH %d\nMAXVAL %d\nTUPLTYPE %s\nENDHDR\n"
            % (W, H, depth, maxval, tupltype)).encode()
    px = []
    for r in rows:
        for v in r:
            px.extend(([v] * min(depth, 3) + [255])[:depth] if depth != 1 else [v])
    return head + bytes(px)


def png(rows, color_type=0, bit_depth=8):
    """color_type 0 gray, 2 RGB, 4 gray+alpha, 6 RGBA; bit depth 8 or 16."""
    chans = {0: 1, 2: 3, 4: 2, 6: 4}[color_type]
    raw = b""
    for r in rows:
        raw += b"\x00"
        for v in r:
            samples = {1: [v], 3: [v, v, v], 2: [v, 255], 4: [v, v, v, 255]}[chans]
            for s in samples:
                raw += struct.pack(">H", s * 257) if bit_depth == 16 else bytes([s])

    def chunk(kind, data):
        c = kind + data
        return struct.pack(">I", len(data)) + c + struct.pack(">I", zlib.crc32(c) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", W, H, bit_depth, color_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw))
            + chunk(b"IEND", b""))


def png_palette(rows):
    pal = bytes([0, 0, 0, 205, 205, 205, 254, 254, 254])
    idx = {0: 0, 205: 1, 254: 2}
    raw = b"".join(b"\x00" + bytes(idx[v] for v in r) for r in rows)

    def chunk(kind, data):
        c = kind + data
        return struct.pack(">I", len(data)) + c + struct.pack(">I", zlib.crc32(c) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", W, H, 8, 3, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"PLTE", pal)
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


# ---------------------------------------------------------------- map_load
def yaml(image, resolution="0.05", origin="[0.0, 0.0, 0.0]", extra=""):
    return ("image: %s\nresolution: %s\norigin: %s\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.196\n%s" % (image, resolution, origin, extra))


def map_seed(name, res_choice, yaml_text, image):
    y = yaml_text.encode()
    out("map_load", name, bytes([res_choice]) + struct.pack("<H", len(y)) + y + image)


ROWS = room()
RAW = room(free=0, occ=100, unk=255)  # mode: raw percentages
map_seed("seed-p2-8bit", 0, yaml("m.pgm"), p2(ROWS))
map_seed("seed-p5-8bit", 1, yaml("m.pgm", "0.050000", "[-10.000000, -10.000000, 0.000000]"), p5(ROWS))
map_seed("seed-p5-16bit", 2, yaml("m.pgm", "0.02"), p5([[v * 257 for v in r] for r in ROWS], 65535))
map_seed("seed-p2-16bit", 3, yaml("m.pgm", "0.1"), p2([[v * 257 for v in r] for r in ROWS], 65535))
map_seed("seed-p2-maxval15", 0, yaml("m.pgm"), p2([[v * 15 // 255 for v in r] for r in ROWS], 15))
map_seed("seed-p5-raw", 0, yaml("m.pgm", extra="mode: raw\n"), p5(RAW))
map_seed("seed-p5-scale-negate", 1,
         yaml("m.pgm", extra="mode: scale\n").replace("negate: 0", "negate: 1"),
         p5([[255 - v for v in r] for r in ROWS]))
map_seed("seed-p6", 0, yaml("m.ppm", "0.0504", "[25.9, 48.5, 3.14]"), p6(ROWS))
map_seed("seed-p3", 0, yaml("m.ppm", "0.05", "[1.0, 2.0]"), p3(ROWS))
map_seed("seed-p1", 0, yaml("m.pbm"), p1(ROWS))
map_seed("seed-p4", 0, yaml("m.pbm"), p4(ROWS))
map_seed("seed-pam-gray-alpha", 0, yaml("m.pam"), pam(ROWS))
map_seed("seed-pam-rgb", 0, yaml("m.pam"), pam(ROWS, depth=3, tupltype="RGB"))
map_seed("seed-png-gray8", 0, yaml("m.png", "0.05", "[-100.0, -172.0, 0.0]"), png(ROWS))
map_seed("seed-png-gray16", 2, yaml("m.png"), png(ROWS, 0, 16))
map_seed("seed-png-rgb", 0, yaml("m.png"), png(ROWS, 2))
map_seed("seed-png-gray-alpha", 1, yaml("m.png"), png(ROWS, 4))
map_seed("seed-png-rgba16", 3, yaml("m.png"), png(ROWS, 6, 16))
map_seed("seed-png-palette", 0, yaml("m.png", "0.025"), png_palette(ROWS))
map_seed("seed-png-raw", 0, yaml("m.png", extra="mode: raw\n"), png(RAW))
# ROS-style YAMLs as written by map_server and by hand (cf. /work/shared/maps).
map_seed("seed-yaml-nav2", 0,
         "image: nav2_depot.pgm\nmode: trinary\nresolution: 0.05\n"
         "origin: [-0.843, -5.37, 0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.25\n",
         p5(ROWS))
map_seed("seed-yaml-comments", 1,
         "# YAML written by us\n# Resolution is an estimate.\nimage: /abs/intel_lab.pgm\n"
         "resolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: false\n", p2(ROWS))
map_seed("seed-yaml-flow", 0,
         "{image: \"m.pgm\", resolution: 1.0e-1, origin: [0, 0, 0.7853981], negate: false,"
         " occupied_thresh: 0.9, free_thresh: 0.1, unknown_key: [1, 2]}\n", p5(ROWS))

# ---------------------------------------------------------------- config_parse
# The complete file of docs/USER-GUIDE.md "Parameters" (every key, defaults).
with open(os.path.join(HERE, "..", "..", "docs", "USER-GUIDE.md")) as f:
    guide = f.read()
FULL = guide.split("```toml\n", 1)[1].split("```", 1)[0] if "```toml\n" in guide else None
CONFIGS = {
    "seed-empty": "",
    "seed-top": "resolution = 0.1\nseed = 42\n",
    "seed-scanner-robot": "[scanner]\nrange = 8.0\n\n[robot]\nradius = 0.2\n",
    "seed-parent": (
        "[parent]\nalpha = 0.01\nbeta = 0.001\nscoring = \"literal\"\nband_width = 1.5\n"
        "samples_per_m2 = 8.0\nmax_samples = 3000\ncluster_area = 24.0\nmax_clusters = 24\n"
        "kmeans_iterations = 30\nmin_gain_cells = 10\nmin_frontier_cells = 2\ngamma = 0.5\n"
        "error_candidates = 4\n"),
    "seed-children": (
        "[children]\ncount = 2\nradius = 0.25\nalpha_c = 1.0\nbeta_c = 1.0\ntheta_t_deg = 90.0\n"
        "d_t = 3.0\nmin_range = 1.3\nmax_range = 20.0\nclearance_cap = 1.0\n"
        "sight_clearance = 0.0\nmarker_radius = 0.1\nstrategy = \"balanced\"\n"
        "travel_weight = 0.01\n"),
    "seed-children-min-error": "[children]\ncount = 2\nstrategy = \"min-error\"\ntravel_weight = 0.5\n",
    "seed-children-random": "[children]\ncount = 1\nstrategy = \"random\"\n",
    "seed-children-angle": "[children]\nstrategy = \"angle\"\nmin_range = 0.5\n",
    "seed-children-distance": "[children]\nstrategy = \"distance\"\nd_t = 1.0\n",
    "seed-children-none": "[children]\ncount = 0\n",
    "seed-instrument": (
        "[instrument]\nmodel = \"ts16\"\ndistance_sigma_mm = 2.0\ndistance_ppm = 2.0\n"
        "angle_sigma_arcsec = 1.0\nmin_range = 1.3\nmax_range = 3000.0\nthree_d = true\n"
        "instrument_height = 1.0\nmarker_height = 0.5\n"),
    "seed-instrument-focus": "[instrument]\nmodel = \"focus-s350\"\n",
    "seed-instrument-presets": "instrument = { model = \"ms05axii\" }\n",
    "seed-accuracy-mission": "[accuracy]\nmonte_carlo_runs = 5\n\n[mission]\nmax_scans = 2\n",
    "seed-limits": "[limits]\nmax_grid_cells = 100000\n",
    "seed-inline": (
        "resolution = 0.1\nscanner.range = 5.0\nrobot = { radius = 0.1 }\n"
        "instrument.model = \"ts60\"\n"),
    "seed-errors": "[children]\ncount = -1\nbogus = 3\n[[parent]]\n",
}
if FULL:
    CONFIGS["seed-user-guide"] = FULL + "\n[limits]\nmax_grid_cells = 150000000\n"
for name, text in CONFIGS.items():
    out("config_parse", name, text)


# ---------------------------------------------------------------- plan_inputs
def plan_seed(name, w, h, res, strategy, rng, cmin, cmax, radius, children, free_robots,
              positions, cells):
    head = bytes([w - 1, h - 1, res, strategy, rng, cmin, cmax, radius,
                  children | (4 if free_robots else 0)])
    pos = b"".join(bytes(p) for p in (positions + [(0, 0, 0)] * 4)[:4])
    packed = bytearray()
    for i in range(0, len(cells), 4):
        b = 0
        for j, c in enumerate(cells[i:i + 4]):
            b |= c << (2 * j)
        packed.append(b)
    out("plan_inputs", name, head + pos + bytes(packed))


def known_room(w, h, seen):
    """Free inside `seen` columns, walls on the border, unknown beyond."""
    cells = []
    for y in range(h):
        for x in range(w):
            if x >= seen:
                cells.append(3)
            elif x == 0 or y == 0 or y == h - 1:
                cells.append(2)
            else:
                cells.append(0)
    return cells


# (mode, a, b): mode 0 cell centre of (a % w, b % h).
plan_seed("seed-parent-alone", 40, 30, 1, 1, 100, 65, 0, 25, 0, False,
          [(0, 10, 15)], known_room(40, 30, 20))
plan_seed("seed-two-children", 64, 40, 1, 1, 100, 65, 0, 25, 2, False,
          [(0, 30, 20), (0, 15, 10), (0, 15, 30)], known_room(64, 40, 40))
plan_seed("seed-min-error", 48, 32, 1, 4, 120, 40, 160, 20, 2, True,
          [(0, 12, 16), (0, 2, 4), (0, 2, 28)], known_room(48, 32, 30))
plan_seed("seed-random-3", 64, 64, 2, 0, 200, 30, 0, 25, 3, True,
          [(0, 20, 30), (0, 10, 20), (0, 10, 40), (0, 30, 30)], known_room(64, 64, 40))
plan_seed("seed-outside", 32, 32, 0, 2, 80, 20, 0, 10, 1, False,
          [(3, 250, 250), (4, 3, 1)], known_room(32, 32, 20))
plan_seed("seed-nan", 16, 16, 1, 3, 60, 20, 0, 10, 1, False,
          [(5, 0, 1)], known_room(16, 16, 10))
plan_seed("seed-all-free", 20, 20, 2, 1, 60, 30, 0, 10, 2, False,
          [(0, 10, 10), (0, 5, 5), (2, 16, 16)], [])
plan_seed("seed-tiny", 1, 1, 1, 1, 60, 65, 0, 25, 0, False, [(0, 0, 0)], [0])
