"""The Python package against the command line's own outputs: a simulated
campaign's records and knowledge map, and a live campaign fed the field data
of a simulation."""

import json

import numpy as np
import pytest

import cpsplan


def test_explore_returns_the_records_and_the_knowledge_map(tmp_path):
    run = cpsplan.explore(builtin="site", max_scans=3, out=tmp_path / "report")
    assert run.summary["scans"] == 3
    assert len(run.steps) == 3
    assert run.knowledge.dtype == np.int8
    assert run.knowledge.shape == (run.map["height"], run.map["width"])
    assert set(np.unique(run.knowledge)) <= {-1, 0, 100}
    # The first scan's cell is known free; row 0 is at the origin.
    res = run.map["resolution"]
    x, y = run.steps[0]["position"]["x"], run.steps[0]["position"]["y"]
    assert run.knowledge[int(y / res), int(x / res)] == 0
    # The same as the report's own files.
    summary = json.loads((tmp_path / "report" / "summary.json").read_text())
    assert summary["scans"] == run.summary["scans"]


def test_a_bad_flag_raises_with_the_one_line_message():
    with pytest.raises(cpsplan.CpsplanError, match="max-scans"):
        cpsplan.explore(builtin="site", max_scans=0)


def test_a_live_campaign_plans_from_the_field_data(tmp_path):
    field = tmp_path / "field"
    cpsplan.explore(builtin="site", max_scans=3, options=["--field-data", field])
    init = json.loads((field / "field.json").read_text())
    camp = cpsplan.Campaign.init(
        tmp_path / "camp",
        start=(init["start"]["x"], init["start"]["y"]),
        area=tuple(init["area"]),
        config=field / "config.toml",
    )
    for n in (1, 2):
        plan = camp.add(field / f"scan-{n:04d}.ply", field / f"readings-{n:04d}.csv")
        assert plan["scans"] == n
    assert camp.scans == 2
    assert plan["stop"] is None
    px, py = plan["next"]["position"]["x"], plan["next"]["position"]["y"]
    assert camp.knowledge[int(py / 0.1), int(px / 0.1)] == 0
    stations = camp.network["stations"]
    assert [s["name"] for s in stations][0] == "S0000"
    with pytest.raises(cpsplan.CpsplanError, match="not a cpsplan campaign"):
        cpsplan.Campaign(tmp_path)
    # An unknown point id is refused and changes nothing.
    bad = tmp_path / "bad.csv"
    lines = (field / "readings-0003.csv").read_text().splitlines()
    cols = lines[1].split(",")
    cols[1] = "X77"
    lines[1] = ",".join(cols)
    bad.write_text("\n".join(lines) + "\n")
    before = (tmp_path / "camp" / "campaign.json").read_bytes()
    with pytest.raises(cpsplan.CpsplanError, match="X77"):
        camp.add(field / "scan-0003.ply", bad)
    assert (tmp_path / "camp" / "campaign.json").read_bytes() == before
