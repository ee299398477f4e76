//! What `explore` leaves out of a report is said on stderr, with why.

mod common;
use common::{cpsplan, summary};

/// One child cannot fix the parent's pose: no σ and no error.png, and one
/// warning says so and what to change; two children give both.
#[test]
fn one_child_says_why_the_report_has_no_error() {
    let tmp = tempfile::tempdir().unwrap();
    for (children, warned) in [("1", true), ("2", false)] {
        let out = tmp.path().join(children);
        let run = cpsplan()
            .args([
                "explore",
                "-q",
                "--max-scans",
                "3",
                "--children",
                children,
                "--out",
            ])
            .arg(&out)
            .output()
            .unwrap();
        assert!(run.status.success());
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(
            err.contains("with one child the parent's new pose is not fixed"),
            warned,
            "{err}"
        );
        assert_eq!(out.join("error.png").exists(), !warned);
        assert_eq!(summary(&out)["final_position_sigma_m"].is_null(), warned);
    }
}
