//! `cpsplan plan` for a live team: the flags `explore` has, a parent alone,
//! and the target's coordinates in the JSON, checked against `explore`'s own
//! first step.

use serde_json::Value;

mod common;
use common::cpsplan;

/// The office after one scan of a parent alone with a 30 m scanner and a
/// 0.3 m robot, planned again by `plan --children 0 --range 30 --radius 0.3`:
/// the same target, given as x,y.
#[test]
fn a_parent_alone_is_planned_with_explores_flags_and_its_target_has_coordinates() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("first");
    let flags = ["--children", "0", "--range", "30", "--radius", "0.3"];
    cpsplan()
        .args(["explore", "--builtin", "office", "--max-scans", "1", "-q"])
        .args(flags)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let ep: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("episode.json")).unwrap()).unwrap();
    let step = &ep["steps"][0];
    let start = &ep["start"];
    let run = cpsplan()
        .arg("plan")
        .arg("--known")
        .arg(out.join("knowledge.yaml"))
        .arg("--parent")
        .arg(format!("{},{}", start["x"], start["y"]))
        .args(flags)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let plan: Value = serde_json::from_slice(&run.stdout).unwrap();
    let index = plan["move"]["target"].as_u64().expect("a target") as usize;
    assert_eq!(plan["move"]["target"], step["move"]["target"]);
    let chosen = &step["plan"]["candidates"][index]["position"];
    assert_eq!(plan["target"], *chosen, "{}", plan["target"]);
    assert_eq!(
        plan["target"],
        plan["plan"]["candidates"][index]["position"]
    );
    assert!(plan["move"]["cycles"]
        .as_array()
        .is_none_or(|c| c.is_empty()));
    assert!(plan["predicted_position_sigma_m"].is_null());
}

/// `--children N` is a check on the `--child` positions given.
#[test]
fn a_child_count_unlike_the_positions_is_refused_in_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("first");
    cpsplan()
        .args([
            "explore",
            "--builtin",
            "site",
            "--max-scans",
            "1",
            "-q",
            "--out",
        ])
        .arg(&out)
        .assert()
        .success();
    let known = out.join("knowledge.yaml");
    for (count, children) in [("2", &["5,5"][..]), ("1", &[][..]), ("0", &["5,5"][..])] {
        let mut c = cpsplan();
        c.arg("plan")
            .arg("--known")
            .arg(&known)
            .args(["--parent", "4,4", "--children", count]);
        for p in children {
            c.args(["--child", p]);
        }
        let run = c.output().unwrap();
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(&format!("--children {count}, but")), "{err}");
    }
}

/// Later rounds too: the site with the default team (two children), planned
/// again after scans 3 and 10 from `explore`'s knowledge after that scan, the
/// team's positions at it, `--scan N` and the round's `gain_scale` (at scan 10
/// the calibration has moved it off 1): `explore`'s target each time.
#[test]
fn plan_repeats_explores_choice_after_later_scans() {
    let tmp = tempfile::tempdir().unwrap();
    let explore = |scans: usize| {
        let out = tmp.path().join(format!("scans{scans}"));
        cpsplan()
            .args(["explore", "--builtin", "site", "-q", "--max-scans"])
            .arg(scans.to_string())
            .arg("--out")
            .arg(&out)
            .assert()
            .success();
        out
    };
    let whole = explore(11);
    let ep: Value =
        serde_json::from_str(&std::fs::read_to_string(whole.join("episode.json")).unwrap())
            .unwrap();
    let mut scales = Vec::new();
    for scan in [3, 10] {
        let known = explore(scan).join("knowledge.yaml");
        let step = &ep["steps"][scan - 1];
        let at = |p: &Value| format!("{},{}", p["x"], p["y"]);
        let mut plan = cpsplan();
        plan.arg("plan")
            .arg("--known")
            .arg(&known)
            .args(["--parent", &at(&step["position"])])
            .args(["--scan", &scan.to_string()])
            .args(["--gain-scale", &step["gain_scale"].to_string()]);
        let children = step["children"]
            .as_array()
            .expect("the children's positions");
        assert_eq!(children.len(), 2);
        for c in children {
            plan.args(["--child", &at(c)]);
        }
        let run = plan.output().unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let planned: Value = serde_json::from_slice(&run.stdout).unwrap();
        let index = step["move"]["target"].as_u64().expect("explore moved on") as usize;
        assert_eq!(
            planned["move"]["target"], step["move"]["target"],
            "scan {scan}"
        );
        assert_eq!(
            planned["target"], step["plan"]["candidates"][index]["position"],
            "scan {scan}"
        );
        scales.push(step["gain_scale"].as_f64().unwrap());
    }
    assert!(
        scales[1] != 1.0,
        "the calibration has not moved the gain scale: {scales:?}"
    );
}

/// `--scan 0` is refused: scans count from 1.
#[test]
fn scan_zero_is_refused() {
    let err = cpsplan()
        .args([
            "plan", "--known", "x.yaml", "--parent", "1,1", "--scan", "0",
        ])
        .output()
        .unwrap();
    assert_eq!(err.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&err.stderr).contains("count from 1"));
}
