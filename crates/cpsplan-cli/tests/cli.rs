//! End-to-end tests of the `cpsplan` command: a full episode on a built-in map,
//! every bad-input case (exit code 2, one clear line, no output written), the
//! `maps` command, and exploration of the shared real maps.

use std::path::{Path, PathBuf};

use serde_json::Value;

mod common;
use common::{cpsplan, skipped, summary};

/// The shared real maps (`../shared/maps` beside the project), or `None` after
/// saying, past the test harness's capture, that `test` is skipped.
fn shared_maps(test: &str) -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/maps");
    if p.is_dir() {
        return Some(p);
    }
    skipped(test, "the shared real maps in ../shared/maps (see README)")
}

/// Every CPS link of the episode in `dir` (each child's spot to the parent's
/// positions before and after its cycle) is checked on the ground truth `truth`:
/// no cell whose full square the line touches is anything but free. Returns the
/// number of links checked.
fn links_clear_on_truth(dir: &Path, truth: &cpsplan::OccupancyGrid) -> usize {
    let text = std::fs::read_to_string(dir.join("episode.json")).expect("episode.json");
    let e: Value = serde_json::from_str(&text).expect("valid JSON");
    let g = *truth.geometry();
    let cell = |p: &Value| {
        let pt = cpsplan::Point::new(p["x"].as_f64().unwrap(), p["y"].as_f64().unwrap());
        g.world_to_cell(pt).expect("inside the map")
    };
    let free = |i: usize| truth.cells()[i] == cpsplan::CellState::Free;
    let mut links = 0;
    for step in e["steps"].as_array().unwrap() {
        for cycle in step["move"]["cycles"].as_array().unwrap() {
            let parents = [cell(&cycle["parent_from"]), cell(&cycle["parent_to"])];
            for child in cycle["children"].as_array().unwrap() {
                let c = cell(&child["to"]);
                for p in parents {
                    assert!(
                        cpsplan::grid::line::segment_clear(&g, c, p, free),
                        "{}: the link {c:?} -> {p:?} touches a cell that is not free",
                        dir.display()
                    );
                    links += 1;
                }
            }
        }
    }
    links
}

/// The ground truth of a shared map at the default planning resolution.
fn shared_truth(yaml: &Path) -> cpsplan::OccupancyGrid {
    let grid = cpsplan_cli::formats::rosmap::load_map(yaml).expect("map loads");
    cpsplan::world::resample_conservative(&grid, 0.1).solidified()
}

/// Runs `explore` and asserts a clean failure: exit 2, one line naming `needle`,
/// and no output directory.
fn assert_rejected(args: &[&str], needle: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let result = cpsplan()
        .arg("explore")
        .args(args)
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .output()
        .unwrap();
    assert_eq!(result.status.code(), Some(2), "args {args:?}");
    let err = String::from_utf8_lossy(&result.stderr);
    assert!(
        err.contains(needle),
        "stderr for {args:?} lacks `{needle}`: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "output written for rejected input {args:?}");
}

#[test]
fn explore_builtin_site_writes_every_output() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("report");
    cpsplan()
        .args(["explore", "--builtin", "site", "--quiet", "--out"])
        .arg(&out)
        .assert()
        .success();
    for f in [
        "summary.json",
        "episode.json",
        "metrics.csv",
        "map.png",
        "knowledge.yaml",
        "knowledge.pgm",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let s = summary(&out);
    assert!(s["coverage"].as_f64().unwrap() >= 0.99, "{s}");
    assert!(s["wall_coverage"].as_f64().unwrap() >= 0.97, "{s}");
    // The stop rule in square metres ends the episode when no position would
    // add 0.1 % of the known free area (or when no border is left).
    let stop = s["stop_reason"].as_str().unwrap();
    assert!(["complete", "no_reachable_frontier"].contains(&stop), "{s}");
    let scans = s["scans"].as_u64().unwrap() as usize;
    for key in ["parent_travel_m", "seed", "wall_ms"] {
        assert!(s.get(key).is_some(), "summary lacks {key}");
    }
    // The process's peak memory, where the system reports it.
    let peak = s["peak_memory_mb"].as_f64();
    if cfg!(target_os = "linux") {
        assert!(peak.is_some_and(|mb| mb > 1.0 && mb < 4096.0), "{s}");
    } else {
        assert!(s.get("peak_memory_mb").is_some(), "{s}");
    }
    // The estimate made before the run, at the scans it took: within a factor
    // of two of the measured peak on this small map.
    let estimate = s["estimated_memory_mb"].as_f64().unwrap();
    if let Some(mb) = peak {
        assert!(estimate > mb / 2.0 && estimate < mb * 2.0, "{s}");
    }
    // The campaign clock: its parts add up, the scans take 3 minutes each.
    let t = &s["campaign_time"];
    let parts: f64 = ["scan_h", "measure_h", "drive_h"]
        .iter()
        .map(|k| t[k].as_f64().unwrap())
        .sum();
    assert!(
        (s["campaign_time_h"].as_f64().unwrap() - parts).abs() < 1e-9,
        "{s}"
    );
    assert!((t["scan_h"].as_f64().unwrap() - scans as f64 * 180.0 / 3600.0).abs() < 1e-9);
    assert!(t["measure_h"].as_f64().unwrap() > 0.0 && t["drive_h"].as_f64().unwrap() > 0.0);
    assert_eq!(s["planner"], "tour", "the default planner");
    // Two children by default: every move ran as CPS cycles, some with subgoals.
    assert_eq!(s["child_travel_m"].as_array().unwrap().len(), 2, "{s}");
    assert!(
        s["cps_cycles"].as_u64().unwrap() as usize + 1 >= scans,
        "{s}"
    );
    let retrievals = s["subgoal_retrievals"].as_u64().unwrap();
    assert!(retrievals > 0, "{s}");
    let site = cpsplan::world::builtin::BuiltinMap::Site
        .generate(0)
        .solidified();
    assert!(links_clear_on_truth(&out, &site) > 0);
    // Every step carries its predicted accuracy; the first scan is the known start.
    let ep0: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("episode.json")).unwrap()).unwrap();
    let first = &ep0["steps"][0];
    assert_eq!(first["position_sigma_m"].as_f64(), Some(0.0));
    let last = &ep0["steps"][scans - 1];
    let cov = last["covariance_m2"].as_array().unwrap();
    let (xx, yy) = (cov[0][0].as_f64().unwrap(), cov[1][1].as_f64().unwrap());
    let sigma = last["position_sigma_m"].as_f64().unwrap();
    assert!((sigma - (xx + yy).sqrt()).abs() < 1e-12);
    assert_eq!(s["final_position_sigma_m"].as_f64(), Some(sigma));
    assert!(last["heading_sigma_arcsec"].as_f64().unwrap() > 0.0);
    // episode.json: one step per scan, candidates with their Eq. (1) terms, paths.
    let ep: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("episode.json")).unwrap()).unwrap();
    let steps = ep["steps"].as_array().unwrap();
    assert_eq!(steps.len(), scans);
    let first = &steps[0]["plan"];
    let cand = &first["candidates"][0];
    for key in ["r", "p", "l_m", "s_cells", "g"] {
        assert!(cand.get(key).is_some(), "candidate lacks {key}");
    }
    assert!(first["path"].as_array().unwrap().len() >= 2);
    // The record shows each retrieval: a move of two or more cycles, each leg
    // ending where the next begins.
    let retrieved: Vec<&Value> = steps
        .iter()
        .filter(|s| s["move"]["subgoal_retrieval"] == true)
        .collect();
    assert_eq!(retrieved.len() as u64, retrievals);
    for step in retrieved {
        let cycles = step["move"]["cycles"].as_array().unwrap();
        assert!(cycles.len() >= 2, "{}", step["scan"]);
        for pair in cycles.windows(2) {
            assert_eq!(pair[0]["parent_to"], pair[1]["parent_from"]);
        }
        // The Visibility Graph path the subgoals came from runs from the parent
        // to the target.
        let graph = step["move"]["graph_path"].as_array().unwrap();
        assert!(graph.len() >= 2, "{}", step["scan"]);
        assert_eq!(graph[0], cycles[0]["parent_from"]);
        assert_eq!(
            graph[graph.len() - 1],
            cycles[cycles.len() - 1]["parent_to"]
        );
    }
    // metrics.csv: a header and one row per scan.
    let csv = std::fs::read_to_string(out.join("metrics.csv")).unwrap();
    assert_eq!(csv.lines().count(), scans + 1);
    // Every scan records what it added and, after the first, what the round that
    // chose it expected; the clock runs forward to the campaign's time.
    let steps = ep0["steps"].as_array().unwrap();
    let mut clock = 0.0;
    for (k, st) in steps.iter().enumerate() {
        let new_free = st["outcome"]["new_free"].as_f64().unwrap();
        assert!((st["gain_m2"].as_f64().unwrap() - new_free * 0.01).abs() < 1e-9);
        assert_eq!(st["expected_gain_m2"].is_null(), k == 0, "scan {}", k + 1);
        assert_eq!(st["expected_s_cells"].is_null(), k == 0, "scan {}", k + 1);
        let c = st["clock_h"].as_f64().unwrap();
        assert!(c > clock, "scan {}: clock {c} after {clock}", k + 1);
        clock = c;
    }
    assert!(clock <= s["campaign_time_h"].as_f64().unwrap() + 1e-9);
    // The knowledge map is a loadable ROS map of the same size.
    let k = cpsplan_cli::formats::rosmap::load_map(&out.join("knowledge.yaml")).unwrap();
    assert_eq!((k.width(), k.height()), (800, 600));
}

/// Every built-in map is explored to completion with the default two children.
#[test]
fn builtin_maps_are_explored_with_children() {
    for map in ["office", "tunnel"] {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join(map);
        cpsplan()
            .args(["explore", "--quiet", "--builtin", map, "--out"])
            .arg(&out)
            .assert()
            .success();
        let s = summary(&out);
        // Done: no border left, only fragments below parent.min_frontier_cells,
        // or no position that would add 0.1 % of the known free area.
        let stop = s["stop_reason"].as_str().unwrap();
        assert!(
            [
                "complete",
                "frontier_below_threshold",
                "no_reachable_frontier"
            ]
            .contains(&stop),
            "{map}: {s}"
        );
        assert!(s["coverage"].as_f64().unwrap() >= 0.99, "{map}: {s}");
        assert!(s["wall_coverage"].as_f64().unwrap() >= 0.97, "{map}: {s}");
        let scans = s["scans"].as_u64().unwrap();
        assert!(s["cps_cycles"].as_u64().unwrap() + 1 >= scans, "{map}: {s}");
        let builtin: cpsplan::world::builtin::BuiltinMap = map.parse().unwrap();
        let truth = builtin.generate(0).solidified();
        assert!(links_clear_on_truth(&out, &truth) > 0, "{map}: no links");
        // The accuracy model's figures.
        let sigma = s["final_position_sigma_m"].as_f64().unwrap();
        assert!(sigma > 0.0 && sigma < 10.0, "{map}: σ {sigma}");
        let pct = s["error_percent_of_travel"].as_f64().unwrap();
        let travel = s["parent_travel_m"].as_f64().unwrap();
        assert!((pct - 100.0 * sigma / travel).abs() < 1e-9, "{map}: {s}");
        assert!(out.join("error.png").is_file() && out.join("error.svg").is_file());
    }
}

#[test]
fn children_run_cps_cycles() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("cps");
    cpsplan()
        .args([
            "explore",
            "--builtin",
            "tunnel",
            "--children",
            "2",
            "--max-scans",
            "6",
            "--quiet",
            "--out",
        ])
        .arg(&out)
        .assert()
        .success();
    let s = summary(&out);
    let scans = s["scans"].as_u64().unwrap();
    assert!(s["cps_cycles"].as_u64().unwrap() + 1 >= scans, "{s}");
    let child_travel = s["child_travel_m"].as_array().unwrap();
    assert_eq!(child_travel.len(), 2);
    assert!(child_travel.iter().all(|t| t.as_f64().unwrap() >= 0.0));
    let ep: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("episode.json")).unwrap()).unwrap();
    let cycle = &ep["steps"][0]["move"]["cycles"][0];
    for key in ["parent_from", "parent_to", "parent_path", "children"] {
        assert!(cycle.get(key).is_some(), "cycle lacks {key}");
    }
    assert_eq!(cycle["children"].as_array().unwrap().len(), 2);
}

#[test]
fn same_seed_gives_identical_episode_records() {
    let tmp = tempfile::tempdir().unwrap();
    let run = |name: &str| {
        let out = tmp.path().join(name);
        cpsplan()
            .args([
                "explore",
                "--builtin",
                "tunnel",
                "--max-scans",
                "8",
                "--seed",
                "3",
                "--quiet",
                "--out",
            ])
            .arg(&out)
            .assert()
            .success();
        std::fs::read(out.join("episode.json")).unwrap()
    };
    assert_eq!(run("a"), run("b"));
}

#[test]
fn config_file_and_flags_are_applied() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = tmp.path().join("run.toml");
    std::fs::write(&cfg, "[parent]\nalpha = 0.0\n[scanner]\nrange = 12.0\n").unwrap();
    let out = tmp.path().join("out");
    cpsplan()
        .args([
            "explore",
            "--builtin",
            "office",
            "--max-scans",
            "3",
            "--beta",
            "0.002",
            "--quiet",
            "--config",
        ])
        .arg(&cfg)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let s = summary(&out);
    assert_eq!(s["config"]["parent"]["alpha"], 0.0);
    assert_eq!(s["config"]["parent"]["beta"], 0.002);
    assert_eq!(s["config"]["scanner"]["range"], 12.0);
    assert_eq!(s["stop_reason"], "scan_limit");
    assert_eq!(s["scans"], 3);
}

#[test]
fn bad_inputs_are_rejected_cleanly() {
    let tmp = tempfile::tempdir().unwrap();
    let missing = tmp.path().join("nope.yaml");
    assert_rejected(&["--map", missing.to_str().unwrap()], "nope.yaml");
    let garbage = tmp.path().join("garbage.yaml");
    std::fs::write(
        &garbage,
        "image: x.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n",
    )
    .unwrap();
    assert_rejected(&["--map", garbage.to_str().unwrap()], "x.pgm");
    let bad_cfg = tmp.path().join("bad.toml");
    std::fs::write(&bad_cfg, "[parent]\nalfa = 1\n").unwrap();
    assert_rejected(&["--config", bad_cfg.to_str().unwrap()], "alfa");
    assert_rejected(&["--range", "-5"], "scanner.range");
    assert_rejected(&["--resolution", "0"], "resolution");
    assert_rejected(&["--start", "-50,3"], "outside the map");
    assert_rejected(&["--start", "1000,1000"], "outside the map");
    // (0.05, 0.05) is in the office's solid border.
    assert_rejected(&["--start", "0.05,0.05"], "not free space");
    assert_rejected(&["--start", "abc"], "X,Y");
    assert_rejected(&["--builtin", "moon"], "moon");
}

#[test]
fn maps_lists_and_exports() {
    let listing = cpsplan().arg("maps").output().unwrap();
    assert!(listing.status.success());
    let text = String::from_utf8_lossy(&listing.stdout);
    for name in ["office", "site", "tunnel"] {
        assert!(text.contains(name));
    }
    let tmp = tempfile::tempdir().unwrap();
    cpsplan()
        .args(["maps", "--export"])
        .arg(tmp.path())
        .assert()
        .success();
    for name in ["office", "site", "tunnel"] {
        let grid = cpsplan_cli::formats::rosmap::load_map(&tmp.path().join(format!("{name}.yaml")))
            .unwrap();
        let builtin: cpsplan::world::builtin::BuiltinMap = name.parse().unwrap();
        assert_eq!(
            grid,
            builtin.generate(0),
            "{name} export does not round-trip"
        );
        assert!(tmp.path().join(format!("{name}.png")).is_file());
    }
}

/// Explores one shared map from its default start (the free cell with the most
/// clearance in the largest free region), with `extra` flags, and checks that the
/// mission ran to completion with at least `min_coverage` of the reachable free
/// space known.
fn explore_shared(dir: &Path, name: &str, min_coverage: f64, extra: &[&str]) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join(name);
    cpsplan()
        .args(["explore", "--quiet", "--max-scans", "5000"])
        .args(extra)
        .arg("--map")
        .arg(dir.join(format!("{name}.yaml")))
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let s = summary(&out);
    assert_ne!(s["stop_reason"], "scan_limit", "{name}: {s}");
    assert_ne!(s["stop_reason"], "no_cps_move", "{name}: {s}");
    let truth = shared_truth(&dir.join(format!("{name}.yaml")));
    let links = links_clear_on_truth(&out, &truth);
    assert!(extra.contains(&"0") || links > 0, "{name}: no links");
    let c = s["coverage"].as_f64().unwrap();
    assert!(c >= min_coverage, "{name}: coverage {c} < {min_coverage}");
    // Space out of the robot's reach (SLAM streaks, half-shut doors) is at most a
    // few per cent of these maps.
    let connected = s["connected_coverage"].as_f64().unwrap();
    assert!(
        (0.9..=1.0).contains(&connected),
        "{name}: connected coverage {connected}"
    );
}

#[test]
fn shared_real_maps_are_explored() {
    let Some(dir) = shared_maps("shared_real_maps_are_explored") else {
        return;
    };
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let p = e.ok()?.path();
            if p.extension()? != "yaml" {
                return None;
            }
            Some(p.file_stem()?.to_string_lossy().into_owned())
        })
        .filter(|n| n != "cit_tsudanuma_campus")
        .collect();
    names.sort();
    assert!(
        names.len() >= 13,
        "expected the shared maps, found {names:?}"
    );
    // With the default team: a parent and two children.
    for name in &names {
        explore_shared(&dir, name, 0.99, &[]);
    }
}

/// The largest shared map (275 m × 221 m outdoors, 2 000 scans), in a test of its
/// own so that it runs beside the others. The parent alone here: with children
/// the run takes several minutes, too long for every test run
/// (`scripts/shared-maps.sh` runs it with children; see docs/HISTORY.md).
#[test]
fn shared_campus_map_is_explored() {
    let Some(dir) = shared_maps("shared_campus_map_is_explored") else {
        return;
    };
    explore_shared(&dir, "cit_tsudanuma_campus", 0.99, &["--children", "0"]);
}

/// The office after one scan with two children: the report directory (in `tmp`),
/// the first step's record, and the `plan` arguments for that state (`--known`
/// map, `--parent`, two `--child`).
fn first_office_step(tmp: &Path) -> (Value, Vec<String>) {
    let out = tmp.join("first");
    cpsplan()
        .args([
            "explore",
            "--builtin",
            "office",
            "--children",
            "2",
            "--max-scans",
            "1",
            "--quiet",
            "--out",
        ])
        .arg(&out)
        .assert()
        .success();
    let ep: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("episode.json")).unwrap()).unwrap();
    let step = ep["steps"][0].clone();
    let xy = |p: &Value| format!("{},{}", p["x"].as_f64().unwrap(), p["y"].as_f64().unwrap());
    let args = vec![
        "--known".to_string(),
        out.join("knowledge.yaml").display().to_string(),
        "--parent".into(),
        xy(&ep["start"]),
        "--child".into(),
        xy(&step["children"][0]),
        "--child".into(),
        xy(&step["children"][1]),
    ];
    (step, args)
}

/// `plan` on the map `explore` had after its first scan gives the same first cycle.
#[test]
fn plan_matches_the_first_cycle_of_explore() {
    let tmp = tempfile::tempdir().unwrap();
    let (step, plan_args) = first_office_step(tmp.path());
    let result = cpsplan().arg("plan").args(&plan_args).output().unwrap();
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let plan: Value = serde_json::from_slice(&result.stdout).unwrap();
    assert_eq!(plan["plan"]["decision"], step["plan"]["decision"]);
    assert_eq!(plan["move"]["target"], step["move"]["target"]);
    let (a, b) = (&plan["move"]["cycles"][0], &step["move"]["cycles"][0]);
    assert!(a.is_object(), "no cycle planned: {plan}");
    assert_eq!(a, b);
    // The predicted error the move adds, that of its last cycle.
    let cycles = plan["move"]["cycles"].as_array().unwrap();
    let sigma = plan["predicted_position_sigma_m"].as_f64().unwrap();
    assert!(sigma > 0.0 && sigma < 1.0, "{plan}");
    assert_eq!(
        cycles.last().unwrap()["position_sigma_m"].as_f64(),
        Some(sigma)
    );
}

#[test]
fn plan_rejects_bad_robots_and_reports_nothing_to_scan() {
    let tmp = tempfile::tempdir().unwrap();
    // A fully known room: nothing left to scan.
    let g = cpsplan::GridGeometry::new(60, 40, 0.1, cpsplan::Point::default());
    let mut room = cpsplan::OccupancyGrid::filled(g, cpsplan::CellState::Occupied);
    room.fill_rect(1, 1, 59, 39, cpsplan::CellState::Free);
    let yaml = tmp.path().join("room.yaml");
    cpsplan_cli::formats::rosmap::save_map(&room, &yaml).unwrap();
    let run = |args: &[&str]| {
        cpsplan()
            .args(["plan", "--known"])
            .arg(&yaml)
            .args(args)
            .output()
            .unwrap()
    };
    let done = run(&["--parent", "3,2", "--child", "1,1", "--child", "5,3"]);
    assert!(done.status.success());
    let plan: Value = serde_json::from_slice(&done.stdout).unwrap();
    assert_eq!(plan["plan"]["decision"]["kind"], "complete");
    // The parent alone (no --child) is planned too.
    let alone = run(&["--parent", "3,2"]);
    assert!(alone.status.success());
    let plan: Value = serde_json::from_slice(&alone.stdout).unwrap();
    assert_eq!(plan["plan"]["decision"]["kind"], "complete");
    for (args, needle) in [
        (vec!["--parent", "3,2", "--children", "1"], "--child"),
        (vec!["--parent", "3,2", "--child", "0.05,0.05"], "child 1"),
        (
            vec!["--parent", "30,2", "--child", "1,1"],
            "outside the map",
        ),
        (vec!["--parent", "0.05,2", "--child", "1,1"], "parent"),
    ] {
        let r = run(&args);
        assert_eq!(r.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"));
    }
}

/// Decodes a PNG file and returns its size.
fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let pic = tiny_skia::Pixmap::decode_png(&bytes).expect("a valid PNG");
    (pic.width(), pic.height())
}

#[test]
fn explore_draws_requested_step_figures_and_warns_beyond_the_end() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("steps");
    let result = cpsplan()
        .args([
            "explore",
            "--builtin",
            "site",
            "--children",
            "2",
            "--max-scans",
            "4",
            "--step-figure",
            "2",
            "--step-figure",
            "9,2",
            "--quiet",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&result.stderr);
    assert!(result.status.success(), "{err}");
    let (w, h) = png_size(&out.join("step-002.png"));
    assert!(w >= 800 && h >= 800, "{w} x {h}");
    // Only the requested steps are drawn; the one beyond the episode warns once.
    let figures: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|e| {
            let name = e.ok()?.file_name().to_string_lossy().into_owned();
            name.starts_with("step-").then_some(name)
        })
        .collect();
    assert_eq!(figures, ["step-002.png"]);
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("warning")).collect();
    assert_eq!(warnings.len(), 2, "{err}");
    assert!(
        warnings[0].contains("--step-figure 9") && warnings[0].contains("4 scans"),
        "{err}"
    );
    // Four scans cover a small part of the site: said, with the reason.
    assert!(
        warnings[1].contains("less than 90 %") && warnings[1].contains("scan_limit"),
        "{err}"
    );
    assert!(out.join("map.png").is_file());
}

#[test]
fn step_figure_numbers_must_be_scan_numbers() {
    for bad in ["0", "two", "2,,3", "1.5"] {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("out");
        let result = cpsplan()
            .args(["explore", "--quiet", "--step-figure", bad, "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(result.status.code(), Some(2), "{bad}");
        let err = String::from_utf8_lossy(&result.stderr);
        assert!(err.contains("scan number"), "{bad}: {err}");
        assert!(!out.exists());
    }
}

#[test]
fn plan_figure_writes_a_png() {
    let tmp = tempfile::tempdir().unwrap();
    let (_, plan_args) = first_office_step(tmp.path());
    let figure = tmp.path().join("plan.png");
    let result = cpsplan()
        .arg("plan")
        .args(&plan_args)
        .arg("--figure")
        .arg(&figure)
        .output()
        .unwrap();
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    // The plan is still printed, and the figure is a picture.
    let plan: Value = serde_json::from_slice(&result.stdout).unwrap();
    assert!(plan["move"]["cycles"][0].is_object(), "{plan}");
    let (w, h) = png_size(&figure);
    assert!(w >= 800 && h >= 800, "{w} x {h}");
    // An unwritable figure path is a clean error.
    let bad = tmp.path().join("no-such-dir").join("plan.png");
    let result = cpsplan()
        .arg("plan")
        .args(&plan_args[..6])
        .arg("--figure")
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(result.status.code(), Some(2));
    let err = String::from_utf8_lossy(&result.stderr);
    assert!(
        err.contains("plan.png") && !err.contains("panicked"),
        "{err}"
    );
}

/// `cpsplan bound` on a built-in map writes its JSON and picture, with the
/// greedy cover growing with the share and the lower bound below it.
#[test]
fn bound_writes_json_and_picture() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("bound");
    let r = cpsplan()
        .args(["bound", "--builtin", "tunnel", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(r.status.success());
    assert!(String::from_utf8_lossy(&r.stdout).contains("greedy stations"));
    let b: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("bound.json")).unwrap()).unwrap();
    let levels = b["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 4);
    let mut last = 0;
    for l in levels {
        let g = l["greedy_stations"].as_u64().unwrap();
        assert!(g >= last, "{l}");
        assert!(l["lower_bound_stations"].as_u64().unwrap() <= g, "{l}");
        last = g;
    }
    assert_eq!(b["stations"].as_array().unwrap().len() as u64, last);
    assert!(b["wall_ms"].as_f64().unwrap() > 0.0);
    let png = std::fs::read(out.join("bound.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    // A start in a wall is refused with the flag named, and nothing is written.
    let bad = tmp.path().join("bad");
    let r = cpsplan()
        .args(["bound", "--builtin", "tunnel", "--start", "0,0", "--out"])
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(r.status.code(), Some(2));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("--start") && !err.contains("panicked"),
        "{err}"
    );
    assert!(!bad.exists());
}

/// `--planner tour` runs the same CPS cycles and records its tour.
#[test]
fn the_tour_planner_explores_the_office() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("tour");
    cpsplan()
        .args([
            "explore",
            "--quiet",
            "--builtin",
            "office",
            "--planner",
            "tour",
            "--out",
        ])
        .arg(&out)
        .assert()
        .success();
    let s = summary(&out);
    assert_eq!(s["planner"], "tour");
    assert!(s["coverage"].as_f64().unwrap() >= 0.99, "{s}");
    assert!(s["cps_cycles"].as_u64().unwrap() + 1 >= s["scans"].as_u64().unwrap());
    let episode: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("episode.json")).unwrap()).unwrap();
    // Every move went to the tour's first stop, or (when no CPS move reached
    // it) to a later stop, a relocated one or a fallback.
    let mut first = 0;
    let steps = episode["steps"].as_array().unwrap();
    for st in steps {
        let Some(t) = st["move"]["target"].as_u64() else {
            continue;
        };
        let c = &st["plan"]["candidates"][t as usize];
        if c["tour_rank"].as_u64() == Some(0) {
            first += 1;
        }
    }
    assert!(
        first * 10 >= steps.len() * 8,
        "{first} of {} moves to the first stop",
        steps.len()
    );
}
