"""What every source shares: running the `cpsplan` binary, reading its
files, the documents' number formats and the registry of sources."""

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
SHARED = ROOT.parent / "shared"


def cpsplan_binary():
    return os.environ.get("CPSPLAN", str(ROOT / "target" / "release" / "cpsplan"))


def run(*args, cwd):
    """Runs cpsplan quietly in `cwd`; stops the script if it fails."""
    cmd = [cpsplan_binary(), *map(str, args)]
    done = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"regen-docs: `{' '.join(cmd)}` failed:\n{done.stderr}")
    return done


def load(path):
    return json.loads(Path(path).read_text())


# -- Formatting, as the documents write figures. ---------------------------------


def count(n):
    """A whole number with thousands separators: 284,160."""
    return f"{int(n):,}"


def fixed(x, places):
    """A number to `places` decimals, with thousands separators: 1,033.6."""
    return f"{x:,.{places}f}"


def mm(metres, places=1):
    return fixed(metres * 1000.0, places)


def percent_share(share, places=1):
    """A share as a percentage that never reads 100 before it is whole, nor 0
    after it has begun (as the reports print it: `render::share_percent`)."""
    step = 10.0 ** -places
    shown = round(share * 100.0, places)
    if shown >= 100.0 and share < 1.0:
        shown = 100.0 - step
    elif shown <= 0.0 and share > 0.0:
        shown = step
    return f"{shown:.{places}f}"


# -- Sources: each runs what its figures need and returns them by name. -----------

SOURCES = {}

# The key of a source's figures under which it gives the pictures to copy into
# the documents' images when writing: {path in the project: file it made}.
IMAGES = "_images"


def source(name, what, needs=None, heavy=False, inputs=()):
    """Registers a source. `needs`: a directory of ../shared it reads. A heavy
    source (minutes to hours) runs only with --heavy; its figures and spot
    checks are kept in the ledger (`ledger.py`), which every other run checks
    the documents against. `inputs`: the project's files it runs (experiment
    files), whose digests the ledger keeps."""

    def register(fn):
        SOURCES[name] = {"fn": fn, "what": what, "needs": needs, "heavy": heavy, "inputs": list(inputs)}
        return fn

    return register


# The key of a heavy source's figures under which it gives its spot checks:
# single `explore` runs, cheap enough for every --check, whose figures must
# equal those of the heavy run (ledger.py).
SPOTS = "_spots"


# -- Statistics over seeds, as the documents state them. --------------------------


def median(values):
    """The median (the mean of the middle two for an even count), as
    `cpsplan report` takes it."""
    v = sorted(values)
    n = len(v)
    return v[n // 2] if n % 2 else (v[n // 2 - 1] + v[n // 2]) / 2


def spread(values, places, scale=1.0):
    """`least–most` of `values`, as the documents write a range."""
    lo, hi = min(values) * scale, max(values) * scale
    return f"{lo:.{places}f}–{hi:.{places}f}"


def median_range(values, places):
    """`median (least–most)`, the form of the medians over seeds; `—` for none."""
    if not values:
        return "—"
    return f"{median(values):,.{places}f} ({min(values):,.{places}f}–{max(values):,.{places}f})"


def mean_sd(values, places):
    """`mean ± sample standard deviation`."""
    m = sum(values) / len(values)
    if len(values) < 2:
        return f"{m:,.{places}f}"
    sd = (sum((x - m) ** 2 for x in values) / (len(values) - 1)) ** 0.5
    return f"{m:,.{places}f} ± {sd:,.{places}f}"


def mean(values):
    return sum(values) / len(values)


def ratio_range(values, places=1, suffix=""):
    """`a–b` of ratios, or one figure when they round alike."""
    lo, hi = f"{min(values):.{places}f}", f"{max(values):.{places}f}"
    return f"{lo}{suffix}" if lo == hi else f"{lo}–{hi}{suffix}"


# -- Words: claims the figures decide, as the documents state them. ------------------

BUILTIN = {"office", "site", "tunnel", "building"}


def called(m):
    """A map as the text names it: `the office`, `intel_lab`."""
    return f"the {m}" if m in BUILTIN else m


def listed(parts):
    """`a`, `a and b`, `a, b and c`."""
    return parts[0] if len(parts) == 1 else ", ".join(parts[:-1]) + " and " + parts[-1]


def places(maps, every):
    """`every map`, `the office and the site`, `no map`."""
    if not maps:
        return "no map"
    if len(maps) == len(every):
        return "every map"
    return listed([called(m) for m in maps])


def per_map(pairs):
    """`31 % on the office, 15 % on the site and 8 % on the tunnel`."""
    return listed([f"{text} on {called(m)}" for m, text in pairs])


# -- Episodes. ------------------------------------------------------------------------


def thetas(episode):
    """Eq. (2)'s angle θ of every child that moved, over an episode's cycles."""
    return [
        child["theta_deg"]
        for step in episode["steps"]
        for cycle in (step.get("move") or {}).get("cycles") or []
        for child in cycle["children"]
        if not child["stays"] and child.get("theta_deg") is not None
    ]


# -- Configurations as TOML (the records keep them as JSON). ------------------------


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    raise ValueError(f"no TOML for {v!r}")


def toml_of(config):
    """A configuration file of `config` (nested tables; nulls left out, which
    is their default)."""
    top, tables = [], []

    def table(prefix, d):
        lines = [f"{k} = {toml_value(v)}" for k, v in d.items() if v is not None and not isinstance(v, dict)]
        tables.append((prefix, lines))
        for k, v in d.items():
            if isinstance(v, dict):
                table(f"{prefix}.{k}" if prefix else k, v)

    table("", config)
    for prefix, lines in tables:
        if prefix:
            top.append(f"\n[{prefix}]")
        top.extend(lines)
    return "\n".join(top) + "\n"
