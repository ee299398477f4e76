"""The ledger of the heavy sources (`ledger.json` beside this file).

A heavy source runs whole experiments: hours on two cores, too long for CI.
`--heavy` runs it and keeps in the ledger what it gave: every figure, the
digest of each project file it ran (the experiment files), and a few *spot
checks*, single episodes of its runs as `explore` commands (with the
configuration they ran with, where not the defaults) and the figures they
ended with. Every other
run of the script then

- takes the source's figures from the ledger, so the documents are checked
  against the last heavy run;
- refuses a ledger whose experiment files have changed since;
- runs the spot checks that need no shared data (episodes on the built-in
  maps, seconds each) and compares their figures with the ledger's to nine
  significant digits. A change to the planner that moves an episode fails
  here, and the figures must be measured again with `--heavy`.
"""

import hashlib
import json
from pathlib import Path

from .common import ROOT, SHARED, load, run, toml_of

LEDGER = Path(__file__).resolve().parent / "ledger.json"

# The figures of an episode a spot check compares.
SPOT_FIELDS = ["scans", "parent_travel_m", "campaign_time_h", "final_position_sigma_m", "coverage", "cps_cycles"]


def read():
    return load(LEDGER) if LEDGER.exists() else {}


def write(ledger):
    staged = LEDGER.with_suffix(".json.regen")
    staged.write_text(json.dumps(ledger, indent=1, sort_keys=True, ensure_ascii=False) + "\n")
    staged.replace(LEDGER)


def digest(relative):
    return hashlib.sha256((ROOT / relative).read_bytes()).hexdigest()


def digests(inputs):
    return {path: digest(path) for path in inputs}


def spot_of_record(record, experiment_dir):
    """The spot check of one experiment record: `explore` on its map from its
    start with its whole configuration, and the figures it ended with."""
    episode = record["episode"]
    where = episode["map"]
    if where.startswith("builtin:"):
        args = ["--builtin", where.split(":", 1)[1]]
    else:
        path = (experiment_dir / where).resolve()
        try:
            args = ["--map", str(path.relative_to(ROOT))]
        except ValueError:
            args = ["--map", "../shared/" + str(path.relative_to(SHARED.resolve()))]
    start = episode["start"]
    if start is not None:
        args += ["--start", f"{start['x']!r},{start['y']!r}"]
    summary = record["outcome"]["summary"]
    return {
        "label": episode["label"],
        "args": args,
        "config": episode["config"],
        "expect": {k: summary[k] for k in SPOT_FIELDS},
    }


def needs_shared(spot):
    return any(str(a).startswith("../shared/") for a in spot["args"])


def figure(v):
    return "null" if v is None else f"{v:.9g}"


def check_spot(spot, tmp):
    """Runs one spot check in `tmp` (a directory of its own); the figures that
    differ, as (field, ledger, run)."""
    tmp = Path(tmp)
    config = []
    if spot.get("config") is not None:
        (tmp / "spot.toml").write_text(toml_of(spot["config"]))
        config = ["--config", tmp / "spot.toml"]
    out = tmp / "spot"
    args = [a if not a.startswith(("experiments/", "../shared/")) else str((ROOT / a).resolve()) for a in spot["args"]]
    run("explore", "-q", *args, *config, "--out", out, cwd=tmp)
    got = load(out / "summary.json")
    return [
        (k, figure(v), figure(got[k])) for k, v in spot["expect"].items() if figure(v) != figure(got[k])
    ]
