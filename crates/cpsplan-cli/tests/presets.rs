//! Presets: `--preset paper` and `preset = "paper"` in a configuration file
//! start from the paper's choices; the file's own keys and the flags still
//! apply.

use std::path::Path;

use assert_cmd::Command;
use serde_json::Value;

fn cpsplan() -> Command {
    Command::cargo_bin("cpsplan").expect("binary built")
}

fn summary(dir: &Path) -> Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json");
    serde_json::from_str(&text).expect("valid JSON")
}

/// `--preset paper` (and `preset = "paper"` in a file) starts from the
/// paper's choices, recorded in the configuration; the file's own keys and the
/// flags still apply.
#[test]
fn the_paper_preset_gives_the_papers_choices() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    cpsplan()
        .args([
            "explore",
            "-q",
            "--builtin",
            "tunnel",
            "--max-scans",
            "3",
            "--preset",
            "paper",
            "--planner",
            "tour",
            "--out",
        ])
        .arg(&out)
        .assert()
        .success();
    let c = &summary(&out)["config"];
    assert_eq!(c["preset"], "paper");
    assert_eq!(
        c["parent"]["planner"], "tour",
        "a flag overrides the preset"
    );
    assert_eq!(c["children"]["strategy"], "balanced");
    assert_eq!(c["parent"]["min_gain_m2"], 0.0);
    assert_eq!(c["parent"]["calibration_window"], 0);
    let file = tmp.path().join("p.toml");
    std::fs::write(&file, "preset = \"paper\"\n[parent]\nmin_gain_m2 = 1.5\n").unwrap();
    cpsplan()
        .args([
            "explore",
            "-q",
            "--builtin",
            "tunnel",
            "--max-scans",
            "3",
            "--config",
        ])
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let c = &summary(&out)["config"];
    assert_eq!(c["preset"], "paper");
    assert_eq!(c["parent"]["min_gain_m2"], 1.5, "the file's key wins");
    assert_eq!(c["parent"]["min_gain_share"], 0.0);
    let bad = cpsplan()
        .args(["explore", "-q", "--preset", "fast", "--out"])
        .arg(tmp.path().join("none"))
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("unknown preset `fast`"));
}
