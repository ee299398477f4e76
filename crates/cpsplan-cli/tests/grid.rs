//! `cpsplan grid` end to end: the four shared real clouds (one per format) become
//! maps that `explore` runs on to completion and `plan` plans a step on;
//! broken clouds and absurd parameters are refused with one line, exit code 2,
//! and nothing written.

use std::path::{Path, PathBuf};

use cpsplan::CellState;
use cpsplan_cli::formats::rosmap::load_map;
use serde_json::Value;

mod common;
use common::{cpsplan, skipped};

/// A shared cloud, or `None` with a visible SKIPPED line when the shared data
/// is absent.
fn shared(name: &str, test: &str) -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/clouds")
        .join(name);
    if p.is_file() {
        return Some(p);
    }
    skipped(test, "the shared clouds in ../shared/clouds (see README)")
}

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("readable")).expect("JSON")
}

/// Converts `cloud` with `flags`, checks the map, explores it to completion and
/// plans one step on its first knowledge map. Returns the grid command's output.
fn convert_explore_plan(
    cloud: &Path,
    flags: &[&str],
    explore_flags: &[&str],
    min_free: usize,
    min_occupied: usize,
) -> String {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("map.yaml");
    let out = cpsplan()
        .args(["grid", "--cloud", s(cloud), "--out", s(&map)])
        .args(flags)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for needle in [
        "points read",
        "kept",
        "free",
        "occupied",
        "unknown",
        "cells of",
    ] {
        assert!(text.contains(needle), "`{needle}` not in {text}");
    }
    let grid = load_map(&map).expect("the map loads");
    let (free, occ) = (grid.count(CellState::Free), grid.count(CellState::Occupied));
    assert!(
        free >= min_free && occ >= min_occupied,
        "{free} free, {occ} occupied"
    );
    let report = dir.path().join("report");
    let run = cpsplan()
        .args(["explore", "--map", s(&map), "--out", s(&report), "-q"])
        .args(explore_flags)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let summary = json(&report.join("summary.json"));
    assert!(summary["scans"].as_u64().unwrap() >= 1);
    let stop = summary["stop_reason"].as_str().unwrap().to_string();
    assert!(
        [
            "complete",
            "frontier_below_threshold",
            "no_reachable_frontier"
        ]
        .contains(&stop.as_str()),
        "{stop}"
    );
    // One step for the team as it stood at the first scan.
    let episode = json(&report.join("episode.json"));
    let start = &episode["start"];
    let parent = format!("{},{}", start["x"], start["y"]);
    let mut plan = cpsplan();
    plan.args([
        "plan",
        "--known",
        s(&report.join("knowledge.yaml")),
        "--parent",
        &parent,
    ]);
    // The planning resolution of the run, if a flag set it.
    if let Some(i) = explore_flags.iter().position(|f| *f == "--resolution") {
        plan.args(["--resolution", explore_flags[i + 1]]);
    }
    for c in episode["steps"][0]["children"].as_array().unwrap() {
        plan.args(["--child", &format!("{},{}", c["x"], c["y"])]);
    }
    let planned = plan.output().unwrap();
    assert!(
        planned.status.success(),
        "{}",
        String::from_utf8_lossy(&planned.stderr)
    );
    let step: Value = serde_json::from_slice(&planned.stdout).expect("plan prints JSON");
    assert!(step.is_object());
    text
}

#[test]
fn pcd_room_scan_converts_and_explores() {
    let Some(cloud) = shared("pcl_room_scan1.pcd", "pcd_room_scan_converts_and_explores") else {
        return;
    };
    convert_explore_plan(&cloud, &["--free-from-scans"], &[], 5_000, 1_000);
}

#[test]
fn pcd_velodyne_sweep_converts_and_explores() {
    let Some(cloud) = shared(
        "velodyne_outdoor_scan_251370668.pcd",
        "pcd_velodyne_sweep_converts_and_explores",
    ) else {
        return;
    };
    convert_explore_plan(&cloud, &["--free-from-scans"], &[], 20_000, 2_000);
}

#[test]
fn laz_airborne_survey_in_feet_converts_to_metres_and_explores() {
    let Some(cloud) = shared(
        "autzen_trim.laz",
        "laz_airborne_survey_in_feet_converts_to_metres_and_explores",
    ) else {
        return;
    };
    let text = convert_explore_plan(
        &cloud,
        &["--resolution", "1", "--height-above-ground", "1,60"],
        &["--resolution", "0.5", "--range", "40"],
        10_000,
        1_000,
    );
    assert!(
        text.contains("feet"),
        "the unit conversion is reported: {text}"
    );
    // 1177 ft × 563 ft is about 359 m × 172 m.
    let width: f64 = text
        .split("cells of 1 m (")
        .nth(1)
        .and_then(|t| t.split(" m").next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("map size in {text}"));
    assert!((355.0..370.0).contains(&width), "{width} m wide");
}

#[test]
fn e57_terrestrial_scan_converts_and_explores() {
    let Some(cloud) = shared(
        "pump_room_scan.e57",
        "e57_terrestrial_scan_converts_and_explores",
    ) else {
        return;
    };
    convert_explore_plan(&cloud, &["--free-from-scans"], &[], 500, 200);
}

/// `grid` with `args` fails with exit code 2 and one line containing every
/// needle, and writes nothing into the output's directory.
fn refused(args: &[&str], needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("map.yaml");
    let out = cpsplan()
        .args(["grid", "--out", s(&map)])
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in {err}");
    }
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "{args:?} left {left:?}");
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

const ROOM_PCD: &str = "# .PCD v0.7
VERSION 0.7
FIELDS x y z
SIZE 4 4 4
TYPE F F F
COUNT 1 1 1
WIDTH 4
HEIGHT 1
VIEWPOINT 0 0 0 1 0 0 0
POINTS 4
DATA ascii
0 0 -1
1 0 -1
0 1 0.5
1 1 0.5
";

#[test]
fn broken_clouds_and_absurd_parameters_are_refused_cleanly() {
    let src = tempfile::tempdir().unwrap();
    let d = src.path();
    let good = write(d, "room.pcd", ROOM_PCD.as_bytes());
    let nan = write(
        d,
        "nan.pcd",
        ROOM_PCD.replace("1 1 0.5", "1 nan 0.5").as_bytes(),
    );
    let empty = write(d, "empty.ply", b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
    let garbage = write(d, "garbage.las", b"LASF this is not a LAS file at all");
    let nothing = write(d, "nothing.e57", b"");
    refused(&["--cloud", s(&nan)], &["nan.pcd", "NaN"]);
    refused(&["--cloud", s(&empty)], &["empty.ply", "no points"]);
    refused(&["--cloud", s(&garbage)], &["garbage.las"]);
    refused(&["--cloud", s(&nothing)], &["nothing.e57"]);
    refused(&["--cloud", s(&d.join("missing.laz"))], &["missing.laz"]);
    refused(&["--cloud", s(&write(d, "x.xyz", b"1 2 3"))], &["x.xyz"]);
    for r in ["0", "-1", "nan"] {
        refused(&["--cloud", s(&good), "--resolution", r], &["--resolution"]);
    }
    // So fine that the grid would exceed the cell limit: 1e5 × 1e5 cells.
    let wide = write(
        d,
        "wide.pcd",
        ROOM_PCD.replace("1 1 0.5", "100 100 0.5").as_bytes(),
    );
    refused(
        &["--cloud", s(&wide), "--resolution", "0.001"],
        &["limits.max_grid_cells"],
    );
    refused(
        &["--cloud", s(&good), "--resolution", "0.00001"],
        &["--resolution"],
    );
    refused(
        &["--cloud", s(&good), "--height-above-ground", "2,1"],
        &["--height-above-ground"],
    );
    refused(
        &["--cloud", s(&good), "--min-points", "0"],
        &["--min-points"],
    );
    refused(
        &["--cloud", s(&good), "--free-from-scans", "--origin", "1,2"],
        &["--origin"],
    );
    // Every shared cloud cut short.
    for name in [
        "autzen_trim.laz",
        "pump_room_scan.e57",
        "pcl_room_scan1.pcd",
        "velodyne_outdoor_scan_251370668.pcd",
    ] {
        let Some(path) = shared(
            name,
            "broken_clouds_and_absurd_parameters_are_refused_cleanly",
        ) else {
            continue;
        };
        let bytes = std::fs::read(path).unwrap();
        let cut_name = format!("cut-{name}");
        let cut = write(d, &cut_name, &bytes[..bytes.len() / 2]);
        refused(&["--cloud", s(&cut)], &[&cut_name]);
    }
    // The good file converts, with the NaN one skipped when asked.
    let out = tempfile::tempdir().unwrap();
    let ok = cpsplan()
        .args([
            "grid",
            "--cloud",
            s(&nan),
            "--drop-invalid",
            "--out",
            s(&out.path().join("m.yaml")),
        ])
        .args(["--z-min", "0", "--z-max", "1"])
        .output()
        .unwrap();
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let grid = load_map(&out.path().join("m.yaml")).unwrap();
    assert_eq!(grid.count(CellState::Occupied), 1);
    assert_eq!(grid.count(CellState::Free), 2);
}

/// The airborne scan at 0.5 m leaves gaps between the scan lines (unknown
/// cells between free ones, a wall to sight and to the robots): `grid` warns
/// and names the resolution that mends it; at that resolution, and for the
/// terrestrial scans with `--free-from-scans`, it says nothing.
#[test]
fn a_fragmented_free_space_is_warned_with_its_fix() {
    let test = "a_fragmented_free_space_is_warned_with_its_fix";
    let Some(autzen) = shared("autzen_trim.laz", test) else {
        return;
    };
    let out = tempfile::tempdir().unwrap();
    let grid = |cloud: &Path, extra: &[&str]| {
        let run = cpsplan()
            .args(["grid", "-q", "--cloud", s(cloud), "--out"])
            .arg(out.path().join("m.yaml"))
            .args(extra)
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        String::from_utf8_lossy(&run.stderr).into_owned()
    };
    let band = ["--height-above-ground", "1,60"];
    let err = grid(&autzen, &[&band[..], &["--resolution", "0.5"]].concat());
    for needle in [
        "warning: the free space is fragmented",
        "% of it is gaps",
        "--resolution 1 leaves",
    ] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!grid(&autzen, &[&band[..], &["--resolution", "1"]].concat()).contains("fragmented"));
    for (name, extra) in [
        ("pcl_room_scan1.pcd", &["--free-from-scans"][..]),
        (
            "velodyne_outdoor_scan_251370668.pcd",
            &["--free-from-scans"][..],
        ),
        (
            "pump_room_scan.e57",
            &["--free-from-scans", "--resolution", "0.05"][..],
        ),
    ] {
        let Some(path) = shared(name, test) else {
            continue;
        };
        assert!(!grid(&path, extra).contains("fragmented"), "{name}");
    }
}
