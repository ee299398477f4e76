"""The measurement that chose the defaults (`experiments/defaults.toml`):
every planner under the default child strategy and every child strategy under
the default planner, on every built-in and shared map, five seeds. RESULTS'
"The defaults" section."""

from .common import count, median, median_range, places, ratio_range, source
from .experiments import by_map_and, experiment, maps_in, reached, summary, with_spots

# The office floors of issue 35's travel target.
OFFICE_FLOORS = ["office", "intel_lab", "willow_garage", "utexas_gdc_floor3", "mit_csail_3rd_floor",
                 "yujin_rnd_office"]
BASELINES = ["paper", "frontier", "gain"]
PLANNERS = ["default"] + BASELINES + ["oracle"]
STRATEGIES = ["default", "balanced", "random", "angle", "distance"]


def positions(record):
    return [(s["position"]["x"], s["position"]["y"]) for s in record["outcome"]["scans"]]


@source("defaults", "`experiment experiments/defaults.toml`: every planner and child strategy, every map, "
        "five seeds (about 2.5 h on two cores)", heavy=True, needs="maps", inputs=["experiments/defaults.toml"])
def defaults(tmp):
    plan, records = experiment("defaults")
    maps = maps_in(plan)
    groups = by_map_and(records, "parameters")

    def values(m, p, f):
        return [f(r) for r in groups[m, p]]

    def med(m, p, f):
        return median(values(m, p, f))

    def hours(r):
        return summary(r)["campaign_time_h"]

    def travel(r):
        return summary(r)["parent_travel_m"]

    def to99(m, p):
        return reached(groups[m, p], 0.99)

    hour_rows, scan_rows, strategy_rows = [], [], []
    wins, misses, oracle_ratio, floor_share, drives_least = [], [], {}, {}, []
    for m in maps:
        h = {p: med(m, p, hours) for p in PLANNERS}
        best = min(BASELINES, key=lambda p: h[p])
        win = h["default"] <= h[best]
        (wins if win else misses).append(m)
        verdict = "yes" if win else f"no: {best} {h[best]:.2f}"
        hour_rows.append(f"| {m} | " + " | ".join(median_range(values(m, p, hours), 2) for p in PLANNERS)
                         + f" | {verdict} |")
        reach = {p: to99(m, p) for p in PLANNERS}
        if reach["oracle"] and len(reach["default"]) == len(groups[m, "default"]):
            oracle_ratio[m] = median(reach["default"]) / median(reach["oracle"])
        share = med(m, "default", travel) / med(m, "paper", travel)
        if m in OFFICE_FLOORS:
            floor_share[m] = share
        if all(med(m, "default", travel) < med(m, p, travel) for p in BASELINES):
            drives_least.append(m)
        ratio = f"{oracle_ratio[m]:.2f}" if m in oracle_ratio else "—"
        floor = " (office floor)" if m in OFFICE_FLOORS else ""
        scan_rows.append(
            f"| {m} | " + " | ".join(median_range(reach[p], 0) for p in PLANNERS)
            + f" | {ratio} | {median_range(values(m, 'default', travel), 0)} "
            f"| {median_range(values(m, 'paper', travel), 0)} | {share:.2f}{floor} |"
        )
        strategy_rows.append(f"| {m} | " + " | ".join(
            f"{med(m, s, hours):.2f} / {med(m, s, lambda r: summary(r)['final_position_sigma_m']) * 1000:.0f}"
            for s in STRATEGIES) + " |")

    within = sorted((m for m, r in oracle_ratio.items() if r <= 1.25), key=maps.index)
    # The best of all four explorers against the oracle, map by map.
    best_over = []
    for m in oracle_ratio:
        ratios = {p: median(to99(m, p)) / median(to99(m, "oracle")) for p in PLANNERS[:-1] if to99(m, p)}
        p = min(ratios, key=ratios.get)
        if ratios[p] > 1.25:
            best_over.append(f"{m} {ratios[p]:.2f} (`{'tour' if p == 'default' else p}`)")
    oracle_short = [m for m in maps if len(to99(m, "oracle")) < len(groups[m, "oracle"])]
    worst = max(oracle_ratio, key=oracle_ratio.get)

    # The child strategies: where they scan, their hours and their accuracy.
    same, other = 0, 0
    spread, slowest_vs_quickest, to_balanced, to_best_other = [], [], [], []
    for m in maps:
        for s in STRATEGIES[1:]:
            for a, b in zip(groups[m, "default"], groups[m, s]):
                other += 1
                same += positions(a) == positions(b)
        h = {s: med(m, s, hours) for s in STRATEGIES}
        spread.append(max(h.values()) / min(h.values()) - 1)
        slowest_vs_quickest.append(h["default"] / min(h.values()) - 1)
        sigma = {s: med(m, s, lambda r: summary(r)["final_position_sigma_m"]) for s in STRATEGIES}
        to_balanced.append(sigma["balanced"] / sigma["default"])
        to_best_other.append(min(sigma[s] for s in STRATEGIES[1:]) / sigma["default"])

    figures = {
        "hours_table": "\n".join([
            "| map | default (tour) h | paper h | frontier h | gain h | oracle h | default ≤ best baseline |",
            "|---|---:|---:|---:|---:|---:|---|",
        ] + hour_rows),
        "scans_table": "\n".join([
            "| map | scans to 99 %: default | paper | frontier | gain | oracle | default ÷ oracle "
            "| parent travel m: default | paper | default ÷ paper |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        ] + scan_rows),
        "strategies_table": "\n".join([
            "| map | min-error (default): h / final σ mm | balanced | random | angle | distance |",
            "|---|---:|---:|---:|---:|---:|",
        ] + strategy_rows),
        "maps": count(len(maps)),
        "wins": count(len(wins)),
        "misses": places(misses, maps) if misses else "none",
        "oracle_maps": count(len(oracle_ratio)),
        "within": count(len(within)),
        "within_where": places(within, maps) if within else "none",
        "oracle_worst": f"{worst}, {oracle_ratio[worst]:.2f}",
        "best_over_count": count(len(best_over)),
        "best_over": ", ".join(best_over) if best_over else "none",
        "oracle_short": places(oracle_short, maps) if oracle_short else "no map",
        "floor_share": ratio_range(list(floor_share.values()), 2),
        "floors_met": count(sum(1 for v in floor_share.values() if v <= 0.8)),
        "drives_least": count(len(drives_least)),
        "same_positions": f"{same} of {other}",
        "hours_spread": f"{max(spread) * 100:.1f}",
        "min_error_hours": f"{max(slowest_vs_quickest) * 100:.1f}",
        "to_balanced": ratio_range(to_balanced, 1),
        "to_best_other": ratio_range(to_best_other, 1),
    }
    return with_spots(figures, records)
