"""Closed CPS networks (RESULTS' "Closed networks", the README's campus
figures): the open chain, thirty targets left by the team and three control
points on the campus, the built-in office and Willow Garage, with Eq. (2) and
`min-error` children, the campus under a 50 mm tolerance and its registered
model (`closed`, about half an hour); and the open chain against thirty
targets on every map (`closed-networks`, experiments/closed-networks.toml)."""

import math
from pathlib import Path

from .common import ROOT, SPOTS, called, count, fixed, load, places, ratio_range, run, source, toml_of
from .experiments import CONTEXT, by_map_and, experiment, maps_in, summary, with_spots
from .ledger import SPOT_FIELDS

# The paper's planner, as these runs have always been measured.
PLANNER = {"parent": {"planner": "paper", "viewpoints": False}}
SITES = {
    "campus": ["--map", "../shared/maps/cit_tsudanuma_campus.yaml"],
    "office": ["--builtin", "office"],
    "willow": ["--map", "../shared/maps/willow_garage.yaml"],
}
NETWORKS = {"open": [], "+30 targets": ["--place-targets", "30"], "3 control": None}
TOLERANCE = "campus +30 targets, max σ 50 mm"


def mm(v):
    return "—" if v is None else f"{v * 1e3:.1f}"


def percent(share):
    """A small share as the documents write it: four decimals, or two
    significant digits below 0.001 %."""
    if share >= 1e-3:
        return f"{share:.4f}"
    return f"{share:.{1 - math.floor(math.log10(share))}f}"


def worst_share(s):
    return 100 * s["worst_smoothed_sigma_m"] / s["parent_travel_m"] if s["parent_travel_m"] else 0.0


def runs_of():
    """Every run of the campaign table: (name, explore arguments)."""
    out = []
    for site, where in SITES.items():
        for strategy in ["balanced", "min-error"]:
            for network, extra in NETWORKS.items():
                extra = extra if extra is not None else ["--targets", f"experiments/control/{site}.csv"]
                out.append((f"{site} {strategy} {network}", [*where, "--child-strategy", strategy, *extra]))
    out.append((TOLERANCE, [*SITES["campus"], "--place-targets", "30", "--max-sigma", "0.05"]))
    return out


def explore_kept(name, args, root):
    """Runs `explore` with the paper's planner into root/NAME unless a whole
    run is there (--records keeps them, as experiments are resumed)."""
    out = root / name.replace(" ", "_").replace(",", "").replace("σ", "sigma")
    if not (out / "summary.json").exists():
        root.mkdir(parents=True, exist_ok=True)
        config = root / "planner.toml"
        config.write_text(toml_of(PLANNER))
        run("explore", "-q", "--config", config, *args, "--max-scans", "5000", "--out", out, cwd=ROOT)
    return load(out / "summary.json")


@source("closed", "`explore` with targets and control points on the campus, the office and Willow Garage "
        "(about half an hour)", heavy=True, needs="maps",
        inputs=["experiments/control/campus.csv", "experiments/control/office.csv", "experiments/control/willow.csv"])
def closed(tmp):
    root = Path(CONTEXT["records"]) / "closed"
    rows, s, spots = [], {}, []
    for name, args in runs_of():
        s[name] = explore_kept(name, args, root)
        x = s[name]
        rows.append(
            f"| {name} | {x['scans']} | {x['parent_travel_m']:.0f} | {x['campaign_time_h']:.1f} "
            f"| {mm(x['final_position_sigma_m'])} | {mm(x['worst_position_sigma_m'])} "
            f"| {mm(x['worst_smoothed_sigma_m'])} | {percent(worst_share(x))} % | {x['targets_placed']} "
            f"| {x['closures']} | {len(x['sigma_violations'])} |"
        )
        if name in ("office balanced open", "office min-error +30 targets"):
            spots.append({"label": name, "args": args + ["--max-scans", "5000"], "config": PLANNER,
                          "expect": {k: x[k] for k in SPOT_FIELDS}})
    rows.append("| paper CPS-VIII (measured, 4 children, FARO Focus markers) | 14+ | 270 | — | 23.1 | — | — "
                "| 0.0085 % | — | — | — |")

    def w(site, strategy, network):
        return s[f"{site} {strategy} {network}"]

    campus_open = w("campus", "balanced", "open")
    tol, tol_min = s[TOLERANCE], w("campus", "min-error", "+30 targets")
    targets_cost = [w(site, k, "+30 targets")["campaign_time_h"] / w(site, k, "open")["campaign_time_h"] - 1
                    for site in SITES for k in ["balanced", "min-error"]]
    names = {"campus": "the campus's", "office": "the office's", "willow": "Willow Garage's"}
    targets = []
    for site in SITES:
        worst_open = w(site, "balanced", "open")["worst_smoothed_sigma_m"]
        opened = f"{worst_open:.1f} m" if worst_open >= 1 else f"{worst_open * 1000:.0f} mm"
        targets.append(
            f"{names[site]} from {opened} to {w(site, 'balanced', '+30 targets')['worst_smoothed_sigma_m'] * 1000:.0f} mm "
            f"and {w(site, 'min-error', '+30 targets')['worst_smoothed_sigma_m'] * 1000:.1f} mm"
        )
    control = "; ".join(
        f"{site} {w(site, 'balanced', '3 control')['worst_smoothed_sigma_m'] * 1000:.0f} / "
        f"{w(site, 'min-error', '3 control')['worst_smoothed_sigma_m'] * 1000:.0f} mm"
        for site in SITES
    )
    same_as_min = all(tol[k] == tol_min[k] for k in SPOT_FIELDS)
    balanced_targets = [worst_share(w(site, "balanced", "+30 targets")) for site in SITES]
    min_targets = [worst_share(w(site, "min-error", "+30 targets")) for site in SITES]

    # The registered campus model under the tolerance.
    model_dir = root / "campus-model"
    if not (model_dir / "summary.json").exists():
        explore_kept("campus-model", [*SITES["campus"], "--place-targets", "30", "--max-sigma", "0.05",
                                      "--monte-carlo", "20", "--cloud-out", str(root / "campus.laz"), "--force"], root)
    model = load(model_dir / "summary.json")["model"]
    figures = {
        "table": "\n".join([
            "| run | scans | parent travel (m) | campaign (h) | final σ (mm) | worst σ when scanned (mm) "
            "| worst smoothed σ (mm) | worst smoothed / travel | targets left | closures | scans over tolerance |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        ] + rows),
        "campus_km": fixed(campus_open["parent_travel_m"] / 1000, 1),
        "campus_open_final_m": fixed(campus_open["final_position_sigma_m"], 1),
        "campus_open_worst_m": fixed(campus_open["worst_smoothed_sigma_m"], 1),
        "eq2_open_share": ratio_range([worst_share(w(site, "balanced", "open")) for site in SITES], 2),
        "targets": "; ".join(targets),
        "campus_min_share": percent(worst_share(w("campus", "min-error", "+30 targets"))),
        "targets_cost": f"{min(targets_cost) * 100:.0f}–{max(targets_cost) * 100:.0f}",
        "control": control,
        "tol_worst_mm": mm(tol["worst_position_sigma_m"]),
        "tol_worst_mm0": f"{tol['worst_position_sigma_m'] * 1000:.0f}",
        "tol_smoothed_mm": mm(tol["worst_smoothed_sigma_m"]),
        "tol_smoothed_mm0": f"{tol['worst_smoothed_sigma_m'] * 1000:.0f}",
        "tol_hours": fixed(tol["campaign_time_h"], 1),
        "tol_hours0": fixed(tol["campaign_time_h"], 0),
        "balanced_targets_hours": fixed(w("campus", "balanced", "+30 targets")["campaign_time_h"], 1),
        "balanced_targets_hours0": fixed(w("campus", "balanced", "+30 targets")["campaign_time_h"], 0),
        "tol_closure_moves": count(tol["closure_moves"]),
        "tol_same": "the same run as the min-error one" if same_as_min else "not the min-error run",
        "model_points": fixed(model["points"] / 1e6, 2),
        "model_mean_mm": fixed(model["mean_distance_m"] * 1000, 1),
        "model_p95_mm": fixed(model["p95_distance_m"] * 1000, 1),
        "model_filtering_mean_mm": fixed(model["filtering"]["mean_distance_m"] * 1000, 1),
        "model_filtering_p95_mm": fixed(model["filtering"]["p95_distance_m"] * 1000, 1),
        "balanced_targets_share": f"{percent(min(balanced_targets))}–{percent(max(balanced_targets))}",
        "min_targets_share": percent(max(min_targets)),
    }
    figures[SPOTS] = spots
    return figures


def bound_mm(s):
    """The issue's bound: the larger of 5 mm and 0.0085 % of the travel."""
    return max(5.0, 0.000085 * s["parent_travel_m"] * 1000)


@source("closed-networks", "`experiment experiments/closed-networks.toml`: the open chain against thirty targets, "
        "every map", heavy=True, needs="maps", inputs=["experiments/closed-networks.toml"])
def closed_networks(tmp):
    plan, records = experiment("closed-networks")
    maps = maps_in(plan)
    by = {}
    for (m, p), rs in by_map_and(records, "parameters").items():
        for r in rs:
            by[m, p, r["episode"]["child_strategy"]] = summary(r)
    rows, within, closest, cost = [], {"balanced": [], "min-error": []}, None, []
    for m in maps:
        ref = by[m, "open", "balanced"]
        b = bound_mm(ref)
        cells = []
        for k in ["balanced", "min-error"]:
            o, t = by[m, "open", k], by[m, "targets30", k]
            ok = t["worst_smoothed_sigma_m"] * 1000 <= b
            if ok:
                within[k].append(m)
            if k == "min-error" and ok:
                room = t["worst_smoothed_sigma_m"] * 1000 / b
                if closest is None or room > closest[1]:
                    closest = (m, room, t["worst_smoothed_sigma_m"] * 1000, b)
            cost.append(t["campaign_time_h"] / o["campaign_time_h"] - 1)
            cells.append(f"{mm(o['worst_smoothed_sigma_m'])} | {mm(t['worst_position_sigma_m'])} / "
                         f"{mm(t['worst_smoothed_sigma_m'])} {'✓' if ok else '✗'}")
        rows.append(f"| {m} | {ref['parent_travel_m']:.0f} | {b:.1f} | {cells[0]} | {cells[1]} "
                    f"| {by[m, 'targets30', 'balanced']['targets_placed']} / "
                    f"{by[m, 'targets30', 'min-error']['targets_placed']} |")
    misses = [m for m in maps if m not in within["balanced"]]
    figures = {
        "table": "\n".join([
            "| map | parent travel (m) | bound (mm) | Eq. (2) open | Eq. (2) +30 targets | min-error open "
            "| min-error +30 targets | targets left, Eq. (2) / min-error |",
            "|---|---:|---:|---:|---:|---:|---:|---:|",
        ] + rows),
        "maps": count(len(maps)),
        "min_within": count(len(within["min-error"])),
        "closest": f"{called(closest[0])}, {closest[2]:.1f} mm against {closest[3]:.1f} mm" if closest else "none",
        "min_misses": places([m for m in maps if m not in within["min-error"]], maps)
        if len(within["min-error"]) < len(maps) else "none",
        "balanced_within": count(len(within["balanced"])),
        "balanced_misses": places(misses, maps) if misses else "none",
        "cost": f"{min(cost) * 100:.0f}–{max(cost) * 100:.0f}",
    }
    return with_spots(figures, records)
