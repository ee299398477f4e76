#!/usr/bin/env python3
"""An independent check that `explore --cloud-out` on a map `grid` made from a
cloud writes the model over its source cloud: same units, same heights, same
coordinate system.

Makes a source cloud with laspy: a 16 m × 10 m room with a pillar, in
international feet at state-plane-like coordinates, its floor on a tilted plane
about 425 ft up, with a GeoTIFF key directory (EPSG 2994, feet). Then runs
`cpsplan grid` and `cpsplan explore --cloud-out` on it, reads the model with
laspy and checks: the coordinate-system record copied byte for byte; the
model's floor on the source's floor and its walls up to 2 m (in feet) above
it; every sampled model point within 1 ft (a cell and the range noise) of a
source point in 3D.

usage: check_frame.py CPSPLAN WORK_DIR
"""
import struct
import subprocess
import sys
from pathlib import Path

import laspy
import numpy as np

FOOT = 0.3048
X0, Y0 = 636000.0, 849000.0  # feet
FLOOR = 425.0  # feet, at the room's corner
SLOPE = (0.01, -0.005)  # rise per run along x and y


def fail(msg):
    print(f"check_frame: FAILED: {msg}")
    sys.exit(1)


def floor_ft(x_m, y_m):
    return FLOOR + (SLOPE[0] * x_m + SLOPE[1] * y_m) / FOOT


def source_room():
    """The room's points in metres, local frame: (x, y, height above the floor)."""
    pts = []
    # The floor every 5 cm, off the 0.1 m cells' edges.
    xs, ys = np.arange(0.025, 16.0, 0.05), np.arange(0.025, 10.0, 0.05)
    gx, gy = np.meshgrid(xs, ys)
    pts.append(np.c_[gx.ravel(), gy.ravel(), np.zeros(gx.size)])
    heights = np.arange(0.0, 3.0001, 0.05)
    def wall(x, y):
        wx, wh = np.meshgrid(x, heights)
        wy, _ = np.meshgrid(y, heights)
        pts.append(np.c_[wx.ravel(), wy.ravel(), wh.ravel()])
    along_x, along_y = np.arange(0.0, 16.0001, 0.05), np.arange(0.0, 10.0001, 0.05)
    wall(along_x, np.zeros_like(along_x))
    wall(along_x, np.full_like(along_x, 10.0))
    wall(np.zeros_like(along_y), along_y)
    wall(np.full_like(along_y, 16.0), along_y)
    side = np.arange(7.0, 8.0001, 0.05)  # a 1 m pillar
    for x, y in [(side, np.full_like(side, 4.0)), (side, np.full_like(side, 5.0)),
                 (np.full_like(side, 7.0), side - 3.0), (np.full_like(side, 8.0), side - 3.0)]:
        wall(x, y)
    return np.vstack(pts)


def geokeys():
    # KeyDirectoryVersion 1, revision 1.0, 3 keys: GTModelType projected,
    # ProjectedCSType 2994 (NAD83 / Oregon GIC Lambert, ft), ProjLinearUnits
    # 9002 (international foot).
    keys = [1, 1, 0, 3, 1024, 0, 1, 1, 3072, 0, 1, 2994, 3076, 0, 1, 9002]
    return struct.pack(f"<{len(keys)}H", *keys)


def main():
    cpsplan, work = sys.argv[1], Path(sys.argv[2])
    work.mkdir(parents=True, exist_ok=True)
    local = source_room()
    src = np.c_[
        X0 + local[:, 0] / FOOT,
        Y0 + local[:, 1] / FOOT,
        floor_ft(local[:, 0], local[:, 1]) + local[:, 2] / FOOT,
    ]
    header = laspy.LasHeader(point_format=0, version="1.2")
    header.scales = np.array([0.001, 0.001, 0.001])
    header.offsets = np.array([X0, Y0, FLOOR])
    keys = geokeys()
    header.vlrs.append(laspy.VLR(user_id="LASF_Projection", record_id=34735,
                                 description="GeoTiff GeoKeyDirectoryTag", record_data=keys))
    las = laspy.LasData(header)
    las.x, las.y, las.z = src[:, 0], src[:, 1], src[:, 2]
    las.write(work / "room.las")

    def run(*args):
        done = subprocess.run([cpsplan, *map(str, args)], capture_output=True, text=True)
        if done.returncode != 0:
            fail(f"cpsplan {' '.join(map(str, args))}: {done.stderr}")

    run("grid", "-q", "--cloud", work / "room.las", "--out", work / "room.yaml")
    if not (work / "room.frame.json").is_file():
        fail("grid wrote no room.frame.json beside the map")
    run("explore", "-q", "--map", work / "room.yaml", "--max-scans", "3",
        "--out", work / "report", "--cloud-out", work / "model.las")
    model = laspy.read(work / "model.las")

    records = [v for v in model.header.vlrs if v.user_id == "LASF_Projection"]
    if len(records) != 1 or records[0].record_id != 34735:
        fail(f"the model's CRS records: {[(v.user_id, v.record_id) for v in model.header.vlrs]}")
    data = getattr(records[0], "record_data", None)
    if data is None:
        data = records[0].record_data_bytes()
    if bytes(data) != keys:
        fail("the model's GeoKeyDirectory differs from the source's")

    m = np.c_[model.x, model.y, model.z]
    if len(m) < 1000:
        fail(f"only {len(m)} model points")
    lo, hi = src.min(axis=0) - 1.0, src.max(axis=0) + 1.0
    if (m < lo).any() or (m > hi).any():
        fail(f"model outside the source's box: {m.min(axis=0)}..{m.max(axis=0)} against {lo}..{hi}")
    # Heights above the source's floor under each point, feet.
    lx, ly = (m[:, 0] - X0) * FOOT, (m[:, 1] - Y0) * FOOT
    above = m[:, 2] - floor_ft(lx, ly)
    if above.min() < -0.3 or above.min() > 0.3:
        fail(f"the model's lowest point is {above.min():.2f} ft off the source's floor")
    top = 2.0 / FOOT
    if abs(above.max() - top) > 0.3:
        fail(f"the model's walls reach {above.max():.2f} ft above the floor, not {top:.2f}")
    # Every sampled model point near a source point (1 ft: a 0.1 m cell and noise).
    rng = np.random.default_rng(0)
    sample = m[rng.choice(len(m), size=min(2000, len(m)), replace=False)]
    walls = src[(src[:, 2] - floor_ft((src[:, 0] - X0) * FOOT, (src[:, 1] - Y0) * FOOT)) > 0.01]
    worst = 0.0
    for chunk in np.array_split(sample, 20):
        d = np.sqrt(((chunk[:, None, :] - walls[None, :, :]) ** 2).sum(axis=2)).min(axis=1)
        worst = max(worst, float(d.max()))
    if worst > 1.0:
        fail(f"a model point lies {worst:.2f} ft from every source point")
    print(f"check_frame: OK: {len(m)} model points over the source room in feet, "
          f"floor to {above.max():.2f} ft, CRS copied, farthest sampled point {worst:.2f} ft "
          f"from the source")


if __name__ == "__main__":
    main()
