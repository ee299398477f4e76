//! `explore --field-data`: the clouds and readings a real team would have
//! recorded, two files per scan, readable by the project's own readers, all or
//! nothing.

use std::path::Path;

use cpsplan_cli::formats::cloud::{read_cloud, CloudReadOptions};
use cpsplan_cli::formats::readings::parse_readings;

mod common;
use common::{cpsplan, summary};

#[test]
fn every_scan_has_its_cloud_and_readings() {
    let tmp = tempfile::tempdir().unwrap();
    let (out, field) = (tmp.path().join("out"), tmp.path().join("field"));
    cpsplan()
        .args([
            "explore",
            "-q",
            "--builtin",
            "site",
            "--max-scans",
            "6",
            "--out",
        ])
        .arg(&out)
        .arg("--field-data")
        .arg(&field)
        .assert()
        .success();
    let scans = summary(&out)["scans"].as_u64().unwrap() as usize;
    let mut names: Vec<String> = std::fs::read_dir(&field)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut expected: Vec<String> = (1..=scans)
        .flat_map(|n| [format!("readings-{n:04}.csv"), format!("scan-{n:04}.ply")])
        .chain(["field.json".to_string(), "config.toml".to_string()])
        .collect();
    expected.sort();
    assert_eq!(names, expected);
    // Each cloud in its scanner's frame: around the origin, within the range.
    for n in 1..=scans {
        let path = field.join(format!("scan-{n:04}.ply"));
        let cloud = read_cloud(&path, &CloudReadOptions::default(), &mut |_, _| {}).unwrap();
        assert!(cloud.points.len() > 100, "{}", path.display());
        let far = cloud
            .points
            .iter()
            .map(|p| p.iter().map(|v| v * v).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        assert!(far < 21.0, "{far}");
    }
    let names: Vec<String> = names.into_iter().filter(|n| n.ends_with(".csv")).collect();
    let mut stations = Vec::new();
    for (k, name) in names.iter().enumerate() {
        let path = field.join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        let readings = parse_readings(&text, &path).unwrap();
        if k == 0 {
            // The start measures no child before the first move.
            assert!(readings.iter().all(|r| r.station == "S0000"));
            continue;
        }
        // Every later scan: the foresights from the station before, then at
        // least the new station's two backsights to the children.
        let last = &readings.last().unwrap().station;
        let own = readings.iter().filter(|r| &r.station == last).count();
        assert!(own >= 2, "{name}: {own} readings from {last}");
        assert!(readings
            .iter()
            .all(|r| r.slope_distance_m > 1.0 && r.slope_distance_m < 25.0));
        stations.push(last.clone());
    }
    // The scan stations come in order, each a new one.
    assert!(stations.windows(2).all(|w| w[0] < w[1]), "{stations:?}");
}

#[test]
fn a_team_without_two_children_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let (out, field) = (tmp.path().join("out"), tmp.path().join("field"));
    let assert = cpsplan()
        .args(["explore", "-q", "--children", "1", "--out"])
        .arg(&out)
        .arg("--field-data")
        .arg(&field)
        .assert()
        .code(2);
    let err = String::from_utf8_lossy(&assert.get_output().stderr).into_owned();
    assert!(
        err.contains("--field-data") && err.lines().count() == 1,
        "{err}"
    );
    assert!(!out.exists() && !field.exists());
}

#[test]
fn a_directory_of_other_files_is_refused_untouched() {
    let tmp = tempfile::tempdir().unwrap();
    let (out, field) = (tmp.path().join("out"), tmp.path().join("field"));
    std::fs::create_dir(&field).unwrap();
    std::fs::write(field.join("notes.txt"), b"mine").unwrap();
    cpsplan()
        .args(["explore", "-q", "--max-scans", "2", "--out"])
        .arg(&out)
        .arg("--field-data")
        .arg(&field)
        .assert()
        .code(2);
    assert_eq!(std::fs::read(field.join("notes.txt")).unwrap(), b"mine");
    assert_eq!(std::fs::read_dir(&field).unwrap().count(), 1);
    assert!(!Path::new(&out).exists());
}
