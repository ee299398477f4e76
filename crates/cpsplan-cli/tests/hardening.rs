//! Regression tests of malformed and extreme input: each is refused with one
//! line naming the value and its limit and exit code 2, or gets a correct
//! result with an honest stop reason; nothing is left half-written.

use std::path::{Path, PathBuf};

mod common;
use common::{cpsplan, room_pgm, summary};

/// Runs `args`, expects exit code 2 with exactly one line on stderr, and
/// returns that line.
fn refused(args: &[&str]) -> String {
    let out = cpsplan().args(args).output().expect("runs");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{args:?}: not one line: {err}");
    assert!(err.starts_with("error: "), "{err}");
    err
}

fn refused_with(args: &[&str], needles: &[&str]) -> String {
    let err = refused(args);
    for n in needles {
        assert!(err.contains(n), "{args:?}: `{n}` not in {err}");
    }
    err
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("write");
    p
}

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// CRC-32 (PNG's) of `bytes`.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A PNG whose header claims `w` × `h` 8-bit gray pixels, followed by a
/// truncated data stream: a decompression bomb's shape, refused on its header.
fn claimed_png(w: u32, h: u32) -> Vec<u8> {
    let chunk = |kind: &[u8], data: &[u8]| {
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        c.extend_from_slice(&body);
        c.extend_from_slice(&crc32(&body).to_be_bytes());
        c
    };
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 0, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(b"IDAT", &[0x78, 0xda, 0xec, 0xc1, 0x01]));
    png.extend(chunk(b"IEND", &[]));
    png
}

fn yaml(dir: &Path, name: &str, image: &str, extra: &str) -> PathBuf {
    write(
        dir,
        name,
        format!("image: {image}\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\n{extra}"),
    )
}

#[test]
fn huge_ranges_are_refused_not_looped_on() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out");
    for range in ["1e9", "3.1e8", "1e-6", "0.01", "-3"] {
        let e = refused(&["explore", "--range", range, "--out", s(&out)]);
        assert!(e.contains("--range") && e.contains("scanner.range"), "{e}");
    }
    let c = write(t.path(), "c.toml", "[children]\nmax_range = 1e9\n");
    refused_with(
        &["explore", "--config", s(&c), "--out", s(&out)],
        &["children.max_range", "10000"],
    );
    let c = write(t.path(), "d.toml", "[children]\nmax_range = 1e300\n");
    refused_with(
        &["explore", "--config", s(&c), "--out", s(&out)],
        &["children.max_range", "1e300"],
    );
    assert!(!out.exists());
}

#[test]
fn grids_beyond_the_cell_limit_are_refused_before_allocation() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out");
    refused_with(
        &["explore", "--resolution", "0.001", "--out", s(&out)],
        &["limits.max_grid_cells", "4.8e9"],
    );
    write(t.path(), "room.pgm", room_pgm(20, 20, |_, _| false));
    for res in ["1e9", "1e300"] {
        let y = write(
            t.path(),
            &format!("r{res}.yaml"),
            format!("image: room.pgm\nresolution: {res}\norigin: [0, 0, 0]\n"),
        );
        refused_with(
            &["explore", "--map", s(&y), "--out", s(&out)],
            &["limits.max_grid_cells"],
        );
    }
    let c = write(t.path(), "c.toml", "resolution = 1e-300\n");
    refused_with(
        &["explore", "--config", s(&c), "--out", s(&out)],
        &["`resolution`", "0.001"],
    );
    // Bombs: the header's size is refused before a pixel is decoded.
    let bomb = write(t.path(), "bomb.png", claimed_png(40_000, 40_000));
    refused_with(
        &["explore", "--map", s(&bomb), "--out", s(&out)],
        &["40000 × 40000", "limits.max_grid_cells"],
    );
    let pgm = write(t.path(), "bomb.pgm", "P5\n65535 65535\n255\n");
    refused_with(
        &["explore", "--map", s(&pgm), "--out", s(&out)],
        &["65535 × 65535"],
    );
    // The cap is a parameter.
    let c = write(t.path(), "small.toml", "[limits]\nmax_grid_cells = 100\n");
    let room = yaml(t.path(), "room.yaml", "room.pgm", "");
    refused_with(
        &[
            "explore",
            "--map",
            s(&room),
            "--config",
            s(&c),
            "--out",
            s(&out),
        ],
        &["limits.max_grid_cells", "20 × 20"],
    );
    assert!(!out.exists());
}

#[test]
fn runs_beyond_the_memory_limit_are_refused_before_they_start() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out");
    // The built-in site's estimate is some tens of MB: a limit of 5 MB refuses
    // it, with the estimate and the limit in the message.
    let c = write(t.path(), "m.toml", "[limits]\nmax_memory_mb = 5\n");
    refused_with(
        &["explore", "--config", s(&c), "--out", s(&out)],
        &["limits.max_memory_mb", "(5 MB)", "estimated to need"],
    );
    assert!(!out.exists());
    // A generous limit lets it run (a short run: two scans).
    let c = write(t.path(), "g.toml", "[limits]\nmax_memory_mb = 100000\n");
    cpsplan()
        .args([
            "explore",
            "--quiet",
            "--max-scans",
            "2",
            "--config",
            s(&c),
            "--out",
            s(&out),
        ])
        .assert()
        .success();
    assert!(out.join("summary.json").is_file());
}

/// A 1 km × 1 km site at 0.1 m (10⁸ cells, within the grid limit; the run is
/// estimated at some 6 GB) under a 3 GB address-space limit (`ulimit -v`):
/// refused at once with the estimate and the limit, nothing written, rather
/// than an allocation failure minutes in.
#[test]
fn an_address_space_limit_refuses_a_run_before_it_allocates() {
    if !Path::new("/proc/self/limits").is_file() || !Path::new("/bin/sh").is_file() {
        eprintln!("SKIP: no /proc/self/limits or /bin/sh to set ulimit -v with");
        return;
    }
    let t = tempfile::tempdir().unwrap();
    write(t.path(), "km.pgm", room_pgm(1000, 1000, |_, _| false));
    let yaml = write(
        t.path(),
        "km.yaml",
        "image: km.pgm\nresolution: 1.0\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n\
         occupied_thresh: 0.65\nfree_thresh: 0.196\n",
    );
    let out = t.path().join("out");
    let script = format!(
        "ulimit -v 3000000 && exec \"$0\" explore -q --map {} --start 50,50 --out {}",
        s(&yaml),
        s(&out)
    );
    let run = std::process::Command::new("/bin/sh")
        .args(["-c", &script, env!("CARGO_BIN_EXE_cpsplan")])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    for needle in ["estimated to need", "address-space limit (ulimit -v)"] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    assert!(!out.exists());
}

#[test]
fn huge_counts_are_refused() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out");
    refused_with(
        &["explore", "--children", "1000", "--out", s(&out)],
        &["--children", "children.count", "0 to 8"],
    );
    refused_with(
        &["explore", "--children", "-1", "--out", s(&out)],
        &["--children", "-1", "whole number"],
    );
    for (name, text, key) in [
        ("a.toml", "[children]\ncount = 1e11\n", "children.count"),
        (
            "b.toml",
            "[children]\ncount = 100000000000\n",
            "children.count",
        ),
        (
            "c.toml",
            "[children]\ncount = 18446744073709551615\n",
            "children.count",
        ),
        (
            "d.toml",
            "[parent]\nmax_samples = 18446744073709551615\nsamples_per_m2 = 1e300\n",
            "parent.",
        ),
        (
            "e.toml",
            "[accuracy]\nmonte_carlo_runs = 18446744073709551615\n",
            "accuracy.monte_carlo_runs",
        ),
    ] {
        let c = write(t.path(), name, text);
        refused_with(&["explore", "--config", s(&c), "--out", s(&out)], &[key]);
    }
    assert!(!out.exists());
}

#[test]
fn cross_checks_are_refused_with_both_names() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out");
    for (text, needles) in [
        (
            "[children]\nmin_range = 1e20\n",
            &["children.min_range", "1e20"][..],
        ),
        (
            "[children]\nmin_range = 1e18\n",
            &["children.min_range", "1e18"][..],
        ),
        (
            "[children]\nmin_range = 10\nmax_range = 5\n",
            &["children.min_range", "children.max_range"][..],
        ),
        (
            "[children]\nmin_range = 30\n",
            &["children.min_range", "scanner.range"][..],
        ),
    ] {
        let c = write(t.path(), "c.toml", text);
        refused_with(&["explore", "--config", s(&c), "--out", s(&out)], needles);
    }
    refused_with(
        &["explore", "--resolution", "50", "--out", s(&out)],
        &["--resolution", "0.001 to 10"],
    );
    refused_with(
        &["explore", "--radius", "100", "--out", s(&out)],
        &["--radius", "robot.radius", "0 to 10"],
    );
    refused_with(
        &["explore", "--radius", "2", "--out", s(&out)],
        &["robot.radius", "parent.band_width"],
    );
}

#[test]
fn files_that_are_not_regular_files_are_refused() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out");
    let y = yaml(t.path(), "dir.yaml", ".", "");
    refused_with(
        &["explore", "--map", s(&y), "--out", s(&out)],
        &["not a regular file"],
    );
    #[cfg(unix)]
    {
        let fifo = t.path().join("fifo.pgm");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let y = yaml(t.path(), "fifo.yaml", "fifo.pgm", "");
            refused_with(
                &["explore", "--map", s(&y), "--out", s(&out)],
                &["fifo.pgm", "not a regular file"],
            );
        } else {
            println!("skipped: mkfifo is not available");
        }
    }
}

#[test]
fn pgm_samples_are_read_as_stored() {
    let t = tempfile::tempdir().unwrap();
    // 16-bit raw: walls stored as 100 stay walls.
    let (w, h) = (30usize, 20usize);
    let mut pgm = format!("P5\n{w} {h}\n65535\n").into_bytes();
    for y in 0..h {
        for x in 0..w {
            let wall = x == 0 || y == 0 || x == w - 1 || y == h - 1;
            pgm.extend_from_slice(&(if wall { 100u16 } else { 0 }).to_be_bytes());
        }
    }
    write(t.path(), "raw16.pgm", pgm);
    let y = yaml(t.path(), "raw16.yaml", "raw16.pgm", "mode: raw\n");
    let grid = cpsplan_cli::formats::rosmap::load_map(&y).unwrap();
    assert_eq!(grid.count(cpsplan::CellState::Occupied), 2 * (w + h) - 4);
    assert_eq!(grid.count(cpsplan::CellState::Free), (w - 2) * (h - 2));
    // Samples above maxval are errors, not free space.
    write(t.path(), "over.pgm", b"P5\n2 2\n100\n\x00\xff\x00\x00");
    let y = yaml(t.path(), "over.yaml", "over.pgm", "");
    let e = cpsplan_cli::formats::rosmap::load_map(&y)
        .unwrap_err()
        .to_string();
    assert!(e.contains("255") && e.contains("maxval 100"), "{e}");
    // A small maxval is white at maxval.
    write(t.path(), "p2.pgm", "P2\n3 1\n10\n10 0 5\n");
    let y = yaml(t.path(), "p2.yaml", "p2.pgm", "");
    let g = cpsplan_cli::formats::rosmap::load_map(&y).unwrap();
    use cpsplan::CellState::*;
    assert_eq!(g.cells(), &[Free, Occupied, Unknown]);
}

#[test]
fn far_origins_are_refused() {
    let t = tempfile::tempdir().unwrap();
    write(t.path(), "room.pgm", room_pgm(20, 20, |_, _| false));
    let y = write(
        t.path(),
        "far.yaml",
        "image: room.pgm\nresolution: 0.1\norigin: [1e16, 0, 0]\n",
    );
    refused_with(
        &["explore", "--map", s(&y), "--out", s(&t.path().join("o"))],
        &["origin", "1e16", "1e8"],
    );
}

#[test]
fn tiny_ranges_and_unknown_maps_do_not_claim_completion() {
    let t = tempfile::tempdir().unwrap();
    // One free cell in a sea of unknown: only a border fragment of one cell,
    // below parent.min_frontier_cells.
    let (w, h) = (50usize, 50usize);
    let mut pgm = format!("P5\n{w} {h}\n255\n").into_bytes();
    pgm.extend((0..w * h).map(|i| if i == 25 * w + 25 { 254u8 } else { 205 }));
    write(t.path(), "unknown.pgm", pgm);
    let y = yaml(t.path(), "unknown.yaml", "unknown.pgm", "");
    let cfg = write(t.path(), "alone.toml", "[children]\ncount = 0\n");
    let _ = cfg;
    let grid = cpsplan_cli::formats::rosmap::load_map(&y).unwrap();
    let step = cpsplan::plan_step(
        &grid,
        cpsplan::Point::new(2.55, 2.45),
        &[],
        &cpsplan::Config::default(),
    )
    .unwrap();
    assert_eq!(
        step.plan.decision,
        cpsplan::parent::Decision::FrontierBelowThreshold
    );
}

#[test]
fn a_tiny_start_region_is_said_and_warned() {
    let t = tempfile::tempdir().unwrap();
    // A 20 m × 10 m hall, and a 1 m closet behind a slit narrower than the
    // robot and a baffle: from the closet the robots reach ~5 % of the free
    // space and see little more.
    let (w, h) = (200usize, 100usize);
    write(
        t.path(),
        "hall.pgm",
        room_pgm(w, h, |x, y| {
            (x == 12 && !(50..52).contains(&y)) || (x == 14 && (40..62).contains(&y))
        }),
    );
    let y = yaml(t.path(), "hall.yaml", "hall.pgm", "");
    let out = t.path().join("out");
    let result = cpsplan()
        .args(["explore", "--quiet", "--map", s(&y), "--start", "0.6,5.05"])
        .args(["--out", s(&out)])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&result.stderr);
    assert!(result.status.success(), "{err}");
    let sm = summary(&out);
    assert_eq!(sm["stop_reason"], "start_region_too_small", "{sm}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("warning: ") && err.contains("less than 90 %"),
        "{err}"
    );

    // Noise: a few free cells here and there.
    let mut state = 12345u32;
    let mut noise = format!("P5\n{w} {h}\n255\n").into_bytes();
    noise.extend((0..w * h).map(|_| {
        state = state.wrapping_mul(1_103_515_245).wrapping_add(12345);
        if (state >> 16) & 1 == 0 {
            0u8
        } else {
            254
        }
    }));
    write(t.path(), "noise.pgm", noise);
    let y = yaml(t.path(), "noise.yaml", "noise.pgm", "");
    let out = t.path().join("noise");
    let result = cpsplan()
        .args(["explore", "--quiet", "--map", s(&y), "--out", s(&out)])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&result.stderr);
    match result.status.code() {
        // No free cell wide enough to start from at all.
        Some(2) => assert!(err.starts_with("error: "), "{err}"),
        _ => {
            let sm = summary(&out);
            assert_eq!(sm["stop_reason"], "start_region_too_small", "{sm}");
            assert!(err.contains("warning: "), "{err}");
        }
    }
}

#[test]
fn plan_checks_the_team_robot_by_robot() {
    let t = tempfile::tempdir().unwrap();
    write(t.path(), "room.pgm", room_pgm(400, 100, |_, _| false));
    let k = yaml(t.path(), "room.yaml", "room.pgm", "");
    let k = s(&k);
    // 35 m away with a 20 m scanner.
    refused_with(
        &["plan", "--known", k, "--parent", "2,5", "--child", "37,5"],
        &["child 1", "35 m", "20 m"],
    );
    refused_with(
        &["plan", "--known", k, "--parent", "2,5", "--child", "2,5"],
        &["child 1", "same cell", "the parent"],
    );
    refused_with(
        &[
            "plan",
            "--known",
            k,
            "--parent",
            "2,5",
            "--child",
            "5,5",
            "--child",
            "5.02,5.03",
        ],
        &["child 2", "same cell", "child 1"],
    );
    // Nearer than the instrument's 1.3 m minimum.
    refused_with(
        &["plan", "--known", k, "--parent", "2,5", "--child", "2.5,5"],
        &["child 1", "1.3"],
    );
    let c = write(t.path(), "one.toml", "[children]\ncount = 1\n");
    refused_with(
        &[
            "plan",
            "--known",
            k,
            "--parent",
            "2,5",
            "--child",
            "5,5",
            "--child",
            "5,7",
            "--config",
            s(&c),
        ],
        &["children.count = 1", "2 --child"],
    );
    let c = write(t.path(), "far.toml", "[children]\nmin_range = 1e20\n");
    refused_with(
        &[
            "plan",
            "--known",
            k,
            "--parent",
            "2,5",
            "--child",
            "5,5",
            "--config",
            s(&c),
        ],
        &["children.min_range"],
    );
}

#[test]
fn reports_are_all_or_nothing() {
    let t = tempfile::tempdir().unwrap();
    // A foreign file in --out: refused before the run, the file untouched.
    let out = t.path().join("mine");
    std::fs::create_dir(&out).unwrap();
    write(&out, "thesis.tex", "precious");
    refused_with(
        &["explore", "--max-scans", "1", "--out", s(&out)],
        &["thesis.tex", "not part of a cpsplan report"],
    );
    assert_eq!(
        std::fs::read_to_string(out.join("thesis.tex")).unwrap(),
        "precious"
    );
    // `map.png` as a directory: nothing written, exit 2.
    let out = t.path().join("blocked");
    std::fs::create_dir_all(out.join("map.png")).unwrap();
    refused(&["explore", "--max-scans", "1", "--out", s(&out)]);
    assert!(!out.join("episode.json").exists() && !out.join("metrics.csv").exists());
    // An earlier report is replaced whole: no stale step figures; the
    // temporary directory of a killed run into the same place is removed.
    let out = t.path().join("report");
    let stale = t.path().join(".report.cpsplan-tmp-4194304999");
    std::fs::create_dir(&stale).unwrap();
    write(&stale, "episode.json", "{}");
    cpsplan()
        .args(["explore", "-q", "--max-scans", "3", "--step-figure", "3"])
        .args(["--out", s(&out)])
        .assert()
        .success();
    assert!(out.join("step-003.png").is_file());
    let result = cpsplan()
        .args(["explore", "-q", "--max-scans", "1", "--builtin", "office"])
        .args(["--out", s(&out)])
        .output()
        .unwrap();
    assert!(result.status.success());
    assert!(!out.join("step-003.png").exists());
    assert_eq!(summary(&out)["scans"], 1);
    // No temporary directory is left beside --out.
    let left: Vec<String> = std::fs::read_dir(t.path())
        .unwrap()
        .filter_map(|e| Some(e.ok()?.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.contains("cpsplan-"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    // A run that fails after the check leaves no --out at all.
    let out = t.path().join("never");
    refused(&[
        "explore",
        "--map",
        "/nonexistent/map.yaml",
        "--out",
        s(&out),
    ]);
    assert!(!out.exists());
}

#[cfg(target_os = "linux")]
#[test]
fn plan_leaves_no_figure_when_stdout_fails() {
    let t = tempfile::tempdir().unwrap();
    write(t.path(), "room.pgm", room_pgm(100, 100, |_, _| false));
    let k = yaml(t.path(), "room.yaml", "room.pgm", "");
    let fig = t.path().join("fig.png");
    let bin = assert_cmd::cargo::cargo_bin("cpsplan");
    let status = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "'{}' plan --known '{}' --parent 2,5 --child 5,5 --figure '{}' > /dev/full",
            bin.display(),
            k.display(),
            fig.display()
        ))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&status.stderr);
    assert_eq!(status.status.code(), Some(2), "{err}");
    assert!(err.contains("cannot write the plan"), "{err}");
    assert!(!fig.exists());
    let left: Vec<_> = std::fs::read_dir(t.path())
        .unwrap()
        .filter_map(|e| Some(e.ok()?.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn messages_are_one_line_with_each_cause_once() {
    let t = tempfile::tempdir().unwrap();
    let e = refused(&["explore", "--map", "/nonexistent/map.yaml"]);
    assert_eq!(e.matches("os error 2").count(), 1, "{e}");
    let bad = write(t.path(), "bad.png", b"\x89PNG\r\n\x1a\nnot really");
    let e = refused(&["explore", "--map", s(&bad)]);
    assert_eq!(e.matches("bad.png").count(), 1, "{e}");
    let c = write(t.path(), "c.toml", "[scanner]\nrange = \"far\"\n");
    refused_with(
        &["explore", "--config", s(&c)],
        &["line 2", "scanner.range"],
    );
    refused_with(
        &["explore", "--bogus"],
        &["--bogus", "cpsplan explore --help"],
    );
    refused_with(&["plan"], &["--known", "--parent"]);
    let c = write(t.path(), "r.toml", "[scanner]\nrange = 1e300\n");
    let e = refused(&["explore", "--config", s(&c)]);
    assert!(e.len() < 200, "{e}");
    // Huge numbers print short.
    let e = refused_with(
        &["explore", "--start", "1e300,5"],
        &["1e300", "outside the map"],
    );
    assert!(e.len() < 200, "{e}");
}

#[test]
fn help_shows_every_default() {
    let out = cpsplan().args(["explore", "--help"]).output().unwrap();
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    let d = cpsplan::Config::default();
    for needle in [
        format!("[default: {}]", d.scanner.range),
        format!("[default: {}]", d.resolution),
        format!("[default: {}]", d.robot.radius),
        format!("[default: {}]", d.children.count),
        format!("[default: {}]", d.mission.max_scans),
        format!("[default: {}]", d.instrument.model.name()),
        "[default: site]".to_string(),
        "[default: out]".to_string(),
    ] {
        assert!(help.contains(&needle), "`{needle}` not in:\n{help}");
    }
}

#[test]
fn a_directory_the_caller_cannot_write_is_not_replaced() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().unwrap();
    std::fs::set_permissions(tmp.path(), std::fs::Permissions::from_mode(0o777)).unwrap();
    let ro = tmp.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    let args = [
        "explore",
        "--builtin",
        "site",
        "--max-scans",
        "2",
        "--out",
        s(&ro),
    ];
    let bin = assert_cmd::cargo::cargo_bin("cpsplan");
    // As root, the run goes as `nobody` (root writes anywhere).
    let root = std::fs::write(ro.join("probe"), b"").is_ok();
    let out = if root {
        std::fs::remove_file(ro.join("probe")).unwrap();
        std::process::Command::new("setpriv")
            .args(["--reuid=65534", "--regid=65534", "--clear-groups"])
            .arg(&bin)
            .args(args)
            .output()
    } else {
        std::process::Command::new(&bin).args(args).output()
    };
    match out {
        Ok(out) if out.status.code() != Some(126) && out.status.code() != Some(127) => {
            let err = String::from_utf8_lossy(&out.stderr);
            if root && err.contains("Permission denied") && !err.contains("--out") {
                eprintln!("SKIPPED: `nobody` cannot run the test binary here: {err}");
            } else {
                assert_eq!(out.status.code(), Some(2), "{err}");
                assert_eq!(err.lines().count(), 1, "{err}");
                assert!(err.contains("cannot write there"), "{err}");
                let meta = std::fs::metadata(&ro).unwrap();
                assert_eq!(
                    meta.permissions().mode() & 0o777,
                    0o555,
                    "the directory is kept"
                );
                assert_eq!(std::fs::read_dir(&ro).unwrap().count(), 0);
            }
        }
        _ => eprintln!("SKIPPED: no way to run as a user who cannot write there (setpriv)"),
    }
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// A bare image given where its map_server YAML lies beside it is read at
/// `--resolution` with origin 0, with a warning naming what the YAML says; no
/// warning for the YAML itself or for a YAML of another image.
#[test]
fn an_image_read_without_its_yaml_says_what_is_lost() {
    let t = tempfile::tempdir().unwrap();
    let pgm = write(t.path(), "room.pgm", room_pgm(60, 40, |_, _| false));
    let yaml = write(
        t.path(),
        "room.yaml",
        "image: room.pgm\nresolution: 0.05\norigin: [-2.0, -3.0, 0.0]\nnegate: 0\n\
         occupied_thresh: 0.65\nfree_thresh: 0.196\n",
    );
    let out = t.path().join("out");
    let explore = |map: &Path| {
        let run = cpsplan()
            .args([
                "explore",
                "-q",
                "--max-scans",
                "1",
                "--map",
                s(map),
                "--out",
                s(&out),
            ])
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let _ = std::fs::remove_dir_all(&out);
        String::from_utf8_lossy(&run.stderr).into_owned()
    };
    let err = explore(&pgm);
    for needle in [
        "room.pgm is read as a plain image at 0.1 m per pixel",
        "room.yaml beside it gives 0.05 m per pixel and origin (-2, -3",
        "give --map",
    ] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    assert!(!explore(&yaml).contains("plain image"));
    write(
        t.path(),
        "room.yaml",
        "image: other.pgm\nresolution: 0.05\norigin: [-2.0, -3.0, 0.0]\nnegate: 0\n\
         occupied_thresh: 0.65\nfree_thresh: 0.196\n",
    );
    assert!(!explore(&pgm).contains("plain image"));
}
