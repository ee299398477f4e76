//! End-to-end tests of `cpsplan experiment`: every episode of a file recorded
//! once, the same figures as `explore` with the same parameters, `--resume`
//! redoing exactly the missing and damaged records, shards merged into the
//! whole run, and every refusal one clear line.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use serde_json::Value;

fn cpsplan() -> Command {
    Command::cargo_bin("cpsplan").expect("binary built")
}

/// Two maps × two parameter sets (the parent alone; a parent with two children)
/// × two seeds, a few scans each.
const SMALL: &str = r#"
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

fn write_spec(dir: &Path, text: &str) -> PathBuf {
    let path = dir.join("small.toml");
    std::fs::write(&path, text).expect("write the experiment file");
    path
}

/// The records of `dir`, by file name, with `wall_ms` taken out.
fn records(dir: &Path) -> BTreeMap<String, Value> {
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

fn run(args: &[&str]) -> (bool, String, String) {
    let out = cpsplan().args(args).output().expect("runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn run_ok(args: &[&str]) -> String {
    let (ok, stdout, stderr) = run(args);
    assert!(ok, "cpsplan {args:?} failed: {stderr}");
    stdout
}

/// A refusal: exit code 2 and one line naming `needle`.
fn refused(args: &[&str], needle: &str) {
    let out = cpsplan().args(args).output().expect("runs");
    assert_eq!(out.status.code(), Some(2), "cpsplan {args:?} should fail");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.trim().lines().count(), 1, "one line: {stderr}");
    assert!(
        stderr.contains(needle),
        "cpsplan {args:?}: `{needle}` not in {stderr}"
    );
}

#[test]
fn every_episode_is_recorded_once_with_the_figures_explore_gives() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = write_spec(tmp.path(), SMALL);
    let out = tmp.path().join("run");
    let stdout = run_ok(&[
        "experiment",
        spec.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        stdout.contains("8 run, 0 done before, of 8 episodes"),
        "{stdout}"
    );
    let recs = records(&out);
    let names: Vec<&String> = recs.keys().collect();
    assert_eq!(
        names,
        (0..8)
            .map(|i| format!("{i:06}.json"))
            .collect::<Vec<_>>()
            .iter()
            .collect::<Vec<_>>()
    );
    let plan: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap();
    assert_eq!(plan["episodes"].as_array().unwrap().len(), 8);
    assert_eq!(plan["shard"]["n"], 1);
    assert_eq!(
        std::fs::read_to_string(out.join("experiment.toml")).unwrap(),
        SMALL,
        "the experiment file is kept as given"
    );
    for (i, r) in recs.values().enumerate() {
        assert_eq!(
            r["episode"], plan["episodes"][i],
            "record {i} names its episode"
        );
        assert_eq!(r["outcome"]["status"], "finished");
        let scans = r["outcome"]["scans"].as_array().unwrap();
        assert_eq!(scans.len(), 4, "max_scans = 4");
        assert_eq!(r["outcome"]["summary"]["scans"], 4);
        let team = r["episode"]["parameters"] == "team";
        assert_eq!(
            scans[3]["position_sigma_m"].is_f64(),
            team,
            "the team's scans carry their predicted error"
        );
        assert_eq!(
            r["outcome"]["summary"]["parent_travel_m"],
            scans[3]["parent_travel_m"]
        );
    }
    // The CSV: one row per episode, in order.
    let csv = std::fs::read_to_string(out.join("episodes.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 9, "{csv}");
    assert!(
        rows[1].starts_with("0,site/alone/seed0,builtin:site,"),
        "{}",
        rows[1]
    );
    assert!(
        rows[8].starts_with("7,tunnel/team/seed1,builtin:tunnel,"),
        "{}",
        rows[8]
    );

    // Episode 5 (tunnel, alone, seed 1) run by `explore` with the same parameters.
    let report = tmp.path().join("explore");
    run_ok(&[
        "explore",
        "-q",
        "--builtin",
        "tunnel",
        "--seed",
        "1",
        "--children",
        "0",
        "--alpha",
        "0",
        "--max-scans",
        "4",
        "--out",
        report.to_str().unwrap(),
    ]);
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("summary.json")).unwrap())
            .unwrap();
    let r = &recs["000005.json"];
    assert_eq!(r["episode"]["label"], "tunnel/alone/seed1");
    for key in [
        "scans",
        "coverage",
        "wall_coverage",
        "parent_travel_m",
        "stop_reason",
    ] {
        assert_eq!(r["outcome"]["summary"][key], summary[key], "{key}");
    }
    assert_eq!(r["episode"]["config"], summary["config"]);
}

#[test]
fn resume_redoes_only_the_missing_and_damaged_records() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = write_spec(tmp.path(), SMALL);
    let out = tmp.path().join("run");
    let args = [
        "experiment",
        spec.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    run_ok(&args);
    let whole = records(&out);
    let dir = out.join("records");
    let kept = std::fs::read(dir.join("000000.json")).unwrap();
    // A killed run: one record missing, one cut off mid-write, one temporary
    // file left behind, one record of another episode under a wrong name.
    std::fs::remove_file(dir.join("000003.json")).unwrap();
    let six = std::fs::read(dir.join("000006.json")).unwrap();
    std::fs::write(dir.join("000006.json"), &six[..six.len() / 2]).unwrap();
    std::fs::write(dir.join(".000004.json.123.tmp"), b"{\"format\"").unwrap();
    std::fs::copy(dir.join("000001.json"), dir.join("000002.json")).unwrap();

    refused(&args, "--resume continues the experiment there");
    let mut resume = args.to_vec();
    resume.push("--resume");
    let (ok, stdout, stderr) = run(&resume);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("3 run, 5 done before, of 8 episodes"),
        "{stdout}"
    );
    for name in ["000006.json", ".000004.json.123.tmp", "000002.json"] {
        assert!(stderr.contains(name), "says it redoes {name}: {stderr}");
    }
    assert_eq!(
        records(&out),
        whole,
        "the same records as the uninterrupted run"
    );
    assert_eq!(
        std::fs::read(dir.join("000000.json")).unwrap(),
        kept,
        "a whole record is left as it was"
    );
    assert!(!dir.join(".000004.json.123.tmp").exists());
    // Nothing left to do.
    let stdout = run_ok(&resume);
    assert!(stdout.contains("0 run, 8 done before"), "{stdout}");

    // Another experiment file, or another shard, is not resumed.
    let changed = write_spec(tmp.path(), &SMALL.replace("max_scans = 4", "max_scans = 5"));
    refused(
        &[
            "experiment",
            changed.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--resume",
        ],
        "different experiment file",
    );
    write_spec(tmp.path(), SMALL);
    let mut other_shard = resume.clone();
    other_shard.extend(["--shard", "1/2"]);
    refused(&other_shard, "give the same --shard");
}

#[test]
fn shards_merge_into_the_whole_run() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = write_spec(tmp.path(), SMALL);
    let spec = spec.to_str().unwrap();
    let whole = tmp.path().join("whole");
    run_ok(&[
        "experiment",
        spec,
        "--out",
        whole.to_str().unwrap(),
        "--jobs",
        "1",
    ]);
    let shard = |k: usize| tmp.path().join(format!("shard{k}"));
    for k in 1..=3 {
        let stdout = run_ok(&[
            "experiment",
            spec,
            "--out",
            shard(k).to_str().unwrap(),
            "--shard",
            &format!("{k}/3"),
        ]);
        let expect = [3, 3, 2][k - 1];
        assert!(
            stdout.contains(&format!(
                "of the {expect} episodes of shard {k}/3 (8 in all)"
            )),
            "{stdout}"
        );
    }
    let s = |k: usize| shard(k).to_str().unwrap().to_string();
    let merged = tmp.path().join("merged");
    let m = merged.to_str().unwrap();
    refused(
        &["experiment", "merge", &s(1), &s(2), "--out", m],
        "2 of 8 episodes have no record, the first 2 (site/team/seed0)",
    );
    refused(
        &[
            "experiment",
            "merge",
            &s(1),
            &s(2),
            &s(3),
            &s(1),
            "--out",
            m,
        ],
        "is given twice",
    );
    // A record copied into another shard's directory is a duplicate.
    std::fs::copy(
        shard(1).join("records/000000.json"),
        shard(2).join("records/000000.json"),
    )
    .unwrap();
    refused(
        &["experiment", "merge", &s(1), &s(2), &s(3), "--out", m],
        "episode 0 (site/alone/seed0) is in both",
    );
    std::fs::remove_file(shard(2).join("records/000000.json")).unwrap();
    assert!(!merged.exists(), "a refused merge writes nothing");
    let stdout = run_ok(&["experiment", "merge", &s(1), &s(2), &s(3), "--out", m]);
    assert!(stdout.contains("8 records from 3 directories"), "{stdout}");
    assert_eq!(
        records(&merged),
        records(&whole),
        "sharded = whole, per episode"
    );
    let plan: Value =
        serde_json::from_str(&std::fs::read_to_string(merged.join("plan.json")).unwrap()).unwrap();
    assert!(plan["shard"].is_null());
    assert_eq!(
        std::fs::read_to_string(merged.join("episodes.csv"))
            .unwrap()
            .lines()
            .count(),
        9
    );
    // A different experiment's shard does not merge.
    let other = tmp.path().join("other");
    let other_spec = tmp.path().join("other.toml");
    std::fs::write(&other_spec, SMALL.replace("\"small\"", "\"other\"")).unwrap();
    run_ok(&[
        "experiment",
        other_spec.to_str().unwrap(),
        "--out",
        other.to_str().unwrap(),
        "--shard",
        "3/3",
        "--quiet",
    ]);
    refused(
        &[
            "experiment",
            "merge",
            &s(1),
            &s(2),
            other.to_str().unwrap(),
            "--out",
            tmp.path().join("m2").to_str().unwrap(),
        ],
        "hold different experiments",
    );
}

#[test]
fn bad_experiments_are_refused_in_one_line_before_anything_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let o = out.to_str().unwrap();
    let cases = [
        ("name = \"x\"\nmaps = [\"builtin:moon\"]\n", "moon"),
        (
            "name = \"x\"\nmaps = [\"builtin:site\"]\nplanners = [\"best\"]\n",
            "best",
        ),
        (
            "name = \"x\"\nmaps = [\"no/such/map.yaml\"]\n",
            "no/such/map.yaml",
        ),
        (
            "name = \"x\"\nmaps = [\"builtin:site\"]\n[base]\nrobot.radius = -1.0\n",
            "robot.radius",
        ),
    ];
    for (text, needle) in cases {
        let spec = tmp.path().join("bad.toml");
        std::fs::write(&spec, text).unwrap();
        refused(&["experiment", spec.to_str().unwrap(), "--out", o], needle);
        assert!(!out.exists(), "{text}: nothing written");
    }
    let spec = write_spec(tmp.path(), SMALL);
    let spec = spec.to_str().unwrap();
    for shard in ["0/3", "4/3", "three"] {
        refused(&["experiment", spec, "--out", o, "--shard", shard], "K/N");
    }
    refused(&["experiment", spec], "--out");
    refused(&["experiment", "merge", "--out", o], "DIR");
    refused(
        &[
            "experiment",
            "merge",
            tmp.path().to_str().unwrap(),
            "--out",
            o,
        ],
        "holds no experiment",
    );
    assert!(!out.exists());
}

#[test]
fn a_killed_run_resumes_to_the_same_records() {
    let tmp = tempfile::tempdir().unwrap();
    let text = SMALL
        .replace("count = 2", "count = 4")
        .replace("max_scans = 4", "max_scans = 6");
    let spec = write_spec(tmp.path(), &text);
    let spec = spec.to_str().unwrap();
    let whole = tmp.path().join("whole");
    run_ok(&[
        "experiment",
        spec,
        "--out",
        whole.to_str().unwrap(),
        "--quiet",
    ]);
    let out = tmp.path().join("killed");
    let o = out.to_str().unwrap();
    let bin = assert_cmd::cargo::cargo_bin("cpsplan");
    let mut child = std::process::Command::new(bin)
        .args(["experiment", spec, "--out", o, "--quiet"])
        .spawn()
        .expect("starts");
    // Killed (SIGKILL: no clean-up) once some records are in.
    let done = |dir: &Path| {
        std::fs::read_dir(dir.join("records"))
            .map(|d| {
                d.flatten()
                    .filter(|e| !e.file_name().to_string_lossy().starts_with('.'))
                    .count()
            })
            .unwrap_or(0)
    };
    loop {
        if done(&out) >= 3 || child.try_wait().expect("wait").is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let _ = child.kill();
    let _ = child.wait();
    let before = done(&out);
    if before == 16 {
        eprintln!("the run finished before it could be killed; the resume has nothing to do");
    }
    let stdout = run_ok(&["experiment", spec, "--out", o, "--resume"]);
    assert!(
        stdout.contains(&format!(
            "{} run, {before} done before, of 16 episodes",
            16 - before
        )),
        "{stdout}"
    );
    assert_eq!(records(&out), records(&whole));
}

#[test]
fn the_report_draws_every_condition_and_tabulates_it() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = write_spec(tmp.path(), SMALL);
    let out = tmp.path().join("run");
    let o = out.to_str().unwrap();
    // Half the episodes first: the report states what it has.
    run_ok(&[
        "experiment",
        spec.to_str().unwrap(),
        "--out",
        o,
        "--shard",
        "1/2",
        "-q",
    ]);
    let stdout = run_ok(&["report", o]);
    assert!(stdout.contains("4 conditions of 4 records"), "{stdout}");
    let md = std::fs::read_to_string(out.join("report/summary.md")).unwrap();
    assert!(md.contains("4 of 8 episodes recorded (shard 1/2)"), "{md}");
    // The whole experiment (merged from both shards).
    let second = tmp.path().join("second");
    run_ok(&[
        "experiment",
        spec.to_str().unwrap(),
        "--out",
        second.to_str().unwrap(),
        "--shard",
        "2/2",
        "-q",
    ]);
    let merged = tmp.path().join("merged");
    let m = merged.to_str().unwrap();
    run_ok(&[
        "experiment",
        "merge",
        o,
        second.to_str().unwrap(),
        "--out",
        m,
    ]);
    let report = tmp.path().join("report");
    let stdout = run_ok(&["report", m, "--out", report.to_str().unwrap()]);
    assert!(
        stdout.contains("4 conditions of 8 records, 10 charts"),
        "{stdout}"
    );
    let md = std::fs::read_to_string(report.join("summary.md")).unwrap();
    for condition in ["site/alone", "site/team", "tunnel/alone", "tunnel/team"] {
        let row = md
            .lines()
            .find(|l| l.starts_with(&format!("| {condition} | 2 |")))
            .unwrap_or_else(|| panic!("no row of {condition}: {md}"));
        assert!(row.contains("| 4.0 ± 0.0 |"), "4 scans each: {row}");
        // The medians over the seeds, with their range.
        let medians = md.split("## Medians over seeds").nth(1).expect("medians");
        let row = medians
            .lines()
            .find(|l| l.starts_with(&format!("| {condition} | 2 |")))
            .unwrap_or_else(|| panic!("no median row of {condition}: {medians}"));
        assert!(row.contains("| 4 (4–4) |"), "4 scans each: {row}");
    }
    let csv = std::fs::read_to_string(report.join("summary.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5);
    for map in ["site", "tunnel"] {
        for chart in ["coverage", "travel", "error", "time", "coverage-travel"] {
            let png = std::fs::read(report.join(format!("{chart}-{map}.png"))).unwrap();
            let img = image::load_from_memory(&png).expect("a PNG");
            assert_eq!((img.width(), img.height()), (1200, 720));
            let svg = std::fs::read_to_string(report.join(format!("{chart}-{map}.svg"))).unwrap();
            assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
            let lines = svg.matches("<polyline").count();
            assert!(lines >= 2, "{chart}-{map}: {lines} lines");
            assert!(
                md.contains(&format!("({chart}-{map}.png)")),
                "summary.md shows {chart}-{map}"
            );
        }
    }
    // All of it in one page, charts inline, nothing fetched.
    let page = std::fs::read_to_string(report.join("report.html")).unwrap();
    assert_eq!(page.matches("<svg").count(), 10);
    assert_eq!(
        page.matches("<tr>").count(),
        10,
        "a header and a row per condition, in the headline and the medians"
    );
    assert!(!page.contains("src=") && !page.contains("href="));
    // The error chart has only the team's line: the parent alone has no CPS chain.
    let svg = std::fs::read_to_string(report.join("error-site.svg")).unwrap();
    assert!(svg.contains("team (2 ep.)") && !svg.contains("alone (2 ep.)"));
    // Again: the earlier report is replaced; a directory of other files is not.
    run_ok(&["report", m, "--out", report.to_str().unwrap(), "-q"]);
    std::fs::write(report.join("notes.txt"), "mine").unwrap();
    refused(
        &["report", m, "--out", report.to_str().unwrap()],
        "notes.txt",
    );
    refused(
        &["report", tmp.path().to_str().unwrap()],
        "holds no experiment",
    );
}

/// The tunnel, the parent alone and with two children, two seeds, with the
/// known-map bound.
const BOUNDED: &str = r#"
name = "bounded"
maps = ["builtin:tunnel"]
seeds = [0, 1]
bound = true

[base]
mission.max_scans = 5

[[parameters]]
name = "alone"
children.count = 0

[[parameters]]
name = "team"
children.count = 2
"#;

#[test]
fn records_carry_the_bound_and_the_report_shows_pages_and_bound() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = write_spec(tmp.path(), BOUNDED);
    let spec = spec.to_str().unwrap();
    let out = tmp.path().join("run");
    let o = out.to_str().unwrap();
    run_ok(&["experiment", spec, "--out", o, "--html", "-q"]);
    let recs = records(&out);
    assert_eq!(recs.len(), 4);
    // Each record's bound is `cpsplan bound`'s for its seed's tunnel.
    for seed in [0u64, 1] {
        let config = tmp.path().join(format!("seed{seed}.toml"));
        std::fs::write(&config, format!("seed = {seed}\n")).unwrap();
        let bound_dir = tmp.path().join(format!("bound{seed}"));
        run_ok(&[
            "bound",
            "--builtin",
            "tunnel",
            "--config",
            config.to_str().unwrap(),
            "--out",
            bound_dir.to_str().unwrap(),
            "-q",
        ]);
        let b: Value =
            serde_json::from_str(&std::fs::read_to_string(bound_dir.join("bound.json")).unwrap())
                .unwrap();
        let greedy: Vec<Value> = b["stations"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["coverage"].clone())
            .collect();
        let of_seed: Vec<&Value> = recs
            .values()
            .filter(|r| r["episode"]["seed"] == seed)
            .collect();
        assert_eq!(of_seed.len(), 2);
        for r in of_seed {
            let rb = &r["bound"];
            assert_eq!(rb["status"], "computed", "{rb}");
            assert_eq!(rb["levels"], b["levels"], "seed {seed}");
            assert_eq!(rb["targets"], b["targets"]);
            assert_eq!(rb["greedy_coverage"], Value::Array(greedy.clone()));
        }
    }
    // A page per episode, written before its record; --resume runs again a
    // finished episode whose page is missing, to the same record.
    for i in 0..4 {
        let page = std::fs::read_to_string(out.join(format!("pages/{i:06}.html"))).unwrap();
        assert!(page.contains("<script id=\"data\" type=\"application/json\">{"));
    }
    std::fs::remove_file(out.join("pages/000002.html")).unwrap();
    let stdout = run_ok(&["experiment", spec, "--out", o, "--html", "--resume"]);
    assert!(stdout.contains("1 run, 3 done before"), "{stdout}");
    assert!(out.join("pages/000002.html").is_file());
    assert_eq!(records(&out), recs);
    // Without --html a missing page is no reason to run again.
    std::fs::remove_file(out.join("pages/000003.html")).unwrap();
    let stdout = run_ok(&["experiment", spec, "--out", o, "--resume"]);
    assert!(stdout.contains("0 run, 4 done before"), "{stdout}");
    // Shards merge with their pages.
    let s1 = tmp.path().join("s1");
    let s2 = tmp.path().join("s2");
    for (k, d) in [(1, &s1), (2, &s2)] {
        run_ok(&[
            "experiment",
            spec,
            "--out",
            d.to_str().unwrap(),
            "--shard",
            &format!("{k}/2"),
            "--html",
            "-q",
        ]);
    }
    let merged = tmp.path().join("merged");
    let stdout = run_ok(&[
        "experiment",
        "merge",
        s1.to_str().unwrap(),
        s2.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert!(stdout.contains("4 records and 4 pages"), "{stdout}");
    assert_eq!(records(&merged), recs);
    // The report: the table against the bound, the bound's line on the
    // coverage chart, and a player of each condition's typical episode.
    let m = merged.to_str().unwrap();
    run_ok(&["report", m, "-q"]);
    let md = std::fs::read_to_string(merged.join("report/summary.md")).unwrap();
    assert!(md.contains("## Against the known-map bound"), "{md}");
    let greedy_90: Vec<f64> = recs
        .values()
        .map(|r| r["bound"]["levels"][0]["greedy_stations"].as_f64().unwrap())
        .collect();
    let mean = (greedy_90[0] + greedy_90[1]) / 2.0;
    let row = md
        .lines()
        .filter(|l| l.matches('|').count() == 10)
        .find(|l| l.starts_with("| alone |") || l.starts_with("| tunnel/alone |"))
        .unwrap_or_else(|| panic!("no bound row of alone: {md}"));
    assert!(row.contains(&format!("| {mean:.1} |")), "{row}");
    let svg = std::fs::read_to_string(merged.join("report/coverage-tunnel.svg")).unwrap();
    assert!(svg.contains("known-map greedy cover (bound)"));
    let page = std::fs::read_to_string(merged.join("report/report.html")).unwrap();
    assert_eq!(
        page.matches("<option value=").count(),
        2,
        "one per condition"
    );
    assert_eq!(
        page.matches("<script type=\"application/json\" id=\"ep-")
            .count(),
        2
    );
    assert!(page.contains("id=\"player-template\""));
    run_ok(&["report", m, "--all-episodes", "-q"]);
    let page = std::fs::read_to_string(merged.join("report/report.html")).unwrap();
    assert_eq!(page.matches("<option value=").count(), 4, "every episode");
}

/// An experiment that runs the oracle beside other planners: the report
/// tabulates each against the oracle of the same map, seed by seed, and the
/// ratios are those of the records (their median over the seeds); planners
/// set in parameter sets pair with the oracle's set just the same.
#[test]
fn the_report_measures_every_planner_against_the_oracle() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = tmp.path().join("oracle.toml");
    std::fs::write(
        &spec,
        "name = \"oracle\"\ndescription = \"paper and the oracle\"\nmaps = [\"builtin:site\"]\n\
         seeds = { from = 0, count = 3 }\nplanners = [\"paper\", \"oracle\"]\n",
    )
    .unwrap();
    let out = tmp.path().join("out");
    let (spec, out_s) = (spec.to_str().unwrap(), out.to_str().unwrap());
    run_ok(&["experiment", spec, "--out", out_s, "--quiet"]);
    run_ok(&["report", out_s, "--quiet"]);
    let md = std::fs::read_to_string(out.join("report/summary.md")).unwrap();
    let table = md
        .split("## Against the oracle")
        .nth(1)
        .expect("the oracle's table");
    let row = table
        .lines()
        .find(|l| l.starts_with("| site/paper |"))
        .expect("the paper planner's row");
    // Seed by seed, scans to 99 % of the paper planner over the oracle's.
    let to99 = |r: &Value| {
        r["outcome"]["scans"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["coverage"].as_f64().unwrap() >= 0.99)
            .map(|s| s["scan"].as_f64().unwrap())
            .unwrap()
    };
    let recs: Vec<Value> = records(&out).into_values().collect();
    let of = |planner: &str, seed: u64| {
        recs.iter()
            .find(|r| r["episode"]["planner"] == planner && r["episode"]["seed"] == seed)
            .map(to99)
            .unwrap()
    };
    let mut ratios: Vec<f64> = (0..3).map(|s| of("paper", s) / of("oracle", s)).collect();
    ratios.sort_by(f64::total_cmp);
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    assert_eq!(cells[2], "3", "{row}");
    let shown: Vec<f64> = cells[5]
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect();
    assert!(
        (shown[0] - ratios[1]).abs() < 0.006,
        "{row}: median {ratios:?}"
    );
    assert!(
        (shown[1] - ratios[2]).abs() < 0.006,
        "{row}: largest {ratios:?}"
    );
    assert!(
        !table.contains("| site/oracle |"),
        "the oracle is not measured against itself"
    );
    // The planners in parameter sets.
    let spec = tmp.path().join("sets.toml");
    std::fs::write(
        &spec,
        "name = \"sets\"\nmaps = [\"builtin:site\"]\nseeds = { from = 0, count = 1 }\n\
         [[parameters]]\nname = \"greedy\"\nparent.planner = \"paper\"\n\
         [[parameters]]\nname = \"truth\"\nparent.planner = \"oracle\"\n",
    )
    .unwrap();
    let out = tmp.path().join("sets");
    let (spec, out_s) = (spec.to_str().unwrap(), out.to_str().unwrap());
    run_ok(&["experiment", spec, "--out", out_s, "--quiet"]);
    run_ok(&["report", out_s, "--quiet"]);
    let md = std::fs::read_to_string(out.join("report/summary.md")).unwrap();
    let table = md.split("## Against the oracle").nth(1).expect("the table");
    let row = table
        .lines()
        .find(|l| l.starts_with("| site/greedy |"))
        .expect("the set's row");
    let shown: f64 = row
        .split('|')
        .nth(5)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let seed0 = of("paper", 0) / of("oracle", 0);
    assert!((shown - seed0).abs() < 0.006, "{row}: seed 0 {seed0}");
}
