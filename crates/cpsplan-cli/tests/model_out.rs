//! `explore --cloud-out`: the registered 3D model of a full default episode,
//! read back by the `las` crate and by cpsplan's own PLY reader, lies on the
//! ground-truth walls within the accuracy the report states.

use std::path::Path;

use cpsplan::model::GroundTruthWalls;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan_cli::formats::cloud::{read_cloud, scan_colour, CloudReadOptions};
use las::Reader;

mod common;
use common::{cpsplan, summary};

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

#[test]
fn the_default_episode_writes_a_las_and_a_ply_on_the_walls() {
    let tmp = tempfile::tempdir().unwrap();
    let (las_path, ply_path) = (tmp.path().join("model.las"), tmp.path().join("model.ply"));
    for (out, cloud) in [("report-las", &las_path), ("report-ply", &ply_path)] {
        let run = cpsplan()
            .args(["explore", "-q", "--monte-carlo", "20", "--out"])
            .arg(tmp.path().join(out))
            .args(["--cloud-out", s(cloud)])
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
    }
    let report = summary(&tmp.path().join("report-las"));
    let model = &report["model"];
    assert_eq!(model["poses"], "smoothed");
    // The same model in the filtering poses, beside it.
    let filtering = &model["filtering"];
    let fp95 = filtering["p95_distance_m"].as_f64().unwrap();
    let fmean = filtering["mean_distance_m"].as_f64().unwrap();
    assert!(
        fp95 > 0.0 && fmean <= fp95 && fp95 != model["p95_distance_m"].as_f64().unwrap(),
        "{model}"
    );
    let points = model["points"].as_u64().unwrap() as usize;
    let p95 = model["p95_distance_m"].as_f64().unwrap();
    let mean = model["mean_distance_m"].as_f64().unwrap();
    let scans = report["scans"].as_u64().unwrap() as usize;
    assert!(points > 100_000 && p95 > 0.0 && mean <= p95, "{model}");

    // The LAS, by the las crate.
    let mut reader = Reader::from_path(&las_path).unwrap();
    let header = reader.header().clone();
    assert_eq!(header.number_of_points() as usize, points);
    assert_eq!((header.version().major, header.version().minor), (1, 2));
    let truth = BuiltinMap::Site.generate(0);
    let walls = GroundTruthWalls::new(&truth, 2.0);
    let mut distances = Vec::with_capacity(points);
    let mut seen_scans = vec![false; scans];
    let data = reader.read_all().unwrap();
    for p in data.points() {
        let p = p.unwrap();
        let scan = p.point_source_id as usize;
        assert_eq!(p.gps_time, Some(scan as f64));
        let [r, g, b] = scan_colour(scan as u32);
        let c = p.color.expect("RGB");
        // LAS colours are 16-bit: the 8-bit palette scaled by 257.
        assert_eq!(
            (c.red, c.green, c.blue),
            (257 * u16::from(r), 257 * u16::from(g), 257 * u16::from(b))
        );
        // Scans numbered from 1, as in model.csv and episode.json.
        assert!(scan >= 1, "scan number {scan}");
        seen_scans[scan - 1] = true;
        distances.push(walls.distance([p.x, p.y, p.z]));
    }
    assert!(seen_scans.iter().all(|&s| s), "every scan has points");
    // The stated figures, within the LAS's 0.1 mm quantum.
    let within = distances.iter().filter(|&&d| d <= p95 + 1e-4).count();
    assert!(
        within as f64 >= 0.95 * points as f64,
        "{within} of {points} within {p95}"
    );
    let read_mean = distances.iter().sum::<f64>() / points as f64;
    assert!((read_mean - mean).abs() < 1e-4, "{read_mean} vs {mean}");

    // The PLY, by cpsplan's reader (ply-rs-bw): the same points.
    let ply = read_cloud(&ply_path, &CloudReadOptions::default(), &mut |_, _| {}).unwrap();
    assert_eq!(ply.points.len(), points);
    let stations = read_cloud(
        &tmp.path().join("model.ply-stations.ply"),
        &CloudReadOptions::default(),
        &mut |_, _| {},
    )
    .unwrap();
    assert_eq!(stations.points.len(), scans);
    let csv = std::fs::read_to_string(tmp.path().join("report-las/model.csv")).unwrap();
    assert_eq!(csv.lines().count(), scans + 1);

    // Out and back in: each model becomes a map of the site's walls again; a
    // truncated PLY is refused with nothing written.
    for cloud in [&las_path, &ply_path] {
        let map = tmp.path().join("again.yaml");
        let run = cpsplan()
            .args(["grid", "-q", "--cloud", s(cloud), "--out", s(&map)])
            .args(["--z-min", "0.5", "--z-max", "1.5"])
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let grid = cpsplan_cli::formats::rosmap::load_map(&map).unwrap();
        assert!(grid.count(cpsplan::CellState::Occupied) > 5_000);
    }
    let bytes = std::fs::read(&ply_path).unwrap();
    let cut = tmp.path().join("cut.ply");
    std::fs::write(&cut, &bytes[..bytes.len() - 100]).unwrap();
    let run = cpsplan()
        .args([
            "grid",
            "--cloud",
            s(&cut),
            "--out",
            s(&tmp.path().join("cut.yaml")),
        ])
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    assert!(!tmp.path().join("cut.yaml").exists() && !tmp.path().join("cut.pgm").exists());
}

#[test]
fn a_bad_cloud_name_is_refused_before_the_run_and_nothing_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let out = cpsplan()
        .args(["explore", "--max-scans", "2", "--out"])
        .arg(tmp.path().join("report"))
        .args(["--cloud-out", s(&tmp.path().join("model.xyz"))])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--cloud-out") && err.contains(".las"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0);
    // A directory, or a file inside --out (which the report replaces whole).
    let dir = tmp.path().join("clouds.las");
    std::fs::create_dir(&dir).unwrap();
    let inside = tmp.path().join("report").join("model.las");
    for (cloud, needle) in [(&dir, "is a directory"), (&inside, "lies inside --out")] {
        let out = cpsplan()
            .args(["explore", "--max-scans", "2", "--out"])
            .arg(tmp.path().join("report"))
            .args(["--cloud-out", s(cloud)])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(!tmp.path().join("report").exists(), "nothing written");
    }
}

#[test]
fn a_model_beyond_the_point_limit_is_left_out_of_the_report_or_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let config = tmp.path().join("limits.toml");
    std::fs::write(&config, "[limits]\nmax_cloud_points = 1000\n").unwrap();
    let report = tmp.path().join("report");
    let run = cpsplan()
        .args([
            "explore",
            "-q",
            "--max-scans",
            "2",
            "--config",
            s(&config),
            "--out",
            s(&report),
        ])
        .output()
        .unwrap();
    assert!(run.status.success());
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(err.contains("limits.max_cloud_points"), "{err}");
    assert!(summary(&report)["model"].is_null());
    assert!(!report.join("model.csv").exists());
    // With --cloud-out the model is the point: exit 2, nothing written.
    let other = tmp.path().join("other");
    let cloud = tmp.path().join("model.laz");
    let run = cpsplan()
        .args([
            "explore",
            "-q",
            "--max-scans",
            "2",
            "--config",
            s(&config),
            "--out",
            s(&other),
        ])
        .args(["--cloud-out", s(&cloud)])
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(2));
    assert!(!other.exists() && !cloud.exists());
    assert!(!tmp.path().join("model.laz-stations.ply").exists());
}

/// An existing cloud or stations file is refused before the run without
/// `--force` and replaced with it; `x.laz` and `x.ply` keep stations of their
/// own.
#[test]
fn an_existing_cloud_is_replaced_only_with_force() {
    let tmp = tempfile::tempdir().unwrap();
    let explore = |cloud: &Path, force: bool| {
        let mut c = cpsplan();
        c.args(["explore", "-q", "--max-scans", "2", "--out"])
            .arg(tmp.path().join("report"))
            .args(["--cloud-out", s(cloud)]);
        if force {
            c.arg("--force");
        }
        c.output().unwrap()
    };
    let laz = tmp.path().join("x.LAZ");
    let ply = tmp.path().join("x.Ply");
    std::fs::write(&laz, b"keep me").unwrap();
    let run = explore(&laz, false);
    assert_eq!(run.status.code(), Some(2));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("already exists") && err.contains("--force"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert_eq!(std::fs::read(&laz).unwrap(), b"keep me");
    assert!(!tmp.path().join("report").exists(), "nothing written");
    // Its stations file alone blocks it too.
    std::fs::remove_file(&laz).unwrap();
    std::fs::write(tmp.path().join("x.LAZ-stations.ply"), b"keep me").unwrap();
    let run = explore(&laz, false);
    assert_eq!(run.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&run.stderr).contains("x.LAZ-stations.ply"));
    assert!(!laz.exists());
    // With --force both are replaced; the PLY beside keeps its own stations.
    assert!(explore(&laz, true).status.success());
    std::fs::remove_dir_all(tmp.path().join("report")).unwrap();
    assert!(explore(&ply, false).status.success());
    for (cloud, stations) in [(&laz, "x.LAZ-stations.ply"), (&ply, "x.Ply-stations.ply")] {
        let header = std::fs::read(cloud).unwrap();
        assert_ne!(header, b"keep me");
        let stations = std::fs::read(tmp.path().join(stations)).unwrap();
        assert!(stations.starts_with(b"ply"), "{cloud:?}");
    }
}

/// `--cloud-out` whose points cannot be held (10 m walls sampled every
/// millimetre) under an 8 GB address-space limit: refused in one line with
/// the estimate, before the first point is made, with nothing left behind.
#[test]
fn a_model_larger_than_the_memory_is_refused_before_it_is_made() {
    let tmp = tempfile::tempdir().unwrap();
    let (report, cloud) = (tmp.path().join("report"), tmp.path().join("m.las"));
    let args = [
        "explore",
        "--builtin",
        "site",
        "--max-scans",
        "20",
        "--cloud-out",
        s(&cloud),
        "--wall-height",
        "10",
        "--vertical-step",
        "0.001",
        "--out",
        s(&report),
        "-q",
    ];
    let Some(run) = common::run_under_address_limit(8 << 20, &args) else {
        return;
    };
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    for needle in [
        "--cloud-out",
        "points is estimated to need",
        "address-space limit",
    ] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    assert_eq!(
        std::fs::read_dir(tmp.path()).unwrap().count(),
        0,
        "nothing left"
    );
}

/// A 12 m × 8 m room as a LAS in international feet at state-plane-like
/// coordinates, its floor 425 ft up and tilted, with a GeoTIFF key directory;
/// `grid` (here with a `--transform` too) and `explore --cloud-out` write the
/// model back in the source's feet, on its floor, with its key directory.
#[test]
fn a_cloud_derived_maps_model_lies_in_its_source_frame() {
    use las::{Builder, Transform, Vector, Vlr, Writer};
    const FOOT: f64 = 0.3048;
    let (x0, y0, floor) = (636_000.0, 849_000.0, 425.0);
    let floor_at = |x: f64, y: f64| floor + (0.01 * x - 0.005 * y) / FOOT;
    let mut local: Vec<[f64; 3]> = Vec::new();
    let (w, h) = (12.0, 8.0);
    let mut x = 0.025;
    while x < w {
        let mut y = 0.025;
        while y < h {
            local.push([x, y, 0.0]);
            y += 0.05;
        }
        x += 0.05;
    }
    let mut z = 0.0;
    while z <= 3.0 {
        let mut t = 0.0;
        while t <= w {
            local.push([t, 0.0, z]);
            local.push([t, h, z]);
            t += 0.05;
        }
        let mut t = 0.0;
        while t <= h {
            local.push([0.0, t, z]);
            local.push([w, t, z]);
            t += 0.05;
        }
        z += 0.05;
    }
    let keys: Vec<u8> = [1u16, 1, 0, 2, 1024, 0, 1, 1, 3076, 0, 1, 9002]
        .iter()
        .flat_map(|k| k.to_le_bytes())
        .collect();
    let mut builder = Builder::from((1, 2));
    builder.transforms = Vector {
        x: Transform {
            scale: 0.001,
            offset: x0,
        },
        y: Transform {
            scale: 0.001,
            offset: y0,
        },
        z: Transform {
            scale: 0.001,
            offset: floor,
        },
    };
    builder.vlrs.push(Vlr {
        user_id: "LASF_Projection".into(),
        record_id: 34735,
        description: "GeoTiff GeoKeyDirectoryTag".into(),
        data: keys.clone(),
    });
    let tmp = tempfile::tempdir().unwrap();
    let source = tmp.path().join("room.las");
    {
        let mut writer = Writer::from_path(&source, builder.into_header().unwrap()).unwrap();
        for p in &local {
            writer
                .write_point(las::Point {
                    x: x0 + p[0] / FOOT,
                    y: y0 + p[1] / FOOT,
                    z: floor_at(p[0], p[1]) + p[2] / FOOT,
                    ..Default::default()
                })
                .unwrap();
        }
        writer.close().unwrap();
    }
    let map = tmp.path().join("room.yaml");
    cpsplan()
        .args(["grid", "-q", "--cloud", s(&source), "--out", s(&map)])
        .args(["--transform=-193850,-258780,30deg"])
        .assert()
        .success();
    let model = tmp.path().join("model.las");
    cpsplan()
        .args(["explore", "-q", "--map", s(&map), "--max-scans", "2"])
        .args([
            "--out",
            s(&tmp.path().join("report")),
            "--cloud-out",
            s(&model),
        ])
        .assert()
        .success();
    let mut reader = Reader::from_path(&model).unwrap();
    let crs: Vec<Vlr> = reader
        .header()
        .vlrs()
        .iter()
        .filter(|v| v.user_id == "LASF_Projection")
        .cloned()
        .collect();
    assert_eq!(crs.len(), 1);
    assert_eq!((crs[0].record_id, &crs[0].data), (34735, &keys));
    let data = reader.read_all().unwrap();
    let points: Vec<las::Point> = data.points().map(Result::unwrap).collect();
    assert!(points.len() > 1000, "{} points", points.len());
    let (mut lowest, mut highest) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in &points {
        let (lx, ly) = ((p.x - x0) * FOOT, (p.y - y0) * FOOT);
        assert!(
            (-0.3..w + 0.3).contains(&lx) && (-0.3..h + 0.3).contains(&ly),
            "({lx}, {ly}) m is off the room"
        );
        let above = p.z - floor_at(lx, ly);
        lowest = lowest.min(above);
        highest = highest.max(above);
    }
    assert!(
        lowest.abs() < 0.3,
        "the model's floor {lowest} ft off the source's"
    );
    assert!(
        (highest - 2.0 / FOOT).abs() < 0.3,
        "walls up to {highest} ft"
    );
}
