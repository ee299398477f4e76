"""cpsplan from Python: simulated campaigns and a real team's live campaign.

    import cpsplan

    run = cpsplan.explore(map="site", seed=0)
    run.summary["scans"], run.knowledge.shape      # dict, numpy int8 (rows from y = 0)

    camp = cpsplan.Campaign.init("camp/", start=(5.05, 5.05), area=(0, 0, 80, 60))
    plan = camp.add("scan-0001.ply", "readings-0001.csv")
    plan["next"]["position"]                      # where the parent scans next

Everything runs the same code as the `cpsplan` command (``cpsplan.run``), in
this process; a failure raises ``CpsplanError`` with the command's one-line
message. Knowledge maps are NumPy ``int8`` arrays as in ROS
``nav_msgs/OccupancyGrid``: 0 free, 100 occupied, -1 unknown, row ``i`` at
``y = origin_y + (i + 0.5) * resolution``.
"""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np

from ._cpsplan import CpsplanError, run as _run

__all__ = ["CpsplanError", "Episode", "Campaign", "explore", "run", "read_map"]

PathLike = Union[str, os.PathLike]


def run(*args: Any) -> None:
    """Runs ``cpsplan ARGS...`` (e.g. ``run("maps", "--export", "maps/")``)."""
    _run([str(a) for a in args])


def read_map(yaml: PathLike) -> Tuple[np.ndarray, dict]:
    """A ROS map_server map written by cpsplan (trinary PGM): the cells as an
    ``int8`` array (0 free, 100 occupied, -1 unknown; row 0 at the origin) and
    the YAML's ``resolution`` and ``origin``."""
    yaml = Path(yaml)
    meta = {}
    for line in yaml.read_text().splitlines():
        if ":" in line and not line.lstrip().startswith("#"):
            key, value = line.split(":", 1)
            meta[key.strip()] = value.strip()
    image = yaml.parent / meta["image"].strip("\"'")
    data = image.read_bytes()
    header = []
    pos = 0
    while len(header) < 4:
        # P5, width, height, maxval: whitespace separated, comments skipped.
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        header.append(data[pos:end])
        pos = end
    pos += 1
    width, height = int(header[1]), int(header[2])
    pixels = np.frombuffer(data, dtype=np.uint8, count=width * height, offset=pos)
    pixels = pixels.reshape(height, width)[::-1]
    cells = np.full(pixels.shape, -1, dtype=np.int8)
    cells[pixels == 254] = 0
    cells[pixels == 0] = 100
    origin = [float(v) for v in meta["origin"].strip("[]").split(",")]
    return cells, {"resolution": float(meta["resolution"]), "origin": origin}


@dataclass
class Episode:
    """A simulated campaign: ``summary`` and ``steps`` as in ``summary.json``
    and ``episode.json``, the final ``knowledge`` map, and where its report is
    (``report``, kept only when ``explore(out=...)`` named it)."""

    summary: dict
    steps: list
    knowledge: np.ndarray
    map: dict
    config: dict
    report: Optional[Path] = None
    episode: dict = field(default_factory=dict, repr=False)


def explore(
    map: Optional[PathLike] = None,
    builtin: Optional[str] = None,
    start: Optional[Tuple[float, float]] = None,
    seed: Optional[int] = None,
    max_scans: Optional[int] = None,
    config: Optional[PathLike] = None,
    out: Optional[PathLike] = None,
    options: Sequence[str] = (),
) -> Episode:
    """Simulates a whole campaign (``cpsplan explore``) on a map file or a
    built-in map (``"site"`` by default; ``"office"``, ``"tunnel"``), and
    returns it. ``options`` are further command-line flags, e.g.
    ``["--planner", "paper"]``."""
    args = ["explore", "--quiet"]
    if map is not None and builtin is not None:
        raise ValueError("give map or builtin, not both")
    if map is not None:
        args += ["--map", os.fspath(map)]
    elif builtin is not None:
        args += ["--builtin", builtin]
    if start is not None:
        args += ["--start", f"{start[0]},{start[1]}"]
    if seed is not None:
        args += ["--seed", str(seed)]
    if max_scans is not None:
        args += ["--max-scans", str(max_scans)]
    if config is not None:
        args += ["--config", os.fspath(config)]
    args += [str(o) for o in options]
    with tempfile.TemporaryDirectory() as tmp:
        report = Path(out) if out is not None else Path(tmp) / "report"
        run(*args, "--out", report)
        episode = json.loads((report / "episode.json").read_text())
        summary = json.loads((report / "summary.json").read_text())
        knowledge, _ = read_map(report / "knowledge.yaml")
    return Episode(
        summary=summary,
        steps=episode["steps"],
        knowledge=knowledge,
        map=episode.get("map", {}),
        config=episode.get("config", {}),
        report=Path(out) if out is not None else None,
        episode=episode,
    )


class Campaign:
    """A real team's campaign directory (``cpsplan campaign``)."""

    def __init__(self, dir: PathLike):
        self.dir = Path(dir)
        if not (self.dir / "campaign.json").is_file():
            raise CpsplanError(f"{self.dir} is not a cpsplan campaign (no campaign.json)")

    @classmethod
    def init(
        cls,
        dir: PathLike,
        start: Tuple[float, float],
        area: Optional[Tuple[float, float, float, float]] = None,
        heading: float = 0.0,
        prior: Optional[PathLike] = None,
        config: Optional[PathLike] = None,
        seed: Optional[int] = None,
    ) -> "Campaign":
        """Creates the campaign directory (``cpsplan campaign init``)."""
        args = ["campaign", "init", os.fspath(dir), "--start", f"{start[0]},{start[1]}",
                "--heading", str(heading)]
        if area is not None:
            args += ["--area", ",".join(str(v) for v in area)]
        if prior is not None:
            args += ["--prior", os.fspath(prior)]
        if config is not None:
            args += ["--config", os.fspath(config)]
        if seed is not None:
            args += ["--seed", str(seed)]
        run(*args)
        return cls(dir)

    def add(self, scan: PathLike, readings: PathLike, mcap_out: Optional[PathLike] = None) -> dict:
        """Adds one scan (its cloud and the readings since the scan before) and
        returns the plan: ``next.json`` as a dict."""
        args = ["campaign", "add", self.dir, "--scan", os.fspath(scan),
                "--readings", os.fspath(readings), "--quiet"]
        if mcap_out is not None:
            args += ["--mcap-out", os.fspath(mcap_out)]
        run(*args)
        return self.next

    @property
    def next(self) -> dict:
        """The next step (``next.json``)."""
        return json.loads((self.dir / "next.json").read_text())

    @property
    def network(self) -> dict:
        """Every station and point adjusted (``network.json``)."""
        return json.loads((self.dir / "network.json").read_text())

    @property
    def knowledge(self) -> np.ndarray:
        """The knowledge map after the last scan."""
        return read_map(self.dir / "knowledge.yaml")[0]

    @property
    def scans(self) -> int:
        """Scans so far."""
        return len(json.loads((self.dir / "campaign.json").read_text())["scans"])
