"""Wall times, page sizes and refusals that the user guide states (`timings`):
measured on this machine by --heavy and kept in the ledger. Wall times differ
between machines and runs, so no spot check re-runs them; the memory figures
are the estimates the refusals print, which do not."""

import os
import re
import resource
import subprocess
import time
from pathlib import Path

from .common import ROOT, cpsplan_binary, fixed, load, run, source

MEMORY = re.compile(r"estimated to need (\d+) MB")
POINTS = re.compile(r"model of (\d+) points")


def timed(*args, cwd, limit_bytes=None, expect_refusal=False):
    """Runs cpsplan; (seconds, stderr). With `limit_bytes`, under that
    address-space limit (`ulimit -v`)."""

    def limit():
        if limit_bytes:
            resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))

    start = time.monotonic()
    done = subprocess.run([cpsplan_binary(), *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          preexec_fn=limit)
    seconds = time.monotonic() - start
    if (done.returncode != 0) != expect_refusal:
        raise SystemExit(f"regen-docs: timings: `{' '.join(map(str, args))}` exited {done.returncode}:\n{done.stderr}")
    return seconds, done.stderr


def megabytes(path):
    return Path(path).stat().st_size / 1e6


@source("timings", "wall times of `bound` and `--html`, page sizes, and the refusals of models and sites too "
        "large for the memory", heavy=True, needs="maps")
def timings(tmp):
    tmp = Path(tmp)
    figures = {}
    # The known-map bound on the built-in maps and the campus.
    bound_s = {}
    for name, where in [("site", ["--builtin", "site"]), ("office", ["--builtin", "office"]),
                        ("tunnel", ["--builtin", "tunnel"]),
                        ("campus", ["--map", ROOT.parent / "shared" / "maps" / "cit_tsudanuma_campus.yaml"])]:
        run("bound", "-q", *where, "--out", tmp / f"bound-{name}", cwd=tmp)
        bound_s[name] = load(tmp / f"bound-{name}" / "bound.json")["wall_ms"] / 1000
    figures["bound_office_s"] = fixed(bound_s["office"], 0)
    figures["bound_campus_s"] = fixed(bound_s["campus"], 0)
    builtin = [bound_s[m] for m in ["site", "office", "tunnel"]]
    figures["bound_builtin_s"] = f"{min(builtin):.0f}–{max(builtin):.0f}"
    # What --html costs, and the page's size.
    overhead, pages = [], {}
    for name in ["site", "office", "tunnel"]:
        run("explore", "-q", "--builtin", name, "--out", tmp / f"plain-{name}", cwd=tmp)
        run("explore", "-q", "--builtin", name, "--html", "--out", tmp / f"html-{name}", cwd=tmp)
        plain = load(tmp / f"plain-{name}" / "summary.json")["wall_ms"]
        html = load(tmp / f"html-{name}" / "summary.json")["wall_ms"]
        overhead.append(html / plain - 1)
        pages[name] = megabytes(tmp / f"html-{name}" / "report.html")
    figures["html_overhead"] = f"{min(overhead) * 100:.0f}–{max(overhead) * 100:.0f}"
    figures["page_site_mb"] = fixed(pages["site"], 1)
    figures["site_scans"] = str(load(tmp / "html-site" / "summary.json")["scans"])
    figures["page_office_mb"] = fixed(pages["office"], 1)
    run("explore", "-q", "--builtin", "office", "--range", "4", "--html", "--out", tmp / "html-office-4m", cwd=tmp)
    figures["page_office_4m_mb"] = fixed(megabytes(tmp / "html-office-4m" / "report.html"), 1)
    figures["office_4m_scans"] = str(load(tmp / "html-office-4m" / "summary.json")["scans"])
    # A model too large for the memory allowed is refused before its first point.
    (tmp / "limit.toml").write_text("[limits]\nmax_memory_mb = 2000\n")
    seconds, said = timed("explore", "-q", "--config", tmp / "limit.toml", "--cloud-out", tmp / "walls.las",
                          "--wall-height", "10", "--vertical-step", "0.001", "--out", tmp / "walls",
                          cwd=tmp, expect_refusal=True)
    figures["model_refused_s"] = fixed(seconds, 1)
    figures["model_points_m"] = fixed(int(POINTS.search(said).group(1)) / 1e6, 0)
    figures["model_estimate_gb"] = fixed(int(MEMORY.search(said).group(1)) / 1000, 0)
    # A 1 km × 1 km site at 0.1 m under a 4 GB address-space limit.
    side = 10_000
    with open(tmp / "km.pgm", "wb") as f:
        f.write(f"P5\n{side} {side}\n255\n".encode())
        wall, free = b"\x00" * side, b"\x00" + b"\xfe" * (side - 2) + b"\x00"
        f.write(wall + free * (side - 2) + wall)
    seconds, said = timed("explore", "-q", "--map", tmp / "km.pgm", "--max-scans", "3", "--out", tmp / "km",
                          cwd=tmp, limit_bytes=4 << 30, expect_refusal=True)
    figures["km_refused_s"] = fixed(seconds, 1)
    figures["km_estimate_gb"] = fixed(int(MEMORY.search(said).group(1)) / 1000, 1)
    return figures


@source("build", "the README's two commands from a clean target directory: the first build, the test build and "
        "the test run (about a quarter of an hour on two cores)", heavy=True)
def build(tmp):
    """Times `cargo run --release -- explore`'s build, the test build and the
    tests, as a new user meets them (a target directory of their own; the
    crates already downloaded)."""
    env = dict(os.environ, CARGO_TARGET_DIR=str(Path(tmp) / "target"), CARGO_TERM_COLOR="never")

    def cargo(*args):
        start = time.monotonic()
        done = subprocess.run(["cargo", *args], cwd=ROOT, env=env, capture_output=True, text=True)
        if done.returncode != 0:
            raise SystemExit(f"regen-docs: build: `cargo {' '.join(args)}` failed:\n{done.stderr[-2000:]}")
        return time.monotonic() - start

    first = cargo("build", "--release", "--locked")
    tests_build = cargo("test", "--workspace", "--release", "--locked", "--no-run")
    tests_run = cargo("test", "--workspace", "--release", "--locked")
    return {
        "first_min": f"{first / 60:.0f}",
        "tests_build_min": f"{tests_build / 60:.0f}",
        "tests_run_min": f"{tests_run / 60:.0f}",
    }
