//! Commands at the edge of the machine: `bound` refusing spacings outside
//! their range and views that cannot be held before it allocates them, and a
//! full disk under `maps --export` and `bound` leaving nothing half-written.

use std::path::Path;

mod common;
use common::{cpsplan, run_under_address_limit};

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// Runs `args`, expects exit code 2 with exactly one line on stderr, and
/// returns that line.
fn refused(args: &[&str]) -> String {
    let out = cpsplan().args(args).output().expect("runs");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{args:?}: not one line: {err}");
    err
}

#[test]
fn bound_spacings_outside_one_cell_to_the_map_are_refused_with_the_range() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("b");
    for spacing in ["1e-9", "1e9", "0.05"] {
        let err = refused(&[
            "bound",
            "--builtin",
            "office",
            "--spacing",
            spacing,
            "--out",
            s(&out),
        ]);
        assert!(
            err.contains("--spacing must be from 0.1 m (one cell) to 80 m (the map's longer side)"),
            "{err}"
        );
    }
    let err = refused(&[
        "bound",
        "--builtin",
        "office",
        "--target-spacing",
        "1e9",
        "--out",
        s(&out),
    ]);
    assert!(err.contains("--target-spacing must be from 0.1 m"), "{err}");
    assert!(!out.exists());
}

/// A 160 m × 160 m open site at 0.1 m with a station on every cell (2.5
/// million stations seeing some 3,000 cells each, about 60 GB of views) under
/// an 8 GB address-space limit: refused within a second, before the views.
#[test]
fn bound_views_beyond_the_memory_are_refused_before_they_are_made() {
    let t = tempfile::tempdir().unwrap();
    let yaml = common::room_map(t.path(), "open", (1600, 1600), |_, _| false);
    let out = t.path().join("b");
    let args = [
        "bound",
        "--map",
        s(&yaml),
        "--spacing",
        "0.1",
        "--out",
        s(&out),
    ];
    let Some(run) = run_under_address_limit(8 << 20, &args) else {
        return;
    };
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    for needle in [
        "views of",
        "stations",
        "estimated to need",
        "address-space limit",
    ] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    assert!(!out.exists());
}

/// A full disk (a 1.2 MB tmpfs in a mount namespace of its own; skipped where
/// none can be made): `maps --export` needs about 1.6 MB and leaves nothing;
/// `bound` names the file it could not write and keeps the earlier output.
#[test]
fn a_full_disk_leaves_nothing_half_written() {
    let bin = env!("CARGO_BIN_EXE_cpsplan");
    let script = format!(
        "d=$(mktemp -d) && mount -t tmpfs -o size=1200k tmpfs \"$d\" || exit 99
         '{bin}' maps --export \"$d/maps\"; echo \"export $?\"; ls -A \"$d\"
         '{bin}' bound --builtin site -q --out \"$d/b\"; echo \"bound $?\"
         dd if=/dev/zero of=\"$d/fill\" bs=1k count=1190 2>/dev/null
         '{bin}' bound --builtin site -q --out \"$d/b\"; echo \"full $?\"; ls -A \"$d\" \"$d/b\""
    );
    let run = std::process::Command::new("unshare")
        .args(["-rm", "sh", "-c", &script])
        .output();
    let run = match run {
        Ok(r) if r.status.code() != Some(99) && !r.stdout.is_empty() => r,
        _ => {
            eprintln!("SKIPPED: no tmpfs in a private mount namespace (unshare -rm) here");
            return;
        }
    };
    let out = String::from_utf8_lossy(&run.stdout);
    let err = String::from_utf8_lossy(&run.stderr);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "export 2", "{out}{err}");
    assert_eq!(lines[1], "bound 0", "the disk was empty again: {out}{err}");
    assert!(
        err.contains("No space left") && err.contains("maps/"),
        "{err}"
    );
    assert!(
        err.contains("bound."),
        "the full disk names the file: {err}"
    );
    assert!(out.contains("full 2"), "{out}");
    // The export left nothing (its directory removed); the bound kept its
    // first output whole.
    let listing: Vec<&str> = lines[2..]
        .iter()
        .copied()
        .filter(|l| !l.is_empty())
        .collect();
    assert!(!listing.contains(&"maps"), "{out}");
    for name in ["bound.json", "bound.png"] {
        assert!(listing.contains(&name), "{name}: {out}");
    }
}
