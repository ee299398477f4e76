//! Ctrl-C during `explore`: the run ends after the scan under way and writes
//! the report of its scans, marked `interrupted`, exit code 130.

use std::path::Path;
use std::time::Duration;

mod common;

/// Whether process `pid` catches SIGINT (its handler is installed), from
/// `/proc/PID/status`; `None` where that cannot be read.
fn catches_sigint(pid: u32) -> Option<bool> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let mask = status.lines().find_map(|l| l.strip_prefix("SigCgt:"))?;
    let mask = u64::from_str_radix(mask.trim(), 16).ok()?;
    Some(mask & (1 << 1) != 0) // SIGINT is signal 2: bit 1
}

#[test]
fn ctrl_c_leaves_a_whole_report_marked_interrupted() {
    if !Path::new("/proc/self/status").is_file() {
        eprintln!("SKIPPED: no /proc here to see when the run catches Ctrl-C");
        return;
    }
    // A 100 m × 100 m open site scanned with a 4 m range: hundreds of scans.
    let t = tempfile::tempdir().unwrap();
    let yaml = common::room_map(t.path(), "site", (1000, 1000), |x, y| {
        x % 97 < 3 && y % 89 < 3
    });
    let out = t.path().join("report");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_cpsplan"))
        .args(["explore", "-q", "--range", "4", "--start", "50,50", "--map"])
        .arg(&yaml)
        .arg("--out")
        .arg(&out)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Ctrl-C once the run catches it (the episode has begun).
    while catches_sigint(child.id()) == Some(false) {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before Ctrl-C"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let sent = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let run = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(130), "{err}");
    assert!(
        err.contains("interrupted: the run stopped after scan"),
        "{err}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["stop_reason"], "interrupted");
    let scans = summary["scans"].as_u64().unwrap() as usize;
    assert!(
        scans >= 1 && (summary["coverage"].as_f64().unwrap()) < 0.9,
        "{summary}"
    );
    // Whole: a metrics row per scan, the map and the knowledge written.
    let metrics = std::fs::read_to_string(out.join("metrics.csv")).unwrap();
    assert_eq!(metrics.lines().count(), scans + 1);
    for name in ["map.png", "knowledge.yaml", "episode.json"] {
        assert!(out.join(name).is_file(), "{name}");
    }
}
