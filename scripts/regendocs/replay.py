"""A simulation replayed as a field campaign (the user guide's "Replaying a
simulation"): `explore --field-data` on the built-in maps, then `campaign
init` and one `campaign add` per scan, as the user guide shows; how far the
campaign's stations lie from where the simulation put them, and how much of
the knowledge map agrees (`replay`, a few minutes)."""

import math
from pathlib import Path

from .common import SPOTS, fixed, load, run, source
from .ledger import SPOT_FIELDS

MAPS = ["site", "tunnel", "office"]
UNKNOWN = 205


def pgm(path):
    """(width, height, pixels) of a binary PGM."""
    data = Path(path).read_bytes()
    magic, size, _, pixels = data.split(b"\n", 3)
    w, h = map(int, size.split())
    return w, h, pixels


def replay_one(name, tmp):
    sim, field, camp = tmp / f"{name}-sim", tmp / f"{name}-field", tmp / f"{name}-camp"
    run("explore", "-q", "--builtin", name, "--field-data", field, "--out", sim, cwd=tmp)
    f = load(field / "field.json")
    start = f"{f['start']['x']!r},{f['start']['y']!r}"
    area = ",".join(repr(v) for v in f["area"])
    run("campaign", "init", camp, "--start", start, "--area", area, "--config", field / "config.toml", cwd=tmp)
    steps = load(sim / "episode.json")["steps"]
    for n in range(1, len(steps) + 1):
        run("campaign", "add", camp, "--scan", field / f"scan-{n:04}.ply",
            "--readings", field / f"readings-{n:04}.csv", "-q", cwd=tmp)
    state, network = load(camp / "campaign.json"), load(camp / "network.json")
    stations = {s["name"]: s for s in network["stations"]}
    worst_ratio, worst_err, worst_sigma = 0.0, 0.0, 0.0
    for scan, step in zip(state["scans"], steps):
        s = stations[scan["station"]]
        err = math.hypot(s["position"]["x"] - step["position"]["x"], s["position"]["y"] - step["position"]["y"])
        worst_ratio = max(worst_ratio, err / s["sigma_m"]) if s["sigma_m"] > 0 else worst_ratio
        worst_err, worst_sigma = max(worst_err, err), max(worst_sigma, s["sigma_m"])
    w, h, mine = pgm(camp / "knowledge.pgm")
    _, _, theirs = pgm(sim / "knowledge.pgm")
    known = sum(1 for v in theirs if v != UNKNOWN)
    agree = sum(1 for a, b in zip(mine, theirs) if a == b and b != UNKNOWN)
    summary = load(sim / "summary.json")
    return {"scans": len(steps), "worst_ratio": worst_ratio, "worst_err": worst_err, "worst_sigma": worst_sigma,
            "agree": agree / known, "summary": summary}


@source("replay", "`explore --field-data` and `campaign init`/`add` on the built-in maps: a simulation replayed "
        "as a field campaign (a few minutes)", heavy=True)
def replay(tmp):
    tmp = Path(tmp)
    r = {name: replay_one(name, tmp) for name in MAPS}
    figures = {f"{m}_sigmas": fixed(r[m]["worst_ratio"], 1) for m in MAPS}
    figures.update({f"{m}_agree": f"{r[m]['agree'] * 100:.1f}" for m in MAPS})
    figures["office_scans"] = str(r["office"]["scans"])
    figures["office_drift_m"] = fixed(r["office"]["worst_err"], 2)
    figures["office_sigma_m"] = fixed(r["office"]["worst_sigma"], 2)
    figures["within"] = "within 3σ" if all(r[m]["worst_ratio"] <= 3 for m in MAPS) else "not all within 3σ"
    figures[SPOTS] = [{"label": f"{m} (the simulation)", "args": ["--builtin", m], "config": None,
                       "expect": {k: r[m]["summary"][k] for k in SPOT_FIELDS}} for m in MAPS[:1]]
    return figures
