//! Helpers shared by the command-line tests: the binary, a run's summary, a
//! small experiment file, running it, and reading its records.

#![allow(dead_code)] // each test binary uses its own part

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use serde_json::Value;

pub fn cpsplan() -> Command {
    Command::cargo_bin("cpsplan").expect("binary built")
}

/// The `summary.json` a run wrote to `dir`.
pub fn summary(dir: &Path) -> Value {
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json");
    serde_json::from_str(&text).expect("valid JSON")
}

/// Two maps × two parameter sets (the parent alone; a parent with two children)
/// × two seeds, a few scans each.
pub const SMALL: &str = r#"
name = "small"
description = "a few scans on two built-in maps"
maps = ["builtin:site", "builtin:tunnel"]
seeds = { from = 0, count = 2 }

[base]
mission.max_scans = 4

[[parameters]]
name = "alone"
children.count = 0
parent.alpha = 0.0

[[parameters]]
name = "team"
children.count = 2
"#;

pub fn write_spec(dir: &Path, text: &str) -> PathBuf {
    let path = dir.join("small.toml");
    std::fs::write(&path, text).expect("write the experiment file");
    path
}

/// [`SMALL`] written into `dir` and run whole into `dir/run`, quietly: the
/// experiment file and the run's directory.
pub fn small_run(dir: &Path) -> (PathBuf, PathBuf) {
    let spec = write_spec(dir, SMALL);
    let out = dir.join("run");
    run_ok(&[
        "experiment",
        spec.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    (spec, out)
}

/// The records of `dir`, by file name, with `wall_ms` taken out.
pub fn records(dir: &Path) -> BTreeMap<String, Value> {
    let mut out = BTreeMap::new();
    for entry in std::fs::read_dir(dir.join("records")).expect("records/") {
        let path = entry.expect("entry").path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let mut v: Value =
            serde_json::from_str(&std::fs::read_to_string(&path).expect("read")).expect("JSON");
        assert!(v["wall_ms"].as_f64().is_some(), "{name} has wall_ms");
        v.as_object_mut().unwrap().remove("wall_ms");
        out.insert(name, v);
    }
    out
}

pub fn run(args: &[&str]) -> (bool, String, String) {
    let out = cpsplan().args(args).output().expect("runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

pub fn run_ok(args: &[&str]) -> String {
    let (ok, stdout, stderr) = run(args);
    assert!(ok, "cpsplan {args:?} failed: {stderr}");
    stdout
}

/// A refusal: exit code 2 and one line naming `needle`.
pub fn refused(args: &[&str], needle: &str) {
    let out = cpsplan().args(args).output().expect("runs");
    assert_eq!(out.status.code(), Some(2), "cpsplan {args:?} should fail");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.trim().lines().count(), 1, "one line: {stderr}");
    assert!(
        stderr.contains(needle),
        "cpsplan {args:?}: `{needle}` not in {stderr}"
    );
}

/// `cpsplan ARGS` run under an address-space limit of `kb` kilobytes
/// (`ulimit -v`); `None`, said on stderr, where it cannot be set.
pub fn run_under_address_limit(kb: u64, args: &[&str]) -> Option<std::process::Output> {
    if !Path::new("/proc/self/limits").is_file() || !Path::new("/bin/sh").is_file() {
        eprintln!("SKIP: no /proc/self/limits or /bin/sh to set ulimit -v with");
        return None;
    }
    let script = format!("ulimit -v {kb} && exec \"$0\" \"$@\"");
    let out = std::process::Command::new("/bin/sh")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_cpsplan"))
        .args(args)
        .output()
        .expect("/bin/sh runs");
    Some(out)
}

/// A walled room as a P5 PGM (254 free, 0 wall) of `w` × `h` pixels, with
/// `inner(x, y)` extra walls.
pub fn room_pgm(w: usize, h: usize, inner: impl Fn(usize, usize) -> bool) -> Vec<u8> {
    let mut pgm = format!("P5\n{w} {h}\n255\n").into_bytes();
    for y in 0..h {
        for x in 0..w {
            let wall = x == 0 || y == 0 || x == w - 1 || y == h - 1 || inner(x, y);
            pgm.push(if wall { 0 } else { 254 });
        }
    }
    pgm
}

/// [`room_pgm`] written into `dir` as `NAME.pgm` with its map_server
/// `NAME.yaml` (0.1 m pixels, origin 0); the YAML's path.
pub fn room_map(
    dir: &Path,
    name: &str,
    (w, h): (usize, usize),
    inner: impl Fn(usize, usize) -> bool,
) -> PathBuf {
    std::fs::write(dir.join(format!("{name}.pgm")), room_pgm(w, h, inner)).expect("write");
    let yaml = dir.join(format!("{name}.yaml"));
    std::fs::write(
        &yaml,
        format!(
            "image: {name}.pgm\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n\
             occupied_thresh: 0.65\nfree_thresh: 0.196\n"
        ),
    )
    .expect("write");
    yaml
}

/// Headless Chromium, or `None` after saying, past the test harness's capture,
/// that `test` is skipped.
pub fn chromium(test: &str) -> Option<PathBuf> {
    let names = [
        "chromium",
        "chromium-browser",
        "google-chrome",
        "google-chrome-stable",
    ];
    let path = std::env::var_os("PATH").unwrap_or_default();
    for dir in std::env::split_paths(&path) {
        for name in names {
            let candidate = dir.join(name);
            if candidate.is_file() {
                return Some(candidate);
            }
        }
    }
    skipped(
        test,
        "headless Chromium (Debian package `chromium`; .ci/run installs it)",
    )
}

/// `None`, after saying past the test harness's capture that `test` is
/// skipped for want of what it `needs`.
pub fn skipped<T>(test: &str, needs: &str) -> Option<T> {
    use std::io::Write as _;
    let _ = writeln!(std::io::stderr(), "SKIPPED {test}: needs {needs}");
    None
}

/// Headless `chrome` with its own new profile in `profile`, and without the
/// background connections a closed network refuses.
pub fn headless(chrome: &Path, profile: &Path) -> std::process::Command {
    let mut c = std::process::Command::new(chrome);
    c.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
    ])
    .arg(format!("--user-data-dir={}", profile.display()));
    c
}

/// `v` with every float rounded as the report's files state them.
pub fn tidied(v: &Value) -> Value {
    match v {
        Value::Number(n) if n.is_f64() => n
            .as_f64()
            .and_then(|f| serde_json::Number::from_f64(cpsplan_cli::formats::tidy::tidy(f)))
            .map_or(Value::Null, Value::Number),
        Value::Array(a) => Value::Array(a.iter().map(tidied).collect()),
        Value::Object(o) => Value::Object(o.iter().map(|(k, v)| (k.clone(), tidied(v))).collect()),
        other => other.clone(),
    }
}

/// `explore --html --max-scans SCANS` into `dir` with `extra` flags: the
/// page's path and its text.
pub fn explore_page(dir: &Path, scans: &str, extra: &[&str]) -> (PathBuf, String) {
    cpsplan()
        .args(["explore", "-q", "--html", "--max-scans", scans, "--out"])
        .arg(dir)
        .args(extra)
        .assert()
        .success();
    let path = dir.join("report.html");
    let html = std::fs::read_to_string(&path).expect("report.html");
    (path, html)
}

/// An experiment of the paper's and the gain planner on the site, up to
/// `scans` scans (`--html`: with its episodes' pages), and its report, in
/// `dir`; the report page's path.
pub fn two_planner_report(dir: &Path, scans: usize, html: bool) -> PathBuf {
    let spec = dir.join("two.toml");
    std::fs::write(
        &spec,
        format!(
            "name = \"two\"\nmaps = [\"builtin:site\"]\nplanners = [\"paper\", \"gain\"]\n\
             [base]\nmission.max_scans = {scans}\n"
        ),
    )
    .expect("write");
    let out = dir.join("run");
    let mut experiment = cpsplan();
    experiment
        .arg("experiment")
        .arg(&spec)
        .args(["-q", "--out"])
        .arg(&out);
    if html {
        experiment.arg("--html");
    }
    experiment.assert().success();
    cpsplan()
        .args(["report", "-q"])
        .arg(&out)
        .assert()
        .success();
    out.join("report/report.html")
}

/// Headless `chrome` in a 1400 × 1000 window, its pages' scripts given 20 s
/// of virtual time, with `args` (the page's address last): what it printed.
pub fn chromium_window<S: AsRef<std::ffi::OsStr>>(
    chrome: &Path,
    profile: &Path,
    args: &[S],
) -> String {
    let out = headless(chrome, profile)
        .args(["--window-size=1400,1000", "--virtual-time-budget=20000"])
        .args(args)
        .output()
        .expect("chromium runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The `<body …>` tag of `url` after its scripts ran, in a 1400 × 1000 window.
pub fn body_after_scripts(chrome: &Path, profile: &Path, url: &str) -> String {
    let dom = chromium_window(
        chrome,
        profile,
        &["--allow-file-access-from-files", "--dump-dom", url],
    );
    let body = dom.find("<body").expect("a body");
    dom[body..body + dom[body..].find('>').expect("a whole tag")].to_string()
}

/// The number in `attr="…"` of `tag`.
pub fn attr(tag: &str, attr: &str) -> f64 {
    let key = format!("{attr}=\"");
    let at = tag
        .find(&key)
        .unwrap_or_else(|| panic!("no {attr} in {tag}"))
        + key.len();
    tag[at..at + tag[at..].find('"').expect("closed")]
        .parse()
        .unwrap_or_else(|_| panic!("{attr} in {tag}"))
}
