"""The paper's experiments, reproduced (`experiments/alpha-beta.toml`,
`strategies.toml`, `cps-viii.toml`): RESULTS' Fig. 9, Fig. 10 and CPS-VIII
tables and the sentences that read them."""

from .common import mean, mean_sd, median, per_map, places, source
from .experiments import by_map_and, experiment, maps_in, reached, summary, with_spots


def seen_m2(s, resolution):
    """The area seen of the reachable free space, m²."""
    return s["coverage"] * s["reachable_free_cells"] * resolution * resolution


@source("alpha-beta", "`experiment experiments/alpha-beta.toml`: Fig. 9, α = 0 against β = 0", heavy=True,
        inputs=["experiments/alpha-beta.toml"])
def alpha_beta(tmp):
    plan, records = experiment("alpha-beta")
    maps = maps_in(plan)
    groups = by_map_and(records, "parameters")
    label = {"alpha0": "α = 0", "beta0": "β = 0"}
    rows, stats = [], {}
    for m in maps:
        for p in ["alpha0", "beta0"]:
            rs = groups[m, p]
            ss = [summary(r) for r in rs]
            res = rs[0]["episode"]["config"]["resolution"]
            to99 = reached(rs, 0.99)
            st = {
                "scans": mean([s["scans"] for s in ss]),
                "per_scan": mean([seen_m2(s, res) / s["scans"] for s in ss]),
                "travel": mean([s["parent_travel_m"] for s in ss]),
                "per_m": mean([seen_m2(s, res) / s["parent_travel_m"] for s in ss]),
                "subgoals": mean([s["subgoal_retrievals"] for s in ss]),
            }
            stats[m, p] = st
            rows.append(
                f"| {m} | {label[p]} | {mean_sd([s['scans'] for s in ss], 1)} "
                f"| {mean(to99):.1f} | {st['per_scan']:.1f} "
                f"| {mean_sd([s['parent_travel_m'] for s in ss], 0)} | {st['per_m']:.2f} | {st['subgoals']:.1f} |"
            )
    a = {m: stats[m, "alpha0"] for m in maps}
    b = {m: stats[m, "beta0"] for m in maps}
    fewer = [m for m in maps if a[m]["scans"] < b[m]["scans"]]

    def less(x, y):
        share = 1 - x / y
        return f"{abs(share) * 100:.0f} % {'fewer' if share >= 0 else 'more'}"

    def more(x, y):
        share = x / y - 1
        return f"{abs(share) * 100:.0f} % {'more' if share >= 0 else 'less'}"

    figures = {
        "table": "\n".join([
            "| map | weights | scans | scans to 99 % | m² per scan | parent travel, m | m² per m travelled | moves with subgoals |",
            "|---|---|---:|---:|---:|---:|---:|---:|",
            "| paper's MAP-C | α = 0 (area) | 18 | — | — | — | — | 4 |",
            "| paper's MAP-C | β = 0 (travel) | 23 | — | — | — | — | 0 |",
        ] + rows),
        "fewer_where": places(fewer, maps),
        "fewer_scans": per_map([(m, less(a[m]["scans"], b[m]["scans"])) for m in maps]),
        "subgoals_where": places([m for m in maps if a[m]["subgoals"] > b[m]["subgoals"]], maps),
        "travel_times": per_map([(m, f"{a[m]['travel'] / b[m]['travel']:.1f} times as far") for m in maps]),
        "per_scan": per_map([(m, more(a[m]["per_scan"], b[m]["per_scan"])) for m in maps]),
        "per_m": per_map([(m, f"{b[m]['per_m'] / a[m]['per_m']:.1f} times as much") for m in maps]),
    }
    return with_spots(figures, records)


STRATEGIES = [("random", "(a) random"), ("balanced", "(b) αc = βc"), ("angle", "(c) αc ≫ βc"),
              ("distance", "(d) αc ≪ βc"), ("min-error", "(e) min-error")]


@source("strategies", "`experiment experiments/strategies.toml`: Fig. 10, the child strategies after nine moves",
        heavy=True, inputs=["experiments/strategies.toml"])
def strategies(tmp):
    plan, records = experiment("strategies")
    maps = maps_in(plan)
    groups = by_map_and(records, "child_strategy")
    sigma = {}
    detail = []
    for m in maps:
        for key, name in STRATEGIES:
            rs = groups[m, key]
            mm = [summary(r)["final_position_sigma_m"] * 1000 for r in rs]
            kids = [sum(summary(r)["child_travel_m"]) / len(summary(r)["child_travel_m"]) for r in rs]
            sigma[m, key] = (mean(mm), median(mm))
            detail.append(
                f"| {m} | {name} | {mean_sd(mm, 1)} | {median(mm):.1f} | {max(mm):.1f} "
                f"| {mean(kids):.0f} | {mean([summary(r)['parent_travel_m'] for r in rs]):.0f} |"
            )
    table = "\n".join([
        "| map | (a) random | (b) αc = βc | (c) αc ≫ βc | (d) αc ≪ βc | (e) min-error |",
        "|---|---:|---:|---:|---:|---:|",
    ] + [
        f"| {m if i else m + ', mean σ mm'} | " + " | ".join(f"{sigma[m, k][0]:.1f}" for k, _ in STRATEGIES) + " |"
        for i, m in enumerate(maps)
    ])
    mean_of = {k: {m: sigma[m, k][0] for m in maps} for k, _ in STRATEGIES}

    def beats_a_and_d(k):
        return [m for m in maps if mean_of[k][m] < mean_of["random"][m] and mean_of[k][m] < mean_of["distance"][m]]

    worst_d = [m for m in maps if all(mean_of["distance"][m] >= mean_of[k][m] for k, _ in STRATEGIES)]
    ratio = [mean_of["balanced"][m] / mean_of["min-error"][m] for m in maps]
    medians = [sigma[m, "min-error"][1] / sigma[m, "balanced"][1] for m in maps]
    figures = {
        "table": table,
        "detail": "\n".join([
            "| map | strategy | σ after nine moves, mm: mean ± sd | median | max | child travel, m (mean) "
            "| parent travel, m (mean) |",
            "|---|---|---:|---:|---:|---:|---:|",
        ] + detail),
        "b_where": places(beats_a_and_d("balanced"), maps),
        "c_where": places(beats_a_and_d("angle"), maps),
        "d_worst": places(worst_d, maps),
        "e_times": f"{min(ratio):.0f} to {max(ratio):.0f}",
        "e_shares": per_map([(m, f"{100 / r:.0f} %") for m, r in zip(maps, ratio)]),
        "e_medians": ", ".join(f"{100 * r:.0f} %" for r in medians),
    }
    return with_spots(figures, records)


@source("cps-viii", "`experiment experiments/cps-viii.toml`: a CPS-VIII-like campaign with four children",
        heavy=True, inputs=["experiments/cps-viii.toml", "experiments/maps/building.yaml",
                            "experiments/maps/building.png"])
def cps_viii(tmp):
    plan, records = experiment("cps-viii")
    (m,) = maps_in(plan)
    groups = by_map_and(records, "child_strategy")
    rows, share = [], {}
    for key, name in [("balanced", "balanced (Eq. 2, αc = βc)"), ("min-error", "min-error")]:
        ss = [summary(r) for r in groups[m, key]]
        sig = [s["final_position_sigma_m"] * 1000 for s in ss]
        travel = [s["parent_travel_m"] for s in ss]
        share[key] = mean(sig) / 1000 / mean(travel) * 100
        rows.append(
            f"| {name} | {mean_sd([s['scans'] for s in ss], 1)} | {mean_sd(travel, 0)} "
            f"| {mean_sd(sig, 1)} | {share[key]:.4f} % |"
        )
    ss = [summary(r) for r in records]
    figures = {
        "table": "\n".join([
            "| | scans | parent travel, m | final σ, mm | σ / travel |",
            "|---|---:|---:|---:|---:|",
            "| paper CPS-VIII (measured, Fig. 13) | 14 | 270.1 | 23.1 | 0.0085 % |",
        ] + rows),
        "min_share": f"{share['min-error']:.4f}",
        "balanced_times": f"{share['balanced'] / 0.0085:.1f}",
        "below": "below" if share["min-error"] < 0.0085 else "above",
        "scans": f"{mean([s['scans'] for s in ss]):.0f}",
        "travel": f"{mean([s['parent_travel_m'] for s in ss]):,.0f}",
    }
    return with_spots(figures, records)
