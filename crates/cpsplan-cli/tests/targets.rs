//! Targets and control points from the command line: `--place-targets N`,
//! `--targets FILE.csv`, `--max-sigma M` and the configuration's `[[targets]]`
//! and `[targets]`; what the report says of them; bad input refused cleanly.

use std::path::Path;

use serde_json::Value;

mod common;
use common::cpsplan;

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("readable")).expect("JSON")
}

#[test]
fn the_team_leaves_targets_and_keeps_a_tolerance() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let run = cpsplan()
        .args([
            "explore",
            "--builtin",
            "site",
            "--place-targets",
            "30",
            "--max-sigma",
            "0.05",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        stdout.contains("targets:") && stdout.contains("closures"),
        "{stdout}"
    );
    assert!(
        stdout.contains("after the whole network (smoothed)"),
        "{stdout}"
    );
    let s = json(&out.join("summary.json"));
    let worst = s["worst_position_sigma_m"].as_f64().unwrap();
    let smoothed = s["worst_smoothed_sigma_m"].as_f64().unwrap();
    assert!(worst <= 0.05 && smoothed <= worst, "{worst} {smoothed}");
    assert_eq!(s["sigma_violations"].as_array().unwrap().len(), 0);
    assert!(s["targets_placed"].as_u64().unwrap() >= 1);
    assert!(s["closures"].as_u64().unwrap() >= 1);
    assert_eq!(s["config"]["mission"]["max_sigma_m"], 0.05);
    assert_eq!(s["config"]["targets"]["place"], "auto");
    let e = json(&out.join("episode.json"));
    let targets = e["targets"].as_array().unwrap();
    assert_eq!(targets.len() as u64, s["targets_placed"].as_u64().unwrap());
    for t in targets {
        assert_eq!(t["origin"], "placed");
        assert!(t["reason"].as_str().is_some_and(|r| !r.is_empty()));
    }
    for step in e["steps"].as_array().unwrap() {
        assert!(
            step["smoothed_sigma_m"].as_f64().unwrap()
                <= step["position_sigma_m"].as_f64().unwrap()
        );
    }
    for f in ["map.png", "error.png", "error.svg"] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

#[test]
fn control_points_and_free_targets_come_from_csv_and_toml() {
    let tmp = tempfile::tempdir().unwrap();
    let csv = tmp.path().join("site.csv");
    std::fs::write(
        &csv,
        "# control of the site\nname,x,y,kind,sigma_mm\nC1,20.0,3.0,control,5\nC2,45.0,4.0,control,5\nF1,10.0,30.0,free,\n",
    )
    .unwrap();
    let out = tmp.path().join("out");
    cpsplan()
        .args([
            "explore",
            "-q",
            "--builtin",
            "site",
            "--max-scans",
            "12",
            "--targets",
        ])
        .arg(&csv)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let e = json(&out.join("episode.json"));
    let t = e["targets"].as_array().unwrap();
    let origins: Vec<&str> = t.iter().map(|t| t["origin"].as_str().unwrap()).collect();
    assert_eq!(origins, ["control", "control", "free"]);
    assert_eq!(t[0]["name"], "C1");
    assert_eq!(t[0]["sigma_mm"], 5.0);
    let measured: u64 = t.iter().map(|t| t["measurements"].as_u64().unwrap()).sum();
    assert!(measured >= 1, "{t:?}");
    // The same points in a configuration file, as [[targets]], and the team's
    // own targets as a [targets] table with the points beneath it.
    for toml in [
        "[[targets]]\nname = \"C1\"\nx = 20.0\ny = 3.0\nkind = \"control\"\nsigma_mm = 5\n",
        "[targets]\nplace = \"auto\"\nmax = 4\n[[targets.points]]\nx = 20.0\ny = 3.0\nkind = \"control\"\nsigma_mm = 5\n",
    ] {
        let cfg = tmp.path().join("c.toml");
        std::fs::write(&cfg, toml).unwrap();
        let out = tmp.path().join("out-toml");
        cpsplan()
            .args(["explore", "-q", "--builtin", "site", "--max-scans", "6", "--config"])
            .arg(&cfg)
            .arg("--out")
            .arg(&out)
            .assert()
            .success();
        let e = json(&out.join("episode.json"));
        assert_eq!(e["targets"][0]["origin"], "control", "{toml}");
    }
}

/// Runs `explore` with `args` and asserts a clean refusal: exit 2, one line
/// naming `needle`, nothing written.
fn refused(args: &[&str], needle: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let run = cpsplan()
        .current_dir(tmp.path())
        .arg("explore")
        .args(args)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2), "{args:?}");
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(err.contains(needle), "{args:?}: {err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!out.exists());
}

#[test]
fn bad_targets_are_refused_with_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        let p = tmp.path().join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let bad_number = write("n.csv", "x,y\n1,2\n3,abc\n");
    refused(&["--targets", &bad_number], "line 3");
    let no_sigma = write("s.csv", "name,x,y,kind\nG1,1,2,control\n");
    refused(
        &["--targets", &no_sigma],
        "control point `G1` needs `sigma_mm`",
    );
    let twice = write("t.csv", "name,x,y\nA,1,2\nA,3,4\n");
    refused(&["--targets", &twice], "two targets are named `A`");
    let column = write("c.csv", "x,y,colour\n1,2,red\n");
    refused(&["--targets", &column], "unknown column `colour`");
    refused(&["--targets", "missing.csv"], "missing.csv");
    refused(&["--max-sigma", "0"], "--max-sigma");
    refused(&["--place-targets", "500"], "--place-targets");
    let cfg = write("a.toml", "[targets]\nplace = \"auto\"\n");
    refused(&["--config", &cfg], "targets.max");
}

#[test]
fn no_targets_no_target_records() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    cpsplan()
        .args([
            "explore",
            "-q",
            "--builtin",
            "tunnel",
            "--max-scans",
            "5",
            "--place-targets",
            "0",
            "--out",
        ])
        .arg(&out)
        .assert()
        .success();
    let text = std::fs::read_to_string(out.join("episode.json")).unwrap();
    assert!(!text.contains("\"targets\"") && !text.contains("left_targets"));
    let s = json(&out.join("summary.json"));
    assert_eq!(s["targets_placed"], 0);
    assert!(s["config"].get("targets").is_none());
}
