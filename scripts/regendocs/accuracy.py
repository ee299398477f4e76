"""The accuracy of whole campaigns: the paper's planner with Eq. (2) and with
`min-error` children on the built-in maps, first order against Monte Carlo
(RESULTS' "Whole campaigns"). Six runs, about half a minute."""

from pathlib import Path

from .common import fixed, load, median, run, source, thetas

MAPS = ["site", "office", "tunnel"]
STRATEGIES = [("balanced", "balanced (the paper's)"), ("min-error", "min-error")]


def share(s):
    return s["final_position_sigma_m"] / s["parent_travel_m"] * 100


@source("accuracy", "`explore --builtin NAME --preset paper --child-strategy S --monte-carlo 500`: whole campaigns")
def accuracy(tmp):
    rows, runs = [], {}
    for m in MAPS:
        for key, name in STRATEGIES:
            out = Path(tmp) / f"{m}-{key}"
            run("explore", "-q", "--builtin", m, "--preset", "paper", "--child-strategy", key,
                "--monte-carlo", "500", "--out", out, cwd=tmp)
            s, e = load(out / "summary.json"), load(out / "episode.json")
            heading = max(step["heading_sigma_arcsec"] for step in e["steps"])
            runs[m, key] = (s, heading)
            rows.append(
                f"| {m} | {name if m == 'site' else key} | {s['scans']} | {s['parent_travel_m']:.0f} "
                f"| {s['final_position_sigma_m'] * 1000:.1f} | {s['monte_carlo_mean_error_m'] * 1000:.1f} "
                f"| {share(s):.4f} % | {sum(s['child_travel_m']):.0f} | {heading:.0f} | {median(thetas(e)):.0f} |"
            )
    site_paper = share(runs["site", "balanced"][0])
    site_min = share(runs["site", "min-error"][0])
    office, office_heading = runs["office", "balanced"]
    office_min = runs["office", "min-error"][0]
    calm = [m for m in MAPS if runs[m, "balanced"][1] < 3000]
    same = all(runs[m, "balanced"][0]["scans"] == runs[m, "min-error"][0]["scans"]
               and abs(runs[m, "balanced"][0]["parent_travel_m"] - runs[m, "min-error"][0]["parent_travel_m"]) < 1e-6
               for m in MAPS)
    return {
        "table": "\n".join([
            "| map | strategy | scans | parent travel (m) | σ of the last scan (mm) | Monte Carlo mean error (mm) "
            "| σ / travel | children's travel (m) | largest heading σ (″) | median θ (°) |",
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
        ] + rows),
        "site_paper_share": f"{site_paper:.4f}",
        "cps_vii": ("inside" if 0.034 <= site_paper <= 0.054 else "below" if site_paper < 0.034 else "above"),
        "site_min_share": f"{site_min:.4f}",
        "cps_viii": "below" if site_min < 0.0085 else "above",
        "calm": ", ".join(calm) if calm else "no map",
        "office_scans": str(office["scans"]),
        "office_heading": f"{office_heading:,.0f}",
        "office_degrees": fixed(office_heading / 3600, 1),
        "office_mc_m": fixed(office["monte_carlo_mean_error_m"], 1),
        "office_sigma_m": fixed(office["final_position_sigma_m"], 1),
        "office_smoothed_mc_m": fixed(office["monte_carlo_smoothed_mean_error_m"], 2),
        "office_min_mc_m": fixed(office_min["monte_carlo_mean_error_m"], 2),
        "office_min_sigma_m": fixed(office_min["final_position_sigma_m"], 2),
        "office_min_smoothed_mc_m": fixed(office_min["monte_carlo_smoothed_mean_error_m"], 2),
        "same_positions": "do not change" if same else "change",
    }
