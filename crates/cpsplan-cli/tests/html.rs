//! `explore --html`: one self-contained page (no network) holding every scan,
//! checked in headless Chromium where it is installed: the page renders the
//! map, and stepping through the scans changes it.

use std::path::Path;

use serde_json::Value;

mod common;
use common::{body_after_scripts, chromium, chromium_window, explore_page, two_planner_report};

fn data(html: &str) -> Value {
    let open = "<script id=\"data\" type=\"application/json\">";
    let start = html.find(open).expect("the data element") + open.len();
    let end = start + html[start..].find("</script>").expect("its end");
    serde_json::from_str(&html[start..end]).expect("the data are JSON")
}

#[test]
fn the_page_is_self_contained_and_holds_every_scan() {
    let tmp = tempfile::tempdir().unwrap();
    let (_, html) = explore_page(&tmp.path().join("out"), "6", &[]);
    for remote in ["src=\"http", "href=\"http", "url(http", "import(", "fetch("] {
        assert!(
            !html.contains(remote),
            "the page loads nothing: found {remote}"
        );
    }
    let d = data(&html);
    assert_eq!(d["grid"]["width"], 800);
    assert_eq!(d["grid"]["height"], 600);
    let steps = d["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 6);
    let summary: Value = serde_json::from_str(
        &std::fs::read_to_string(tmp.path().join("out/summary.json")).unwrap(),
    )
    .unwrap();
    let last = &steps[5];
    // summary.json states them to 12 digits (formats::tidy).
    let tidy = |v: &Value| v.as_f64().map(cpsplan_cli::formats::tidy::tidy);
    assert_eq!(tidy(&last["coverage"]), summary["coverage"].as_f64());
    assert_eq!(tidy(&last["travel"]), summary["parent_travel_m"].as_f64());
    // The default team: two children, their AND regions and the error of each scan.
    assert_eq!(last["children"].as_array().unwrap().len(), 2);
    assert!(steps
        .iter()
        .any(|s| !s["and"].as_array().unwrap().is_empty()));
    assert!(steps[1..]
        .iter()
        .all(|s| s["sigma_mm"].is_f64() && s["ellipse"].is_array()));
    // The raster: three bytes per cell, deflated.
    use base64::Engine as _;
    let z = base64::engine::general_purpose::STANDARD
        .decode(d["cells"].as_str().unwrap())
        .unwrap();
    let mut raw = Vec::new();
    use std::io::Read as _;
    flate2::read::ZlibDecoder::new(&z[..])
        .read_to_end(&mut raw)
        .unwrap();
    assert_eq!(raw.len(), 3 * 800 * 600);
    let seen: Vec<u16> = raw
        .chunks(3)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .collect();
    assert!(seen.iter().all(|&s| s <= 6));
    assert!(seen.contains(&1) && seen.contains(&6));
    // A cell seen at all is known at the end.
    assert!(raw.chunks(3).all(|c| (c[0] | c[1] == 0) == (c[2] == 0)));
}

/// Pixels of the page's colours for free, occupied and unknown cells in `png`.
fn colours(png: &Path) -> [usize; 3] {
    let img = image::open(png).expect("a screenshot").to_rgb8();
    let mut n = [0usize; 3];
    for p in img.pixels() {
        match p.0 {
            [255, 255, 255] => n[0] += 1,
            [31, 41, 51] => n[1] += 1,
            [203, 210, 217] => n[2] += 1,
            _ => {}
        }
    }
    n
}

#[test]
fn chromium_renders_the_map_and_stepping_changes_it() {
    let Some(chrome) = chromium("chromium_renders_the_map_and_stepping_changes_it") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let (path, _) = explore_page(&tmp.path().join("out"), "8", &[]);
    let url = |hash: &str| format!("file://{}#{hash}", path.display());
    let run = |args: &[String]| {
        let mut all = vec!["--hide-scrollbars".to_string()];
        all.extend_from_slice(args);
        chromium_window(&chrome, &tmp.path().join("profile"), &all)
    };
    // The script ran to the end and shows the asked-for scan.
    let dom = run(&["--dump-dom".into(), url("step=3")]);
    assert!(
        dom.contains("data-ready=\"1\""),
        "the page did not finish loading"
    );
    assert!(dom.contains("scan 3 of 8"), "the step label");
    assert!(dom.contains("Coverage, %") && dom.contains("<td>CPS cycles</td>"));
    // Screenshots at the first and the last scan.
    let first = tmp.path().join("first.png");
    let last = tmp.path().join("last.png");
    run(&[format!("--screenshot={}", first.display()), url("step=1")]);
    run(&[format!("--screenshot={}", last.display()), url("step=8")]);
    let (a, b) = (colours(&first), colours(&last));
    // The map is drawn: free, occupied and unknown cells in their colours.
    for (k, name) in ["free", "occupied", "unknown"].iter().enumerate() {
        assert!(a[k] > 200 && b[k] > 200, "{name} pixels: {a:?} {b:?}");
    }
    // Stepping on shows more of the map: fewer unknown pixels, more free ones.
    assert!(b[2] * 10 < a[2] * 9, "unknown pixels {} -> {}", a[2], b[2]);
    assert!(b[0] > a[0], "free pixels {} -> {}", a[0], b[0]);
}

/// With targets the page holds them and every station's measurement of them,
/// draws them, and lists at each scan the targets measured on the way there.
#[test]
fn chromium_draws_the_targets_and_their_measurements() {
    let tmp = tempfile::tempdir().unwrap();
    let (path, html) = explore_page(&tmp.path().join("out"), "10", &["--place-targets", "5"]);
    let d = data(&html);
    let targets = d["targets"].as_array().unwrap();
    assert!(!targets.is_empty() && targets[0]["name"] == "P1" && targets[0]["kind"] == "placed");
    let steps = d["steps"].as_array().unwrap();
    let sights: usize = steps
        .iter()
        .map(|s| s["sights"].as_array().unwrap().len())
        .sum();
    assert!(sights >= 2, "{sights} measurements of targets");
    assert!(steps.iter().all(|s| s["smoothed_mm"].is_f64()));
    let Some(chrome) = chromium("chromium_draws_the_targets_and_their_measurements") else {
        return;
    };
    let shot = tmp.path().join("last.png");
    chromium_window(
        &chrome,
        &tmp.path().join("profile"),
        &[
            "--hide-scrollbars".to_string(),
            format!("--screenshot={}", shot.display()),
            format!("file://{}#step=10", path.display()),
        ],
    );
    // The targets are drawn in their colour (#00796b).
    let img = image::open(&shot).expect("a screenshot").to_rgb8();
    let teal = img.pixels().filter(|p| p.0 == [0, 121, 107]).count();
    assert!(teal > 20, "{teal} target pixels");
}

/// An experiment's `report.html` shows its episodes' pages in a player: the
/// address picks the episode and the scan, and the player inside shows them.
#[test]
fn chromium_plays_an_experiments_episodes_in_its_report() {
    let Some(chrome) = chromium("chromium_plays_an_experiments_episodes_in_its_report") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let path = two_planner_report(tmp.path(), 6, true);
    let dom = |hash: &str| {
        let url = format!("file://{}#{hash}", path.display());
        body_after_scripts(&chrome, &tmp.path().join("profile"), &url)
    };
    let first = dom("");
    assert!(first.contains("data-player-ready=\"1\""), "{first}");
    assert!(
        first.contains("two \u{2014} site/paper/seed0"),
        "the first episode: {first}"
    );
    assert!(
        first.contains("data-player-step=\"scan 6 of 6\""),
        "{first}"
    );
    let second = dom("episode=1&step=2");
    assert!(second.contains("data-player-ready=\"1\""), "{second}");
    assert!(
        second.contains("two \u{2014} site/gain/seed0"),
        "the chosen episode: {second}"
    );
    assert!(
        second.contains("data-player-step=\"scan 2 of 6\""),
        "{second}"
    );
}
