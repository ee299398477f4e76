//! Point-cloud files: the shared real clouds, round trips through the model
//! writers, hand-written PCD and PLY files, units and E57 poses; damaged or
//! hostile input in [`hostile`].

use std::io::Write as _;
use std::path::{Path, PathBuf};

use cpsplan::model::{ModelPoint, ModelStation};
use cpsplan_cli::formats::cloud::{
    encode_las, encode_ply, encode_stations_ply, parse_cloud, read_cloud, scan_colour, scan_number,
    Cloud, CloudFormat, CloudReadOptions, LengthUnit,
};
use proptest::prelude::*;

mod hostile;

const CLOUDS_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/clouds");

/// The table in clouds/SOURCES.md: file, points, and the extent (min, max)
/// in metres.
const SHARED: &[(&str, u64, [f64; 3], [f64; 3])] = &[
    (
        "pcl_room_scan1.pcd",
        112_586,
        [-13.8, -6.5, -1.35],
        [15.5, 8.0, 1.71],
    ),
    (
        "velodyne_outdoor_scan_251370668.pcd",
        69_088,
        [-23.3, -74.7, -3.0],
        [19.0, 8.9, 10.8],
    ),
    (
        "pump_room_scan.e57",
        155_201,
        [-2.90, -5.30, -1.90],
        [1.72, -0.79, 1.84],
    ),
];

/// The autzen LAZ: points, and its size in feet (SOURCES.md).
const AUTZEN: (&str, u64, [f64; 3]) = ("autzen_trim.laz", 110_000, [1177.0, 563.0, 114.0]);

/// The shared clouds' directory, or `None` after saying, past the test
/// harness's capture, that `test` is skipped.
fn shared_clouds(test: &str) -> Option<PathBuf> {
    let dir = Path::new(CLOUDS_DIR);
    if !dir.is_dir() {
        let _ = std::io::stderr().write_all(
            format!("SKIPPED {test}: needs the shared clouds in ../shared/clouds\n").as_bytes(),
        );
        return None;
    }
    Some(dir.to_path_buf())
}

fn read(path: &Path, options: &CloudReadOptions) -> Cloud {
    read_cloud(path, options, &mut |_, _| {}).unwrap_or_else(|e| panic!("{e}"))
}

fn extent(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// An error's message is one line that starts with the file's name.
fn assert_one_line(e: &impl std::fmt::Display, name: &str) {
    let m = e.to_string();
    assert!(
        !m.contains('\n') && !m.contains('\r'),
        "multi-line message: {m:?}"
    );
    assert!(m.starts_with(name), "message does not name {name}: {m}");
}

#[test]
fn shared_clouds_read_with_their_counts_and_extents() {
    let Some(dir) = shared_clouds("shared_clouds_read_with_their_counts_and_extents") else {
        return;
    };
    for &(file, count, lo, hi) in SHARED {
        let mut reports = Vec::new();
        let cloud = read_cloud(
            &dir.join(file),
            &CloudReadOptions::default(),
            &mut |d, t| reports.push((d, t)),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(cloud.points.len() as u64, count, "{file}");
        assert_eq!(cloud.points_in_file, count, "{file}");
        assert_eq!(
            cloud.points_dropped, 0,
            "{file}: no point is NaN or flagged"
        );
        assert_eq!(cloud.scans.len(), 1, "{file}");
        assert_eq!(cloud.scans[0].points, 0..count as usize, "{file}");
        let (got_lo, got_hi) = extent(&cloud.points);
        for k in 0..3 {
            assert!(
                (got_lo[k] - lo[k]).abs() < 0.06,
                "{file} min {got_lo:?} vs {lo:?}"
            );
            assert!(
                (got_hi[k] - hi[k]).abs() < 0.06,
                "{file} max {got_hi:?} vs {hi:?}"
            );
        }
        assert_eq!(reports.last(), Some(&(count, count)), "{file}");
        assert!(
            reports.len() as u64 >= count / 65_536,
            "{file}: {reports:?}"
        );
    }
}

#[test]
fn shared_pcds_and_e57_carry_their_formats_and_origins() {
    let Some(dir) = shared_clouds("shared_pcds_and_e57_carry_their_formats_and_origins") else {
        return;
    };
    let options = CloudReadOptions::default();
    let room = read(&dir.join("pcl_room_scan1.pcd"), &options);
    assert_eq!(room.format, CloudFormat::Pcd);
    // VIEWPOINT 0 0 0 1 0 0 0: the sensor at the origin.
    assert_eq!(room.scans[0].origin, Some([0.0; 3]));
    let pump = read(&dir.join("pump_room_scan.e57"), &options);
    assert_eq!(pump.format, CloudFormat::E57);
    // The file's data3D has no pose: its local frame is the file's (E57
    // standard, `pose`: identity when absent), the scanner at its origin.
    assert_eq!(pump.scans[0].origin, Some([0.0; 3]));
}

#[test]
fn autzen_is_in_feet_and_read_in_metres() {
    let Some(dir) = shared_clouds("autzen_is_in_feet_and_read_in_metres") else {
        return;
    };
    let (file, count, feet) = AUTZEN;
    let path = dir.join(file);
    let cloud = read(&path, &CloudReadOptions::default());
    assert_eq!(cloud.format, CloudFormat::Laz);
    assert_eq!(cloud.points.len() as u64, count);
    assert_eq!(cloud.scans[0].origin, None);
    assert_eq!(
        cloud.notes,
        vec!["LAS coordinates in international feet: converted to metres (× 0.3048)"]
    );
    let (lo, hi) = extent(&cloud.points);
    let size: Vec<f64> = (0..3).map(|k| hi[k] - lo[k]).collect();
    for k in 0..3 {
        assert!(
            (size[k] - feet[k] * 0.3048).abs() < 0.5,
            "size {size:?} m vs {feet:?} ft"
        );
    }
    assert!((size[0] - 359.0).abs() < 1.0 && (size[1] - 172.0).abs() < 1.0);
    assert!((size[2] - 35.0).abs() < 1.0);

    // --units overrides what the file says.
    let as_metres = read(
        &path,
        &CloudReadOptions {
            units: Some(LengthUnit::Metre),
            ..CloudReadOptions::default()
        },
    );
    let (lo_m, hi_m) = extent(&as_metres.points);
    assert!(
        (hi_m[0] - lo_m[0] - feet[0]).abs() < 1.0,
        "{lo_m:?} {hi_m:?}"
    );
    assert_eq!(as_metres.notes.len(), 1, "{:?}", as_metres.notes);
    let us = read(
        &path,
        &CloudReadOptions {
            units: Some(LengthUnit::UsSurveyFoot),
            ..CloudReadOptions::default()
        },
    );
    for (a, b) in us.points.iter().zip(&as_metres.points) {
        for k in 0..3 {
            assert!((a[k] - b[k] * 1200.0 / 3937.0).abs() < 1e-6);
        }
    }
}

/// A model of `scans` scans of `per_scan` points each, spread over tens of
/// metres with sub-millimetre detail.
fn model(scans: u32, per_scan: u32) -> Vec<ModelPoint> {
    let mut points = Vec::new();
    for scan in 0..scans {
        for i in 0..per_scan {
            let t = f64::from(i) * 0.731 + f64::from(scan) * 3.1;
            points.push(ModelPoint {
                position: [
                    1000.0 + 20.0 * t.sin() + f64::from(scan),
                    -250.0 + 15.0 * (1.3 * t).cos(),
                    0.5 + 0.012_345_6 * f64::from(i % 97),
                ],
                scan: scan * 7919 % 70_001,
            });
        }
    }
    points
}

#[test]
fn encoded_las_and_laz_read_back_within_a_tenth_of_a_millimetre() {
    let points = model(5, 300);
    let tmp = tempfile::tempdir().unwrap();
    for compressed in [false, true] {
        let bytes = encode_las(&points, compressed).unwrap();
        let name = if compressed { "model.laz" } else { "model.las" };
        let path = tmp.path().join(name);
        std::fs::write(&path, &bytes).unwrap();
        let cloud = read(&path, &CloudReadOptions::default());
        let format = if compressed {
            CloudFormat::Laz
        } else {
            CloudFormat::Las
        };
        assert_eq!(cloud.format, format);
        assert_eq!(cloud.points.len(), points.len());
        assert!(cloud.notes.is_empty(), "{:?}", cloud.notes);
        for (got, want) in cloud.points.iter().zip(&points) {
            for k in 0..3 {
                assert!(
                    (got[k] - want.position[k]).abs() <= 1e-4,
                    "{got:?} {want:?}"
                );
            }
        }
        let from_memory = parse_cloud(&bytes, format, &CloudReadOptions::default()).unwrap();
        assert_eq!(from_memory.points, cloud.points);

        // The las crate sees the scan, the colour and the software.
        let mut reader = las::Reader::new(std::io::Cursor::new(bytes)).unwrap();
        let header = reader.header().clone();
        assert_eq!(header.generating_software(), "cpsplan");
        assert_eq!(header.point_format().to_u8().unwrap(), 3);
        assert_eq!(header.version(), las::Version::new(1, 2));
        assert_eq!(header.transforms().x.scale, 1e-4);
        let data = reader.read_all().unwrap();
        for (p, want) in data.points().map(Result::unwrap).zip(&points) {
            // Scans numbered from 1 in the file, as in the report's tables.
            let n = want.scan + 1;
            assert_eq!(scan_number(want.scan), n);
            assert_eq!(p.gps_time, Some(f64::from(n)));
            assert_eq!(p.point_source_id, u16::try_from(n).unwrap_or(u16::MAX));
            let [r, g, b] = scan_colour(n).map(|c| u16::from(c) * 257);
            assert_eq!(p.color, Some(las::Color::new(r, g, b)));
            assert!((p.x - want.position[0]).abs() <= 1e-4);
        }
    }
}

#[test]
fn encoded_ply_reads_back_exactly_with_its_scan_and_colour() {
    let points = model(3, 200);
    let bytes = encode_ply(&points).unwrap();
    let cloud = parse_cloud(&bytes, CloudFormat::Ply, &CloudReadOptions::default()).unwrap();
    let want: Vec<[f64; 3]> = points.iter().map(|p| p.position).collect();
    assert_eq!(cloud.points, want);

    let ply = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new()
        .read_ply(&mut bytes.as_slice())
        .unwrap();
    let vertices = &ply.payload["vertex"];
    assert_eq!(vertices.len(), points.len());
    for (v, p) in vertices.iter().zip(&points) {
        use ply_rs_bw::ply::Property;
        let [r, g, b] = scan_colour(p.scan + 1);
        assert_eq!(v["scan"], Property::UInt(p.scan + 1));
        assert_eq!(v["red"], Property::UChar(r));
        assert_eq!(v["green"], Property::UChar(g));
        assert_eq!(v["blue"], Property::UChar(b));
        assert!(matches!(v["intensity"], Property::UShort(_)));
    }
}

#[test]
fn stations_ply_holds_estimates_truths_and_the_route() {
    let stations: Vec<ModelStation> = (0..4)
        .map(|i| ModelStation {
            scan: i,
            truth: [f64::from(i) * 10.0, 1.0, 0.3],
            estimate: [f64::from(i) * 10.0 + 0.01, 1.02, 0.3],
            heading_error_rad: 0.001 * f64::from(i),
            position_sigma_m: (i > 0).then_some(0.002 * f64::from(i)),
        })
        .collect();
    let bytes = encode_stations_ply(&stations).unwrap();
    let cloud = parse_cloud(&bytes, CloudFormat::Ply, &CloudReadOptions::default()).unwrap();
    let estimates: Vec<[f64; 3]> = stations.iter().map(|s| s.estimate).collect();
    assert_eq!(cloud.points, estimates);

    use ply_rs_bw::ply::Property;
    let ply = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new()
        .read_ply(&mut bytes.as_slice())
        .unwrap();
    let v = &ply.payload["vertex"];
    assert_eq!(v[2]["true_x"], Property::Double(20.0));
    assert_eq!(v[3]["heading_error"], Property::Double(0.003));
    assert!(matches!(v[0]["sigma"], Property::Double(s) if s.is_nan()));
    assert_eq!(v[1]["sigma"], Property::Double(0.002));
    // Stations numbered from 1, as the scans in the report.
    assert_eq!(v[0]["scan"], Property::UInt(1));
    assert_eq!(v[3]["scan"], Property::UInt(4));
    let edges = &ply.payload["edge"];
    assert_eq!(edges.len(), 3);
    for (i, e) in edges.iter().enumerate() {
        assert_eq!(e["vertex1"], Property::Int(i as i32));
        assert_eq!(e["vertex2"], Property::Int(i as i32 + 1));
    }
}

const ASCII_PCD: &str = "# .PCD v0.7 - Point Cloud Data file format
VERSION 0.7
FIELDS x y z rgb
SIZE 4 4 4 4
TYPE F F F U
COUNT 1 1 1 1
WIDTH 3
HEIGHT 1
VIEWPOINT 1.5 -2 0.25 0.7071068 0 0 0.7071068
POINTS 3
DATA ascii
1 2 3 4278190335
-1.5 0.25 8 0
0 0 -2.5 16777215
";

#[test]
fn hand_written_ascii_pcd_reads_with_its_viewpoint_origin() {
    let cloud = parse_cloud(
        ASCII_PCD.as_bytes(),
        CloudFormat::Pcd,
        &CloudReadOptions::default(),
    )
    .unwrap();
    assert_eq!(
        cloud.points,
        vec![[1.0, 2.0, 3.0], [-1.5, 0.25, 8.0], [0.0, 0.0, -2.5]]
    );
    // Points as stored: the viewpoint's rotation is not applied.
    assert_eq!(cloud.scans[0].origin, Some([1.5, -2.0, 0.25]));
    assert_eq!(cloud.points_in_file, 3);
}

/// A binary PCD of `points` with fields `_` (4 padding bytes), `x`, `y`, `z`
/// (double) and `label` (uint16), all as `data`.
fn binary_pcd(points: &[[f64; 3]], compressed: bool) -> Vec<u8> {
    let mut rows: Vec<Vec<u8>> = vec![Vec::new(); 5];
    for (i, p) in points.iter().enumerate() {
        rows[0].extend_from_slice(&[0xAB; 4]);
        for k in 0..3 {
            rows[k + 1].extend_from_slice(&p[k].to_le_bytes());
        }
        rows[4].extend_from_slice(&(i as u16).to_le_bytes());
    }
    let data = if compressed {
        // Column-major, LZF-encoded as literal runs of at most 32 bytes.
        let columns: Vec<u8> = rows.concat();
        let mut lzf = Vec::new();
        for run in columns.chunks(32) {
            lzf.push(run.len() as u8 - 1);
            lzf.extend_from_slice(run);
        }
        let mut d = (lzf.len() as u32).to_le_bytes().to_vec();
        d.extend_from_slice(&(columns.len() as u32).to_le_bytes());
        d.extend(lzf);
        d
    } else {
        let mut d = Vec::new();
        for i in 0..points.len() {
            d.extend_from_slice(&rows[0][4 * i..4 * i + 4]);
            for row in &rows[1..4] {
                d.extend_from_slice(&row[8 * i..8 * i + 8]);
            }
            d.extend_from_slice(&rows[4][2 * i..2 * i + 2]);
        }
        d
    };
    let kind = if compressed {
        "binary_compressed"
    } else {
        "binary"
    };
    let mut bytes = format!(
        "VERSION 0.7\nFIELDS _ x y z label\nSIZE 1 8 8 8 2\nTYPE U F F F U\nCOUNT 4 1 1 1 1\n\
         WIDTH {n}\nHEIGHT 1\nVIEWPOINT 10 20 30 1 0 0 0\nPOINTS {n}\nDATA {kind}\n",
        n = points.len()
    )
    .into_bytes();
    bytes.extend(data);
    bytes
}

#[test]
fn hand_written_binary_pcds_read_with_padding_and_viewpoint() {
    let points: Vec<[f64; 3]> = (0..50)
        .map(|i| [f64::from(i) * 0.5, -f64::from(i), 1e-3 * f64::from(i * i)])
        .collect();
    for compressed in [false, true] {
        let bytes = binary_pcd(&points, compressed);
        let cloud = parse_cloud(&bytes, CloudFormat::Pcd, &CloudReadOptions::default())
            .unwrap_or_else(|e| panic!("compressed {compressed}: {e}"));
        assert_eq!(cloud.points, points, "compressed {compressed}");
        assert_eq!(cloud.scans[0].origin, Some([10.0, 20.0, 30.0]));
    }
}

const ASCII_PLY: &str = "ply
format ascii 1.0
comment made by hand
element camera 1
property float px
property list uchar int tags
element vertex 3
property float x
property float y
property float z
property uchar red
property list uchar int ids
element face 1
property list uchar int vertex_indices
end_header
7 2 1 2
0 1 2 255 0
1.5 -2 0.125 0 2 5 6
3 3 3 9 1 4
3 0 1 2
";

#[test]
fn hand_written_ascii_ply_reads() {
    let cloud = parse_cloud(
        ASCII_PLY.as_bytes(),
        CloudFormat::Ply,
        &CloudReadOptions::default(),
    )
    .unwrap();
    assert_eq!(
        cloud.points,
        vec![[0.0, 1.0, 2.0], [1.5, -2.0, 0.125], [3.0, 3.0, 3.0]]
    );
    assert_eq!(cloud.format, CloudFormat::Ply);
    assert_eq!(cloud.scans[0].origin, None);
}

#[test]
fn nan_points_are_refused_by_default_and_dropped_on_request() {
    let pcd = ASCII_PCD.replace("-1.5 0.25 8 0", "nan nan nan 0");
    let ply = ASCII_PLY.replace("1.5 -2 0.125", "1.5 NaN 0.125");
    for (bytes, format) in [
        (pcd.as_bytes(), CloudFormat::Pcd),
        (ply.as_bytes(), CloudFormat::Ply),
    ] {
        let e = parse_cloud(bytes, format, &CloudReadOptions::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{format} data: point 1 has a NaN coordinate (pass --drop-invalid to skip such points)"
            )
        );
        let lenient = CloudReadOptions {
            drop_invalid: true,
            ..CloudReadOptions::default()
        };
        let cloud = parse_cloud(bytes, format, &lenient).unwrap();
        assert_eq!(cloud.points.len(), 2);
        assert_eq!(cloud.points_in_file, 3);
        assert_eq!(cloud.points_dropped, 1);
        assert!(
            cloud.notes.iter().any(|n| n.contains("1 point with a NaN")),
            "{:?}",
            cloud.notes
        );
    }
    let all_nan = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\nnan 0 0\n";
    let lenient = CloudReadOptions {
        drop_invalid: true,
        ..CloudReadOptions::default()
    };
    let e = parse_cloud(all_nan.as_bytes(), CloudFormat::Pcd, &lenient).unwrap_err();
    assert_eq!(
        e.to_string(),
        "PCD data: holds no valid points (all 1 were invalid)"
    );
}

#[test]
fn units_override_scales_other_formats() {
    let options = CloudReadOptions {
        units: Some(LengthUnit::Foot),
        ..CloudReadOptions::default()
    };
    let cloud = parse_cloud(ASCII_PCD.as_bytes(), CloudFormat::Pcd, &options).unwrap();
    assert_eq!(cloud.points[0], [0.3048, 2.0 * 0.3048, 3.0 * 0.3048]);
    assert_eq!(
        cloud.scans[0].origin,
        Some([1.5 * 0.3048, -2.0 * 0.3048, 0.25 * 0.3048])
    );
    assert_eq!(cloud.notes.len(), 1);
}

#[test]
fn empty_inputs_and_files_without_points_hold_no_points() {
    let tmp = tempfile::tempdir().unwrap();
    for ext in ["las", "laz", "e57", "ply", "pcd"] {
        let path = tmp.path().join(format!("x.{ext}"));
        std::fs::write(&path, b"").unwrap();
        let e = read_cloud(&path, &CloudReadOptions::default(), &mut |_, _| {}).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("{}: holds no points", path.display())
        );
    }
    let no_vertices = "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    let e = parse_cloud(
        no_vertices.as_bytes(),
        CloudFormat::Ply,
        &CloudReadOptions::default(),
    )
    .unwrap_err();
    assert_eq!(e.to_string(), "PLY data: holds no points");
    let las = encode_las(&[], false).unwrap();
    let e = parse_cloud(&las, CloudFormat::Las, &CloudReadOptions::default()).unwrap_err();
    assert_eq!(e.to_string(), "LAS data: holds no points");
}

#[test]
fn only_regular_files_of_known_kinds_within_the_size_limit_are_read() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("scan.ply");
    std::fs::create_dir(&dir).unwrap();
    let e = read_cloud(&dir, &CloudReadOptions::default(), &mut |_, _| {}).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("{}: not a regular file", dir.display())
    );

    let fifo = tmp.path().join("pipe.pcd");
    if std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        let e = read_cloud(&fifo, &CloudReadOptions::default(), &mut |_, _| {}).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("{}: not a regular file", fifo.display())
        );
    }

    let xyz = tmp.path().join("scan.xyz");
    std::fs::write(&xyz, b"1 2 3\n").unwrap();
    let e = read_cloud(&xyz, &CloudReadOptions::default(), &mut |_, _| {}).unwrap_err();
    assert!(e.to_string().contains("unknown point-cloud format"), "{e}");

    let pcd = tmp.path().join("room.PCD");
    std::fs::write(&pcd, ASCII_PCD).unwrap();
    let small = CloudReadOptions {
        max_bytes: 100,
        ..CloudReadOptions::default()
    };
    let e = read_cloud(&pcd, &small, &mut |_, _| {}).unwrap_err();
    assert!(
        e.to_string()
            .contains("more than the 100 bytes a cloud file may have"),
        "{e}"
    );
    assert_one_line(&e, &pcd.display().to_string());
    assert_eq!(read(&pcd, &CloudReadOptions::default()).points.len(), 3);

    let few = CloudReadOptions {
        max_points: 2,
        ..CloudReadOptions::default()
    };
    let e = read_cloud(&pcd, &few, &mut |_, _| {}).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}: holds 3 points, more than `limits.max_cloud_points` = 2",
            pcd.display()
        )
    );
}

/// A LAS 1.2 file of one point (1, 2, 3) with a `LASF_Projection` VLR.
fn las_with_projection(record_id: u16, data: Vec<u8>) -> Vec<u8> {
    let mut builder = las::Builder::from((1, 2));
    builder.vlrs.push(las::Vlr {
        user_id: "LASF_Projection".to_string(),
        record_id,
        description: String::new(),
        data,
    });
    let mut writer = las::Writer::new(
        std::io::Cursor::new(Vec::new()),
        builder.into_header().unwrap(),
    )
    .unwrap();
    writer
        .write_point(las::Point {
            x: 1.0,
            y: 2.0,
            z: 3.0,
            ..las::Point::default()
        })
        .unwrap();
    writer.into_inner().unwrap().into_inner()
}

/// A LAS 1.2 file of one point (1, 2, 3) with GeoTIFF keys `keys` (key, value).
fn las_with_geokeys(keys: &[(u16, u16)]) -> Vec<u8> {
    let mut data: Vec<u16> = vec![1, 1, 0, keys.len() as u16];
    for &(key, value) in keys {
        data.extend([key, 0, 1, value]);
    }
    las_with_projection(34735, data.iter().flat_map(|v| v.to_le_bytes()).collect())
}

#[test]
fn wkt_gives_horizontal_and_vertical_units() {
    let wkt = r#"COMPD_CS["NAD83 / Oregon GIC Lambert (ft) + NAVD88 height (ftUS)",PROJCS["NAD83 / Oregon GIC Lambert (ft)",GEOGCS["NAD83",DATUM["NAD83",SPHEROID["GRS 1980",6378137,298.257222101]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Lambert_Conformal_Conic_2SP"],UNIT["foot",0.3048]],VERT_CS["NAVD88 height (ftUS)",VERT_DATUM["NAVD88",2005],UNIT["US survey foot",0.304800609601219]]]"#;
    let mut data = wkt.as_bytes().to_vec();
    data.push(0);
    let bytes = las_with_projection(2112, data);
    let cloud = parse_cloud(&bytes, CloudFormat::Las, &CloudReadOptions::default()).unwrap();
    let p = cloud.points[0];
    assert!(
        (p[0] - 0.3048).abs() < 1e-4 && (p[1] - 0.6096).abs() < 1e-4,
        "{p:?}"
    );
    assert!((p[2] - 3.0 * 1200.0 / 3937.0).abs() < 1e-4, "{p:?}");
    assert_eq!(cloud.notes.len(), 2, "{:?}", cloud.notes);
}

#[test]
fn geotiff_keys_give_horizontal_and_vertical_units() {
    let read = |keys: &[(u16, u16)], units| {
        let options = CloudReadOptions {
            units,
            ..CloudReadOptions::default()
        };
        parse_cloud(&las_with_geokeys(keys), CloudFormat::Las, &options).unwrap()
    };
    let us = 1200.0 / 3937.0;
    let close = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-3);
    // US survey feet across, metres up.
    let cloud = read(&[(3072, 2992), (3076, 9003), (4099, 9001)], None);
    assert!(
        close(cloud.points[0], [us, 2.0 * us, 3.0]),
        "{:?}",
        cloud.points
    );
    assert_eq!(cloud.notes.len(), 1, "{:?}", cloud.notes);
    assert!(cloud.notes[0].starts_with("LAS x and y in US survey feet"));
    // Feet, heights unstated: feet too.
    let cloud = read(&[(3076, 9002)], None);
    assert!(close(cloud.points[0], [0.3048, 0.6096, 0.9144]));
    // Geographic linear units when there is no projected one.
    let cloud = read(&[(2052, 9002)], None);
    assert!(close(cloud.points[0], [0.3048, 0.6096, 0.9144]));
    // Metres, or no units: as stored, without a note.
    for keys in [&[(3076, 9001)][..], &[(1024, 1)][..]] {
        let cloud = read(keys, None);
        assert!(close(cloud.points[0], [1.0, 2.0, 3.0]));
        assert!(cloud.notes.is_empty(), "{:?}", cloud.notes);
    }
    // --units wins, for heights too.
    let cloud = read(&[(3076, 9002)], Some(LengthUnit::UsSurveyFoot));
    assert!(close(cloud.points[0], [us, 2.0 * us, 3.0 * us]));
}

#[test]
fn e57_scans_are_posed_converted_and_flagged_points_dropped() {
    use e57::{
        Quaternion, Record, RecordDataType, RecordName, RecordValue, Transform, Translation,
    };
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("two scans.e57");
    let mut writer = e57::E57Writer::from_file(&path, "file").unwrap();
    let double = |name| Record {
        name,
        data_type: RecordDataType::F64,
    };
    let cartesian = vec![
        double(RecordName::CartesianX),
        double(RecordName::CartesianY),
        double(RecordName::CartesianZ),
        Record {
            name: RecordName::CartesianInvalidState,
            data_type: RecordDataType::Integer { min: 0, max: 2 },
        },
    ];
    let mut scan = writer.add_pointcloud("scan-a", cartesian).unwrap();
    // A quarter turn about z, then a translation.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    scan.set_transform(Some(Transform {
        rotation: Quaternion {
            w: h,
            x: 0.0,
            y: 0.0,
            z: h,
        },
        translation: Translation {
            x: 10.0,
            y: 20.0,
            z: 1.0,
        },
    }));
    for (p, state) in [
        ([1.0, 0.0, 0.0], 0),
        ([0.0, 2.0, 0.0], 2),
        ([0.0, 0.0, 3.0], 0),
    ] {
        let mut values: Vec<RecordValue> = p.iter().map(|&c| RecordValue::Double(c)).collect();
        values.push(RecordValue::Integer(state));
        scan.add_point(values).unwrap();
    }
    scan.finalize().unwrap();
    let spherical = vec![
        double(RecordName::SphericalRange),
        double(RecordName::SphericalAzimuth),
        double(RecordName::SphericalElevation),
    ];
    let mut scan = writer.add_pointcloud("scan-b", spherical).unwrap();
    let quarter = std::f64::consts::FRAC_PI_2;
    for p in [[2.0, 0.0, 0.0], [1.0, quarter, 0.0], [3.0, 0.0, quarter]] {
        scan.add_point(p.iter().map(|&c| RecordValue::Double(c)).collect())
            .unwrap();
    }
    scan.finalize().unwrap();
    writer.finalize().unwrap();
    drop(writer);

    let cloud = read(&path, &CloudReadOptions::default());
    let want = [
        [10.0, 21.0, 1.0],
        [10.0, 20.0, 4.0],
        [2.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 3.0],
    ];
    assert_eq!(cloud.points.len(), want.len());
    for (got, want) in cloud.points.iter().zip(want) {
        for k in 0..3 {
            assert!((got[k] - want[k]).abs() < 1e-12, "{got:?} vs {want:?}");
        }
    }
    assert_eq!(cloud.points_in_file, 6);
    assert_eq!(cloud.points_dropped, 1);
    assert_eq!(cloud.scans.len(), 2);
    assert_eq!(cloud.scans[0].points, 0..2);
    assert_eq!(cloud.scans[0].origin, Some([10.0, 20.0, 1.0]));
    assert_eq!(cloud.scans[1].points, 2..5);
    // Without a pose the scan is in the file frame, its scanner at the origin.
    assert_eq!(cloud.scans[1].origin, Some([0.0; 3]));
    assert_eq!(
        cloud.notes,
        vec!["1 point flagged invalid by the file was dropped"]
    );
}
