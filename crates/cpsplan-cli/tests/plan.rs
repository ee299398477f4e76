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
