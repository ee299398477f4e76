"""The light sources: single `explore`, `grid` and `--cloud-out` runs of a few
seconds each, run by every `--check`."""

import re
import struct
import sys
from pathlib import Path

from .common import IMAGES, SHARED, count, fixed, load, median, mm, percent_share, run, source, spread, thetas


def episode_figures(summary):
    """The figures every explore run gives."""
    s = summary
    return {
        "scans": count(s["scans"]),
        "travel_m": count(round(s["parent_travel_m"])),
        "hours": fixed(s["campaign_time_h"], 1),
        "hours2": fixed(s["campaign_time_h"], 2),
        "coverage": percent_share(s["coverage"], 1),
        "sigma_mm": mm(s["final_position_sigma_m"], 0),
        "sigma_mm1": mm(s["final_position_sigma_m"], 1),
        "cycles": count(s["cps_cycles"]),
        "subgoals": count(s["subgoal_retrievals"]),
        "stop": s["stop_reason"],
        "error_percent3": fixed(s["error_percent_of_travel"], 3),
        "error_percent4": fixed(s["error_percent_of_travel"], 4),
    }


@source("site", "`explore --monte-carlo 500`: the default run on the built-in site (README's first command)")
def site(tmp):
    run("explore", "-q", "--monte-carlo", "500", "--out", "out", cwd=tmp)
    out = Path(tmp) / "out"
    figures = episode_figures(load(out / "summary.json"))
    figures[IMAGES] = {
        "docs/images/explore-site.png": out / "map.png",
        "docs/images/error-site-min-error.png": out / "error.png",
    }
    return figures


@source("site-paper", "`explore --preset paper`: the paper's choices on the built-in site")
def site_paper(tmp):
    run("explore", "-q", "--preset", "paper", "--out", "out", cwd=tmp)
    return episode_figures(load(Path(tmp) / "out" / "summary.json"))



def model_rows(path):
    """model.csv: one row per scan, as dicts of floats."""
    lines = Path(path).read_text().strip().split("\n")
    head = lines[0].split(",")
    return [dict(zip(head, map(float, line.split(",")))) for line in lines[1:]]


@source("cloud-out", "`explore --monte-carlo 20 --cloud-out`: the site's registered 3D model, open and with "
        "targets, and in its true poses")
def cloud_out(tmp):
    figures = {}
    rows = []
    runs = [
        ("open", ["--monte-carlo", "20"], "default site, smoothed poses of Monte Carlo run 1 (filtering poses)"),
        ("targets", ["--monte-carlo", "20", "--place-targets", "30", "--child-strategy", "min-error"],
         "`--place-targets 30 --child-strategy min-error`, smoothed (filtering)"),
        ("true", [], "the same site, true poses (no `--monte-carlo`: range noise only, 2 mm + 2 ppm)"),
    ]
    for key, extra, label in runs:
        run("explore", "-q", *extra, "--cloud-out", f"{key}.laz", "--out", key, cwd=tmp)
        s = load(Path(tmp) / key / "summary.json")
        model = s["model"]
        figures[f"{key}_points"] = count(model["points"])
        figures[f"{key}_mean_mm"] = mm(model["mean_distance_m"])
        figures[f"{key}_p95_mm"] = mm(model["p95_distance_m"])
        if "filtering" in model:
            f = model["filtering"]
            figures[f"{key}_filtering_mean_mm"] = mm(f["mean_distance_m"])
            figures[f"{key}_filtering_p95_mm"] = mm(f["p95_distance_m"])
            cells = [f"{mm(model[k])} mm ({mm(f[k])})" for k in ["mean_distance_m", "p95_distance_m",
                                                                "max_position_error_m"]]
        else:
            cells = [f"{mm(model['mean_distance_m'])} mm", f"{mm(model['p95_distance_m'])} mm", "0"]
        rows.append(f"| {label} | {count(model['points'])} | {s['scans']} | " + " | ".join(cells) + " |")
    figures["table"] = "\n".join([
        "| | points | scans | mean distance to the walls | 95th percentile | largest pose error |",
        "|---|---:|---:|---:|---:|---:|",
        "| paper CPS-VII (Fig. 12) | 9.85 million | 26 | — | — | 98–116 mm 3D error after 181–343 m |",
        "| paper CPS-VIII (Fig. 13) | 6.13 billion | 14+ | — | — | 23.1 mm after 270.1 m |",
    ] + rows)
    # How the open model's error grows along the chain (model.csv, per scan).
    scans = model_rows(Path(tmp) / "open" / "model.csv")
    first, last = scans[0], scans[len(scans) * 2 // 3:]

    def span(key, scale=1000.0, places=0):
        values = [abs(r[key]) * scale for r in last]
        return f"{min(values):.{places}f}–{max(values):.{places}f}"

    figures["first_mean_mm"] = mm(first["mean_distance_m"])
    figures["first_p95_mm"] = mm(first["p95_distance_m"])
    figures["last_scans"] = f"{int(last[0]['scan'])}–{int(last[-1]['scan'])}"
    figures["last_mean_mm"] = span("mean_distance_m")
    figures["last_pose_mm"] = span("position_error_m")
    figures["last_heading"] = span("heading_error_arcsec", 1.0)  # as large, of either sign
    # The same model as LAS and as LAZ.
    run("explore", "-q", "--cloud-out", "true.las", "--out", "true-las", cwd=tmp)
    ratio = (Path(tmp) / "true.las").stat().st_size / (Path(tmp) / "true.laz").stat().st_size
    figures["laz_smaller"] = fixed(ratio, 0)
    open_mean = load(Path(tmp) / "open" / "summary.json")["model"]["mean_distance_m"]
    targets_mean = load(Path(tmp) / "targets" / "summary.json")["model"]["mean_distance_m"]
    figures["targets_tighter"] = f"{open_mean / targets_mean:.1f}"
    return figures


BUILTIN_HEADER = [
    "| map | scans | coverage | wall coverage | CPS cycles | moves with subgoals | parent travel (m) | children's travel (m) | campaign h | final σ mm | stop |",
    "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|",
]


def builtin_row(name, s):
    kids = ", ".join(str(round(t)) for t in s["child_travel_m"])
    return (
        f"| {name} | {s['scans']} | {s['coverage']:.4f} | {s['wall_coverage']:.4f} | {s['cps_cycles']} "
        f"| {s['subgoal_retrievals']} | {round(s['parent_travel_m'])} | {kids} | {s['campaign_time_h']:.2f} "
        f"| {s['final_position_sigma_m'] * 1000:.1f} | {s['stop_reason']} |"
    )


@source("builtin", "`explore --builtin NAME` and `--preset paper`, seed 0, on the three built-in maps")
def builtin(tmp):
    maps = ["site", "office", "tunnel"]
    runs = {}
    for preset in ["default", "paper"]:
        for name in maps:
            out = f"{preset}-{name}"
            extra = [] if preset == "default" else ["--preset", "paper"]
            run("explore", "-q", "--builtin", name, *extra, "--out", out, cwd=tmp)
            runs[preset, name] = load(Path(tmp) / out / "summary.json")
    figures = {
        f"{preset}_table": "\n".join(BUILTIN_HEADER + [builtin_row(n, runs[preset, n]) for n in maps])
        for preset in ["default", "paper"]
    }
    pairs = [(runs["default", n], runs["paper", n]) for n in maps]
    figures["fewer_scans"] = spread([1 - d["scans"] / p["scans"] for d, p in pairs], 0, 100)
    figures["travel_share"] = spread([d["parent_travel_m"] / p["parent_travel_m"] for d, p in pairs], 0, 100)
    figures["time_share"] = spread([d["campaign_time_h"] / p["campaign_time_h"] for d, p in pairs], 0, 100)
    ratios = [p["final_position_sigma_m"] / d["final_position_sigma_m"] for d, p in pairs]
    figures["accuracy_ratio"] = f"{min(ratios):.1f}–{max(ratios):.0f}"
    figures["free_unseen"] = f"{max(1 - d['coverage'] for d, _ in pairs) * 100:.2f}"
    figures["walls_unseen"] = f"{max(1 - d['wall_coverage'] for d, _ in pairs) * 100:.2f}"
    # The paper's planner with the parent alone: the same scan positions?
    same = True
    alone = {}
    for name in maps:
        out = Path(tmp) / f"alone-{name}"
        run("explore", "-q", "--builtin", name, "--preset", "paper", "--children", "0", "--out", out, cwd=tmp)
        alone[name] = load(out / "summary.json")
        positions = lambda d: [s["position"] for s in load(Path(tmp) / d / "episode.json")["steps"]]
        same = same and positions(out) == positions(f"paper-{name}")
        figures[f"alone_{name}_scans"] = count(alone[name]["scans"])
    figures["alone_same"] = "at the same positions as" if same else "at other positions than"
    # Eq. (2)'s angle θ over the children that moved, the paper's site run.
    theta = median(thetas(load(Path(tmp) / "paper-site" / "episode.json")))
    figures["paper_site_theta"] = fixed(theta, 0)
    figures["paper_site_travel_m"] = count(round(runs["paper", "site"]["parent_travel_m"]))
    figures["alone_site_travel_m"] = count(round(alone["site"]["parent_travel_m"]))
    figures["alone_coverage"] = f"{min(a['coverage'] for a in alone.values()):.4f}"
    figures["alone_walls"] = f"{min(a['wall_coverage'] for a in alone.values()):.2f}"
    return figures


WORDS = ["no", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine"]


def word(n):
    return WORDS[n] if 0 <= n < len(WORDS) else str(n)


@source("site-step", "`explore --builtin site --children 2 --step-figure 7`: the user guide's step figure")
def site_step(tmp):
    run("explore", "-q", "--builtin", "site", "--children", "2", "--step-figure", "7", "--out", "out", cwd=tmp)
    out = Path(tmp) / "out"
    step = load(out / "episode.json")["steps"][6]
    move = step["move"]
    target = step["plan"]["candidates"][move["target"]]
    cycles = len(move["cycles"])
    return {
        "g": fixed(target["g"], 1),
        "cycles": word(cycles),
        "subgoals": word(max(cycles - 1, 0)),
        IMAGES: {"docs/images/step-figure-site.png": out / "step-007.png"},
    }

READ_LINE = re.compile(r": (\d+) points read")
MAP_LINE = re.compile(r"map: (\d+) × (\d+) cells of ([\d.]+) m .*?: (\d+) free, (\d+) occupied")
GAPS_LINE = re.compile(r"([\d.]+) % of it is gaps")
MENDS_LINE = re.compile(r"--resolution (\S+) leaves ([\d.]+) % gaps and (\d+) % in one piece")


@source("clouds", "`grid --cloud` and `explore --map` on the four shared clouds", needs="clouds")
def clouds(tmp):
    where = SHARED / "clouds"
    runs = [
        ("room", "pcl_room_scan1.pcd", ["--free-from-scans"], []),
        ("velodyne", "velodyne_outdoor_scan_251370668.pcd", ["--free-from-scans"], []),
        ("autzen", "autzen_trim.laz", ["--resolution", "1", "--height-above-ground", "1,60"],
         ["--resolution", "1", "--range", "40"]),
        ("autzen_fine", "autzen_trim.laz", ["--resolution", "0.5", "--height-above-ground", "1,60"],
         ["--resolution", "0.5", "--range", "40"]),
        ("pump", "pump_room_scan.e57", ["--free-from-scans", "--resolution", "0.05"], ["--resolution", "0.05"]),
    ]
    figures = {}
    for key, cloud, grid_flags, explore_flags in runs:
        done = run("grid", "--cloud", where / cloud, *grid_flags, "--out", f"{key}.yaml",
                   "--preview", f"{key}.png", cwd=tmp)
        said = done.stdout + done.stderr
        m = MAP_LINE.search(said)
        if not m:
            sys.exit(f"regen-docs: clouds: no map line from grid on {cloud}:\n{said}")
        w, h, _, free, occupied = m.groups()
        figures[f"{key}_points_read"] = count(READ_LINE.search(said).group(1))
        figures[f"{key}_cells"] = f"{w} × {h}"
        figures[f"{key}_free"] = count(free)
        figures[f"{key}_occupied"] = count(occupied)
        gaps = GAPS_LINE.search(said)
        figures[f"{key}_gaps"] = gaps.group(1) if gaps else "none"
        mends = MENDS_LINE.search(said)
        if mends:
            figures[f"{key}_mend_resolution"], figures[f"{key}_mend_gaps"], figures[f"{key}_mend_piece"] = mends.groups()
        model = ["--cloud-out", f"{key}.las"] if key == "autzen" else []
        run("explore", "-q", "--map", f"{key}.yaml", *explore_flags, *model, "--out", f"{key}-out", cwd=tmp)
        if model:
            # The model's height range from its LAS header (max z at byte 211,
            # min z at 219), and the ground's height from the map's frame.
            header = (Path(tmp) / f"{key}.las").read_bytes()[:227]
            zmax, zmin = struct.unpack_from("<2d", header, 211)
            figures[f"{key}_model_zmin"] = fixed(zmin, 0)
            figures[f"{key}_model_zmax"] = fixed(zmax, 0)
            frame = load(Path(tmp) / f"{key}.frame.json")
            figures[f"{key}_ground"] = fixed(frame["ground"]["c"] / frame["metres_per_unit"][1], 0)
        s = load(Path(tmp) / f"{key}-out" / "summary.json")
        figures[f"{key}_scans"] = count(s["scans"])
        figures[f"{key}_travel_m"] = fixed(s["parent_travel_m"], 1)
        figures[f"{key}_travel_km"] = fixed(s["parent_travel_m"] / 1000.0, 1)
        figures[f"{key}_coverage"] = percent_share(s["coverage"], 1)
        figures[f"{key}_connected"] = percent_share(s["connected_coverage"], 0)
        figures[f"{key}_stop"] = s["stop_reason"]
        figures[f"{key}_seen"] = (
            "every reachable free cell seen"
            if s["coverage"] >= 1.0
            else f"{percent_share(s['coverage'], 1)} % of the reachable free space seen"
        )
    figures[IMAGES] = {
        "docs/images/grid-pcl-room.png": Path(tmp) / "room.png",
        "docs/images/grid-velodyne.png": Path(tmp) / "velodyne.png",
        "docs/images/grid-autzen.png": Path(tmp) / "autzen.png",
        "docs/images/grid-pump-room.png": Path(tmp) / "pump.png",
        "docs/images/explore-velodyne.png": Path(tmp) / "velodyne-out" / "map.png",
    }
    stops = {figures[f"{key}_stop"] for key, *_ in runs if key != "autzen_fine"}
    figures["stops"] = " or ".join(f"`{s}`" for s in sorted(stops))
    return figures
