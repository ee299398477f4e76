//! `cpsplan campaign`: the field data of `explore --field-data` replayed scan
//! by scan through `campaign init` and `campaign add`, as a real team would
//! feed its scans and readings; and every refusal leaving the directory as it
//! was, byte for byte.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;

mod common;
use common::{cpsplan, refused, run_ok};

#[cfg(feature = "ros")]
#[path = "campaign/live.rs"]
mod live;

/// `explore --field-data` on a built-in map: (report, field data).
fn field_data(tmp: &Path, map: &str, max_scans: Option<usize>) -> (PathBuf, PathBuf) {
    let (out, field) = (
        tmp.join(format!("out-{map}")),
        tmp.join(format!("field-{map}")),
    );
    let mut cmd = cpsplan();
    cmd.args(["explore", "-q", "--builtin", map, "--out"])
        .arg(&out)
        .arg("--field-data")
        .arg(&field);
    if let Some(n) = max_scans {
        cmd.args(["--max-scans", &n.to_string()]);
    }
    cmd.assert().success();
    (out, field)
}

fn json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// `campaign init` as `field.json` says.
fn init(field: &Path, camp: &Path) {
    let f = json(&field.join("field.json"));
    let (start, area) = (&f["start"], &f["area"]);
    let start = format!("{},{}", start["x"], start["y"]);
    let area: Vec<String> = area
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.to_string())
        .collect();
    cpsplan()
        .args(["campaign", "init"])
        .arg(camp)
        .args(["--start", &start, "--area", &area.join(","), "--config"])
        .arg(field.join("config.toml"))
        .assert()
        .success();
}

fn scan_files(field: &Path, n: usize) -> (PathBuf, PathBuf) {
    (
        field.join(format!("scan-{n:04}.ply")),
        field.join(format!("readings-{n:04}.csv")),
    )
}

fn add_args(camp: &Path, scan: &Path, readings: &Path) -> Vec<String> {
    vec![
        "campaign".into(),
        "add".into(),
        camp.display().to_string(),
        "--scan".into(),
        scan.display().to_string(),
        "--readings".into(),
        readings.display().to_string(),
    ]
}

fn add(camp: &Path, field: &Path, n: usize) {
    let (scan, readings) = scan_files(field, n);
    let args = add_args(camp, &scan, &readings);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    run_ok(&args);
}

/// Every file under `dir` with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(p.clone(), std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// A ROS map's cells: (width, height, PGM pixels).
fn pgm(path: &Path) -> (usize, usize, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    let mut parts = bytes.splitn(4, |&b| b == b'\n');
    let _magic = parts.next();
    let size = String::from_utf8_lossy(parts.next().unwrap()).into_owned();
    let _max = parts.next();
    let mut wh = size.split_whitespace().map(|v| v.parse::<usize>().unwrap());
    let (w, h) = (wh.next().unwrap(), wh.next().unwrap());
    (w, h, parts.next().unwrap().to_vec())
}

/// Replays the whole field data of `map` and checks what holds: every add
/// succeeds; every station lies within 3σ of where the simulation put it;
/// the knowledge map agrees with the simulation's; the next step is on known
/// free space; status and export work on the result.
fn replay(map: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let (out, field) = field_data(tmp.path(), map, None);
    let camp = tmp.path().join("campaign");
    init(&field, &camp);
    let episode = json(&out.join("episode.json"));
    let steps = episode["steps"].as_array().unwrap();
    for n in 1..=steps.len() {
        add(&camp, &field, n);
    }
    let state = json(&camp.join("campaign.json"));
    let scans = state["scans"].as_array().unwrap();
    assert_eq!(scans.len(), steps.len());
    // Every station within 3σ (radial) of the truth.
    let network = json(&camp.join("network.json"));
    let stations = network["stations"].as_array().unwrap();
    for (scan, step) in scans.iter().zip(steps) {
        let name = scan["station"].as_str().unwrap();
        let s = stations.iter().find(|s| s["name"] == name).unwrap();
        let (x, y) = (
            s["position"]["x"].as_f64().unwrap(),
            s["position"]["y"].as_f64().unwrap(),
        );
        let (tx, ty) = (
            step["position"]["x"].as_f64().unwrap(),
            step["position"]["y"].as_f64().unwrap(),
        );
        let err = (x - tx).hypot(y - ty);
        let sigma = s["sigma_m"].as_f64().unwrap();
        assert!(
            err <= 3.0 * sigma + 1e-9,
            "{map} {name}: {err} m against σ {sigma} m"
        );
    }
    // The knowledge map: the walls as the registered scans place them. Cells
    // the simulation knew free and the campaign holds for walls, or the other
    // way round, come from the stations' errors; the rest agree.
    let (w, h, mine) = pgm(&camp.join("knowledge.pgm"));
    let (we, he, sim) = pgm(&out.join("knowledge.pgm"));
    assert_eq!((w, h), (we, he));
    let known = sim.iter().filter(|&&v| v != 205).count();
    let agree = mine
        .iter()
        .zip(&sim)
        .filter(|(a, b)| a == b && **b != 205)
        .count();
    assert!(
        agree as f64 > 0.9 * known as f64,
        "{map}: {agree} of {known}"
    );
    // The next step stands on known free space.
    let next = json(&camp.join("next.json"));
    if next["stop"].is_null() {
        let p = &next["next"]["position"];
        let (x, y) = (p["x"].as_f64().unwrap(), p["y"].as_f64().unwrap());
        let (cx, cy) = ((x / 0.1) as usize, (y / 0.1) as usize);
        assert_eq!(
            mine[(h - 1 - cy) * w + cx],
            254,
            "{map}: next at ({x}, {y})"
        );
    }
    assert!(std::fs::read(camp.join("next.png"))
        .unwrap()
        .starts_with(b"\x89PNG"));
    let status = run_ok(&["campaign", "status", camp.to_str().unwrap()]);
    assert!(
        status.contains(&format!("{} scans", steps.len())),
        "{status}"
    );
    // Export: the registered model holds every scan's points.
    let (laz, yaml, html) = (
        tmp.path().join("model.laz"),
        tmp.path().join("map.yaml"),
        tmp.path().join("page.html"),
    );
    cpsplan()
        .args(["campaign", "export"])
        .arg(&camp)
        .arg("--cloud")
        .arg(&laz)
        .arg("--map")
        .arg(&yaml)
        .arg("--html")
        .arg(&html)
        .assert()
        .success();
    let options = cpsplan_cli::formats::cloud::CloudReadOptions::default();
    let model = cpsplan_cli::formats::cloud::read_cloud(&laz, &options, &mut |_, _| {}).unwrap();
    let mut total = 0;
    for n in 1..=steps.len() {
        let (scan, _) = scan_files(&field, n);
        total += cpsplan_cli::formats::cloud::read_cloud(&scan, &options, &mut |_, _| {})
            .unwrap()
            .points
            .len();
    }
    assert_eq!(model.points.len(), total);
    assert_eq!(pgm(&tmp.path().join("map.pgm")), (w, h, mine));
    assert!(std::fs::read_to_string(&html)
        .unwrap()
        .contains("cpsplan campaign"));
}

#[test]
fn the_site_replayed_from_its_field_data() {
    replay("site");
}

#[test]
fn the_tunnel_replayed_from_its_field_data() {
    replay("tunnel");
}

#[test]
fn the_office_replayed_from_its_field_data() {
    replay("office");
}

/// A campaign of the site's first scan, and its field data.
fn started() -> (tempfile::TempDir, PathBuf, PathBuf) {
    let tmp = tempfile::tempdir().unwrap();
    let (_, field) = field_data(tmp.path(), "site", Some(4));
    let camp = tmp.path().join("campaign");
    init(&field, &camp);
    add(&camp, &field, 1);
    (tmp, camp, field)
}

/// `add` with `scan` and `readings` is refused with one line holding
/// `needle`, and the directory stays as it was.
fn refused_unchanged(camp: &Path, scan: &Path, readings: &Path, needle: &str) {
    let before = snapshot(camp);
    let args = add_args(camp, scan, readings);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(&args, needle);
    assert!(before == snapshot(camp), "the campaign changed");
}

/// The readings file `n` with its `row`-th reading changed by `edit`.
fn edited(field: &Path, n: usize, to: &Path, edit: impl Fn(&mut Vec<String>)) -> PathBuf {
    let (_, readings) = scan_files(field, n);
    let text = std::fs::read_to_string(readings).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    edit(&mut lines);
    std::fs::write(to, lines.join("\n") + "\n").unwrap();
    to.to_path_buf()
}

#[test]
fn a_reading_ten_centimetres_off_is_named_and_changes_nothing() {
    let (tmp, camp, field) = started();
    let (scan, _) = scan_files(&field, 2);
    let bad = edited(&field, 2, &tmp.path().join("bad.csv"), |lines| {
        let mut cols: Vec<String> = lines[1].split(',').map(str::to_string).collect();
        let d: f64 = cols[2].parse().unwrap();
        cols[2] = format!("{}", d + 0.1);
        lines[1] = cols.join(",");
    });
    let first = std::fs::read_to_string(&bad).unwrap();
    let row = first.lines().nth(1).unwrap();
    let name: Vec<&str> = row.split(',').take(2).collect();
    refused_unchanged(
        &camp,
        &scan,
        &bad,
        &format!("{} \u{2192} {}", name[0], name[1]),
    );
    // The good readings are taken.
    add(&camp, &field, 2);
}

#[test]
fn an_unknown_point_id_changes_nothing() {
    let (tmp, camp, field) = started();
    let (scan, _) = scan_files(&field, 2);
    let bad = edited(&field, 2, &tmp.path().join("bad.csv"), |lines| {
        let mut cols: Vec<String> = lines[1].split(',').map(str::to_string).collect();
        cols[1] = "X77".into();
        lines[1] = cols.join(",");
    });
    refused_unchanged(&camp, &scan, &bad, "unknown point `X77`");
}

#[test]
fn a_truncated_cloud_changes_nothing() {
    let (tmp, camp, field) = started();
    let (scan, readings) = scan_files(&field, 2);
    let bytes = std::fs::read(&scan).unwrap();
    let cut = tmp.path().join("cut.ply");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    refused_unchanged(&camp, &cut, &readings, "cut.ply");
}

#[test]
fn a_directory_of_another_version_or_none_is_refused() {
    let (tmp, camp, field) = started();
    let (scan, readings) = scan_files(&field, 2);
    let state = camp.join("campaign.json");
    let text = std::fs::read_to_string(&state).unwrap();
    std::fs::write(&state, text.replace("\"version\": 1", "\"version\": 2")).unwrap();
    refused_unchanged(&camp, &scan, &readings, "format version 2");
    // A grid beyond the limits is refused before anything is allocated.
    std::fs::write(
        &state,
        text.replace("\"width\": 800", "\"width\": 1000000000000"),
    )
    .unwrap();
    refused_unchanged(&camp, &scan, &readings, "damaged");
    std::fs::write(&state, "{ not json").unwrap();
    refused_unchanged(&camp, &scan, &readings, "damaged");
    let foreign = tmp.path().join("foreign");
    std::fs::create_dir(&foreign).unwrap();
    std::fs::write(foreign.join("notes.txt"), "hello").unwrap();
    refused_unchanged(&foreign, &scan, &readings, "not a cpsplan campaign");
    // init refuses a directory that is not empty.
    refused(
        &[
            "campaign",
            "init",
            foreign.to_str().unwrap(),
            "--start",
            "1,1",
        ],
        "not empty",
    );
}

#[test]
fn the_first_scan_is_taken_at_the_start() {
    let tmp = tempfile::tempdir().unwrap();
    let (_, field) = field_data(tmp.path(), "site", Some(3));
    let camp = tmp.path().join("campaign");
    init(&field, &camp);
    // Scan 2's readings set up a new station: not the first scan's.
    let (scan, readings) = scan_files(&field, 2);
    refused_unchanged(
        &camp,
        &scan,
        &readings,
        "the first scan is taken at the start",
    );
    let out = run_ok(&["campaign", "status", camp.to_str().unwrap()]);
    assert!(out.contains("no scan yet"), "{out}");
}

/// The topics every `--mcap-out` file carries (the independent decoding is
/// `ci/check_mcap.py`, with Python's `mcap` and `mcap-ros2-support`).
fn assert_mcap(path: &Path) {
    let bytes = std::fs::read(path).unwrap();
    assert!(bytes.starts_with(b"\x89MCAP0\r\n"), "MCAP magic");
    assert!(bytes.ends_with(b"\x89MCAP0\r\n"), "MCAP magic at the end");
    let text = String::from_utf8_lossy(&bytes);
    for topic in [
        "/map",
        "/cpsplan/scans",
        "/cpsplan/stations",
        "/cpsplan/path/parent",
        "/cpsplan/path/child1",
        "/cpsplan/plan",
        "/tf",
        "nav_msgs/msg/OccupancyGrid",
        "visualization_msgs/msg/MarkerArray",
    ] {
        assert!(text.contains(topic), "{topic} in {}", path.display());
    }
}

#[test]
fn explore_and_add_write_the_campaign_as_ros2_messages() {
    let tmp = tempfile::tempdir().unwrap();
    let mcap = tmp.path().join("run.mcap");
    cpsplan()
        .args([
            "explore",
            "-q",
            "--builtin",
            "site",
            "--max-scans",
            "3",
            "--out",
        ])
        .arg(tmp.path().join("out"))
        .arg("--mcap-out")
        .arg(&mcap)
        .assert()
        .success();
    assert_mcap(&mcap);
    let (_, field) = field_data(tmp.path(), "site", Some(3));
    let camp = tmp.path().join("campaign");
    init(&field, &camp);
    let live = tmp.path().join("live.mcap");
    for n in 1..=2 {
        let (scan, readings) = scan_files(&field, n);
        let mut args = add_args(&camp, &scan, &readings);
        args.extend(["--mcap-out".to_string(), live.display().to_string()]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        run_ok(&args);
    }
    assert_mcap(&live);
    // A refused add writes no MCAP file.
    let (_, readings) = scan_files(&field, 3);
    let other = tmp.path().join("other.mcap");
    let bad = tmp.path().join("bad.ply");
    std::fs::write(&bad, b"ply\nformat ascii 1.0\n").unwrap();
    let mut args = add_args(&camp, &bad, &readings);
    args.extend(["--mcap-out".to_string(), other.display().to_string()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    refused(&args, "bad.ply");
    assert!(!other.exists());
}
