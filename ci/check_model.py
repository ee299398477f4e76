#!/usr/bin/env python3
"""An independent reader of the registered 3D model `cpsplan explore --cloud-out`
writes: reads the LAS with laspy and the PLY files with numpy, and checks them
against the run's summary.json and the ground-truth map.

usage: check_model.py REPORT_DIR MODEL.las MODEL.ply MAP.yaml
"""
import json
import sys
from pathlib import Path

import laspy
import numpy as np


def fail(msg):
    print(f"check_model: FAILED: {msg}")
    sys.exit(1)


def read_ply(path):
    """Binary little-endian PLY: {element: structured array}."""
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    if header[0] != "ply" or header[1] != "format binary_little_endian 1.0":
        fail(f"{path}: not a binary little-endian PLY")
    types = {"double": "<f8", "float": "<f4", "uint": "<u4", "int": "<i4",
             "uchar": "u1", "ushort": "<u2"}
    elements = []
    for line in header[2:]:
        words = line.split()
        if words[0] == "element":
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property":
            elements[-1][2].append((words[2], types[words[1]]))
    out, offset = {}, end
    for name, count, props in elements:
        dtype = np.dtype(props)
        out[name] = np.frombuffer(data, dtype=dtype, count=count, offset=offset)
        offset += dtype.itemsize * count
    if offset != len(data):
        fail(f"{path}: {len(data) - offset} bytes after the last element")
    return out


def read_map(yaml_path):
    """A trinary ROS map (as cpsplan writes it): occupied mask, resolution, origin."""
    meta = {}
    for line in Path(yaml_path).read_text().splitlines():
        if ":" in line and not line.startswith("#"):
            k, v = line.split(":", 1)
            meta[k.strip()] = v.strip()
    pgm = Path(yaml_path).with_name(meta["image"].strip("'\""))
    raw = pgm.read_bytes()
    fields, pos = [], 0
    while len(fields) < 4:
        while raw[pos:pos + 1].isspace():
            pos += 1
        start = pos
        while not raw[pos:pos + 1].isspace():
            pos += 1
        fields.append(raw[start:pos])
    w, h = int(fields[1]), int(fields[2])
    pixels = np.frombuffer(raw, dtype=np.uint8, count=w * h, offset=pos + 1).reshape(h, w)
    free = pixels[::-1] == 254  # row 0 at the bottom
    origin = [float(v) for v in meta["origin"].strip("[]").split(",")]
    return ~free, float(meta["resolution"]), origin


def main():
    report, las_path, ply_path, map_yaml = sys.argv[1:5]
    summary = json.loads((Path(report) / "summary.json").read_text())
    model, scans = summary["model"], summary["scans"]

    las = laspy.read(las_path)
    n = las.header.point_count
    if n != model["points"]:
        fail(f"LAS holds {n} points, summary.json says {model['points']}")
    if (las.header.version.major, las.header.version.minor) != (1, 2):
        fail(f"LAS version {las.header.version}")
    ids = np.asarray(las.point_source_id)
    if sorted(np.unique(ids)) != list(range(1, scans + 1)):
        fail("the point source ids are not the scan numbers 1..scans")
    if not np.array_equal(np.asarray(las.gps_time), ids.astype(float)):
        fail("gps_time does not repeat the scan number")

    ply = read_ply(ply_path)["vertex"]
    if len(ply) != n:
        fail(f"PLY holds {len(ply)} points, the LAS {n}")
    if sorted(np.unique(ply["scan"])) != list(range(1, scans + 1)):
        fail("the PLY's scan numbers are not 1..scans")
    stations = read_ply(Path(ply_path).with_name(Path(ply_path).name + "-stations.ply"))
    if len(stations["vertex"]) != scans or len(stations["edge"]) != scans - 1:
        fail("the stations PLY does not hold one vertex per scan and one edge between each")
    if list(stations["vertex"]["scan"]) != list(range(1, scans + 1)):
        fail("the stations are not numbered 1..scans in order")
    model_csv = (Path(report) / "model.csv").read_text().splitlines()[1:]
    if [int(line.split(",")[0]) for line in model_csv] != list(range(1, scans + 1)):
        fail("model.csv does not number its scans 1..scans")

    # Each point within the stated 95th-percentile distance of a ground-truth
    # wall (plus the LAS's 0.1 mm quantum): one of the cells at the corners of
    # the square of that half-width around it is solid.
    solid, res, origin = read_map(map_yaml)
    x = np.asarray(las.x) - origin[0]
    y = np.asarray(las.y) - origin[1]
    d = model["p95_distance_m"] + 2e-4
    near = np.zeros(n, dtype=bool)
    h, w = solid.shape
    for dx in (-d, d):
        for dy in (-d, d):
            cx = np.clip(np.floor((x + dx) / res).astype(int), 0, w - 1)
            cy = np.clip(np.floor((y + dy) / res).astype(int), 0, h - 1)
            near |= solid[cy, cx]
    share = near.mean()
    if share < 0.95:
        fail(f"only {100 * share:.2f} % of the points lie within {d * 1e3:.1f} mm of a wall")
    print(f"check_model: laspy {laspy.__version__} read {n} points of {scans} scans; "
          f"{100 * share:.2f} % lie within {d * 1e3:.1f} mm of a ground-truth wall "
          f"(stated 95th percentile {model['p95_distance_m'] * 1e3:.1f} mm); PLY and stations agree")


if __name__ == "__main__":
    main()
