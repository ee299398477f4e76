"""Running the experiment files of `experiments/` for the heavy sources, and
reading their records: conditions, seeds, and the figures the documents take
from them."""

import sys
from pathlib import Path

from .common import ROOT, SPOTS, load, run
from .ledger import spot_of_record

EXPERIMENTS = ROOT / "experiments"

# Where --heavy keeps the experiments' records (`--records`); a run there is
# resumed, so an interrupted experiment goes on where it stopped.
CONTEXT = {"records": ROOT / "target" / "regen-docs"}


def experiment(name):
    """Runs `experiments/NAME.toml` into the records directory (resuming what
    is there) and returns its plan and every record, in episode order."""
    file = EXPERIMENTS / f"{name}.toml"
    out = Path(CONTEXT["records"]) / name
    resume = ["--resume"] if (out / "plan.json").exists() else []
    print(f"regen-docs: experiment {name} into {out}", file=sys.stderr)
    run("experiment", file, "--out", out, *resume, "-q", cwd=EXPERIMENTS)
    plan = load(out / "plan.json")
    records = [load(p) for p in sorted((out / "records").glob("*.json"))]
    if len(records) != len(plan["episodes"]):
        sys.exit(f"regen-docs: {out}: {len(records)} records of {len(plan['episodes'])} episodes")
    failed = [r["episode"]["label"] for r in records if r["outcome"]["status"] != "finished"]
    if failed:
        sys.exit(f"regen-docs: {name}: episodes failed: {', '.join(failed)}")
    return plan, records


def map_name(where):
    """`builtin:office` → office; `../shared/maps/intel_lab.yaml` → intel_lab."""
    return where.split(":", 1)[1] if where.startswith("builtin:") else Path(where).stem


def summary(record):
    return record["outcome"]["summary"]


def scans_to(record, share):
    """The first scan at which the coverage reached `share`; None if none did."""
    for s in record["outcome"]["scans"]:
        if s["coverage"] >= share:
            return s["scan"]
    return None


def reached(records, share):
    """Each episode's scans to `share` of the coverage, of those that got there."""
    return [t for t in (scans_to(r, share) for r in records) if t is not None]


def condition(record):
    e = record["episode"]
    return (e["parameters"], e["planner"], e["child_strategy"], e["instrument"])


def grouped(records, key):
    """Records by `key(record)`, each group in episode order, groups in the
    order they first appear."""
    out = {}
    for r in records:
        out.setdefault(key(r), []).append(r)
    return out


def by_map_and(records, field):
    """{(map name, episode[field]): [records over the seeds]}."""
    return grouped(records, lambda r: (map_name(r["episode"]["map"]), r["episode"][field]))


def maps_in(plan):
    seen = []
    for e in plan["episodes"]:
        m = map_name(e["map"])
        if m not in seen:
            seen.append(m)
    return seen


def spots(records, limit=None):
    """The spot checks of an experiment: for each condition, its shortest
    episode (fewest scans, then least parent travel, then the first) on a map
    of the project (built-in or in experiments/), so that every --check can
    run it without the shared data; chosen by what the episode did, not by
    its wall time, so that a run again chooses the same."""
    own = [r for r in records if not r["episode"]["map"].startswith("../")]
    chosen = []
    for group in grouped(own, condition).values():
        chosen.append(min(group, key=lambda r: (summary(r)["scans"], summary(r)["parent_travel_m"],
                                                r["episode"]["index"])))
    chosen = chosen[:limit] if limit else chosen
    return [spot_of_record(r, EXPERIMENTS) for r in chosen]


def with_spots(figures, records, limit=None):
    figures[SPOTS] = spots(records, limit)
    return figures
