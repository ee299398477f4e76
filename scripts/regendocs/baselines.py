"""The planners against each other, with the team and alone, and against the
known-map bound (`experiments/baselines.toml`): RESULTS' baselines section."""

from pathlib import Path

from .common import IMAGES, median, median_range, per_map, places, ratio_range, run, source
from .experiments import CONTEXT, experiment, grouped, map_name, maps_in, reached, scans_to, summary, with_spots

NAMES = {"paper": "the paper's planner", "tour": "the tour", "frontier": "explore_lite's nearest frontier",
         "gain": "pure gain"}


def per_greedy(records, share):
    """Each episode's scans to `share` over its layout's greedy stations for it."""
    return [scans_to(r, share) / greedy_stations(r, share) for r in records
            if scans_to(r, share) is not None and greedy_stations(r, share)]


def greedy_stations(record, share):
    bound = record.get("bound") or {}
    for level in bound.get("levels", []):
        if abs(level["share"] - share) < 1e-9:
            return level["greedy_stations"]
    return None


@source("baselines", "`experiment experiments/baselines.toml`: paper, tour, frontier and gain, team and alone, "
        "against the known-map bound", heavy=True, inputs=["experiments/baselines.toml"])
def baselines(tmp):
    plan, records = experiment("baselines")
    maps = maps_in(plan)
    planners = []
    for e in plan["episodes"]:
        if e["planner"] not in planners:
            planners.append(e["planner"])
    groups = grouped(records, lambda r: (map_name(r["episode"]["map"]), r["episode"]["planner"],
                                         r["episode"]["parameters"]))

    def med(m, p, team, f):
        return median([f(r) for r in groups[m, p, "team" if team else "single"]])

    rows, bound_rows = [], []
    for m in maps:
        for p in planners:
            team, single = groups[m, p, "team"], groups[m, p, "single"]
            rows.append(
                f"| {m} | {p} | {median_range(reached(team, 0.99), 0)} | {median_range([summary(r)['scans'] for r in team], 0)} "
                f"| {median_range([summary(r)['parent_travel_m'] for r in team], 0)} "
                f"| {median_range([summary(r)['campaign_time_h'] for r in team], 2)} "
                f"| {median_range([summary(r)['final_position_sigma_m'] * 1000 for r in team], 0)} "
                f"| {median_range([summary(r)['parent_travel_m'] for r in single], 0)} "
                f"| {median_range([summary(r)['campaign_time_h'] for r in single], 2)} |"
            )
            bound_rows.append(
                f"| {m} | {p} | {median_range(per_greedy(team, 0.9), 2)} | {median_range(per_greedy(team, 0.99), 2)} "
                f"| {median([greedy_stations(r, 0.99) for r in team]):.0f} |"
            )

    hours = {(m, p, t): med(m, p, t, lambda r: summary(r)["campaign_time_h"]) for m in maps for p in planners
             for t in (True, False)}
    travel = {(m, p, t): med(m, p, t, lambda r: summary(r)["parent_travel_m"]) for m in maps for p in planners
              for t in (True, False)}

    def quickest(m, team):
        return min(planners, key=lambda p: hours[m, p, team])

    tour_first = [m for m in maps if quickest(m, True) == "tour"]
    time_pairs = []
    drive_shares = []
    for m in maps:
        others = [p for p in planners if p != "tour"]
        next_p = min(others, key=lambda p: hours[m, p, True])
        time_pairs.append((m, f"{hours[m, 'tour', True]:.2f} h against {hours[m, next_p, True]:.2f} h for {NAMES[next_p]}"))
        drive_shares.append(travel[m, "tour", True] / min(travel[m, p, True] for p in others))
    same_ranking = all(
        sorted(planners, key=lambda p: hours[m, p, True]) == sorted(planners, key=lambda p: hours[m, p, False])
        for m in maps
    )

    def to99_median(m, p):
        return median(reached(groups[m, p, "team"], 0.99))

    soonest = []
    soonest_drive = []
    for m in maps:
        best = min(planners, key=lambda p: (to99_median(m, p), p != "tour"))
        if best == "tour":
            soonest.append((m, f"the tour ({to99_median(m, 'tour'):.0f} scans)"))
        else:
            soonest.append((m, f"{NAMES[best]} ({to99_median(m, best):.0f} scans against the tour's "
                               f"{to99_median(m, 'tour'):.0f})"))
            soonest_drive.append(travel[m, best, True] / travel[m, "tour", True])

    best_per_greedy = {share: [] for share in (0.9, 0.99)}
    for share in best_per_greedy:
        for m in maps:
            best_per_greedy[share].append(min(median(per_greedy(groups[m, p, "team"], share)) for p in planners))

    same_scans = all(
        [summary(r)["scans"] for r in groups[m, p, "team"]] == [summary(r)["scans"] for r in groups[m, p, "single"]]
        for m in maps for p in planners
    )
    farther = [travel[m, p, True] / travel[m, p, False] - 1 for m in maps for p in planners]
    longer = [hours[m, p, True] / hours[m, p, False] for m in maps for p in planners]
    sigma = {(m, p): med(m, p, True, lambda r: summary(r)["final_position_sigma_m"]) for m in maps for p in planners}
    share = [sigma[m, p] / travel[m, p, True] * 100 for m in maps for p in planners]
    spread_by_map = [(m, max(sigma[m, p] for p in planners) / min(sigma[m, p] for p in planners)) for m in maps]
    widest, widest_ratio = max(spread_by_map, key=lambda x: x[1])
    lo_p = min(planners, key=lambda p: sigma[widest, p])
    hi_p = max(planners, key=lambda p: sigma[widest, p])

    figures = {
        "table": "\n".join([
            "| map | planner | scans to 99 %, team | all scans | parent travel m, team | campaign h, team "
            "| final σ mm, team | parent travel m, single | campaign h, single |",
            "|---|---|---:|---:|---:|---:|---:|---:|---:|",
        ] + rows),
        "bound_table": "\n".join([
            "| map | planner | to 90 % ÷ greedy | to 99 % ÷ greedy | greedy stations, 99 % |",
            "|---|---|---:|---:|---:|",
        ] + bound_rows),
        "tour_first": places(tour_first, maps),
        "time_pairs": per_map(time_pairs),
        "drive_share": ratio_range(drive_shares, 2),
        "single_ranking": "is the same" if same_ranking else "differs on some maps",
        "soonest": per_map(soonest),
        "soonest_drive": ratio_range(soonest_drive, 1) if soonest_drive else "—",
        "best_to99": ratio_range(best_per_greedy[0.99], 1),
        "best_to90": ratio_range(best_per_greedy[0.9], 1),
        "same_scans": "the team scans where the single robot does (the same scans for every planner and seed)"
        if same_scans else "the team's scans differ from the single robot's on some seeds",
        "farther": f"{min(farther) * 100:.0f}–{max(farther) * 100:.0f}",
        "longer": ratio_range(longer, 1),
        "office_tour_hours": f"{hours['office', 'tour', True]:.2f} h against {hours['office', 'tour', False]:.2f} h",
        "sigma_share": f"{min(share):.3f}–{max(share):.3f}",
        "sigma_spread": f"{widest_ratio:.1f}",
        "sigma_spread_where": f"the {widest}: {sigma[widest, lo_p] * 1000:.0f} mm for {NAMES[lo_p]}, "
                              f"{sigma[widest, hi_p] * 1000:.0f} mm for {NAMES[hi_p]}",
    }
    report = Path(tmp) / "report"
    run("report", Path(CONTEXT["records"]) / "baselines", "--out", report, "-q", cwd=tmp)
    figures[IMAGES] = {"docs/images/baselines-coverage-office.png": report / "coverage-office.png"}
    return with_spots(figures, records)
