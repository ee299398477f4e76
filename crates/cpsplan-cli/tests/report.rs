//! End-to-end tests of `cpsplan report`: every condition drawn and
//! tabulated, the known-map bound, the episodes' pages, the medians over seeds
//! and every planner against the oracle.

mod common;

use serde_json::Value;

use common::*;

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
            // bound.json states the record's figures to 12 digits (formats::tidy).
            assert_eq!(tidied(&rb["levels"]), b["levels"], "seed {seed}");
            assert_eq!(tidied(&rb["targets"]), b["targets"]);
            assert_eq!(tidied(&rb["greedy_coverage"]), Value::Array(greedy.clone()));
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

#[test]
fn hostile_names_stay_text_in_every_table() {
    let tmp = tempfile::tempdir().unwrap();
    let text = "name = \"n|<b>x</b>\"\ndescription = \"two\\nlines <script>\"\n\
                maps = [\"builtin:site\"]\nseeds = { from = 0, count = 1 }\n\
                [base]\nmission.max_scans = 3\n\
                [[parameters]]\nname = \"=HYPERLINK(\\\"http://x\\\")|<img src=x onerror=alert(1)>\"\n\
                children.count = 0\n\
                [[parameters]]\nname = \"plain\"\nchildren.count = 0\n";
    let spec = write_spec(tmp.path(), text);
    let out = tmp.path().join("run");
    let o = out.to_str().unwrap();
    run_ok(&["experiment", spec.to_str().unwrap(), "--out", o, "--quiet"]);
    run_ok(&["report", o, "-q"]);
    let md = std::fs::read_to_string(out.join("report/summary.md")).unwrap();
    assert!(
        !md.contains("<img") && !md.contains("<b>") && !md.contains("<script"),
        "{md}"
    );
    // The headline table: a header, the alignment row and one row a
    // condition, each with the header's number of cells.
    let table: Vec<&str> = md
        .lines()
        .skip_while(|l| !l.starts_with("| condition"))
        .take_while(|l| l.starts_with('|'))
        .collect();
    assert_eq!(table.len(), 4, "{md}");
    let cells = |l: &str| l.replace("\\|", "").matches('|').count();
    assert!(
        table.iter().all(|l| cells(l) == cells(table[0])),
        "{table:?}"
    );
    let html = std::fs::read_to_string(out.join("report/report.html")).unwrap();
    assert!(
        !html.contains("<img") && !html.contains("<b>x"),
        "raw HTML in the page"
    );
    assert!(
        html.contains("&lt;img src=x onerror=alert(1)&gt;"),
        "the name shown as text"
    );
    for csv in ["report/summary.csv", "episodes.csv"] {
        let text = std::fs::read_to_string(out.join(csv)).unwrap();
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        for row in reader.records() {
            for cell in row.unwrap().iter() {
                assert!(
                    cell.parse::<f64>().is_ok() || !cell.starts_with(['=', '+', '-', '@']),
                    "{csv}: a formula cell {cell:?}"
                );
            }
        }
        // The parameter set's own column starts with its name.
        if csv == "episodes.csv" {
            assert!(text.contains("'=HYPERLINK"), "{csv} keeps the name: {text}");
        }
    }
}
