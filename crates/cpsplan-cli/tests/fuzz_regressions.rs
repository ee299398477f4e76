//! Replays every input the fuzz targets keep (`fuzz/regressions/<target>/`:
//! inputs that once crashed; `fuzz/seeds/<target>/`: the seed corpus) through
//! the targets' own bodies, so a fixed crash stays fixed without libFuzzer.

use std::path::{Path, PathBuf};

#[path = "../../../fuzz/src/cloud_grid.rs"]
mod cloud_grid;
#[path = "../../../fuzz/src/config_parse.rs"]
mod config_parse;
#[path = "../../../fuzz/src/map_load.rs"]
mod map_load;
#[path = "../../../fuzz/src/plan_inputs.rs"]
mod plan_inputs;
#[path = "../../../fuzz/src/record_load.rs"]
mod record_load;

/// The files of `fuzz/<kind>/<target>/`, sorted.
fn inputs(kind: &str, target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz")
        .join(kind)
        .join(target);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.is_file() && p.extension().is_none_or(|e| e != "py"))
        .collect();
    files.sort();
    files
}

fn replay(target: &str, run: fn(&[u8])) -> usize {
    let mut n = 0;
    for kind in ["regressions", "seeds"] {
        for file in inputs(kind, target) {
            let bytes = std::fs::read(&file).expect("readable input");
            eprintln!("{}", file.display());
            run(&bytes);
            n += 1;
        }
    }
    n
}

#[test]
fn map_load_inputs_replay_without_panics() {
    assert!(
        !inputs("regressions", "map_load").is_empty(),
        "the PNG palette crashes are kept"
    );
    assert!(replay("map_load", map_load::run) >= 20);
}

#[test]
fn config_parse_inputs_replay_without_panics() {
    assert!(replay("config_parse", config_parse::run) >= 10);
}

#[test]
fn plan_inputs_replay_without_panics() {
    assert!(replay("plan_inputs", plan_inputs::run) >= 5);
}

#[test]
fn cloud_grid_inputs_replay_without_panics() {
    use cpsplan_cli::formats::cloud::{parse_cloud, CloudFormat, CloudReadOptions};
    // Every seed is a valid cloud of its format, so the fuzzer starts from
    // inputs that reach the projection.
    let formats = [
        CloudFormat::Las,
        CloudFormat::Laz,
        CloudFormat::E57,
        CloudFormat::Ply,
        CloudFormat::Pcd,
    ];
    for seed in inputs("seeds", "cloud_grid") {
        let bytes = std::fs::read(&seed).expect("readable seed");
        let format = formats[usize::from(bytes[0]) % formats.len()];
        let cloud = parse_cloud(&bytes[2..], format, &CloudReadOptions::default());
        assert!(cloud.is_ok(), "{}: {:?}", seed.display(), cloud.err());
    }
    assert!(replay("cloud_grid", cloud_grid::run) >= 15);
}

/// Writes the seed corpus of `cloud_grid` (`fuzz/seeds/cloud_grid/`): a small
/// room in each of the five formats, each with a few option bytes. Run it with
/// `cargo test --release -p cpsplan-cli --test fuzz_regressions -- --ignored`.
#[test]
#[ignore = "writes the cloud_grid seeds; run by hand"]
fn write_cloud_grid_seeds() {
    use cpsplan::model::ModelPoint;
    use cpsplan_cli::formats::cloud::{encode_las, encode_ply};

    let mut room = Vec::new();
    for i in 0..12 {
        for j in 0..8 {
            let (x, y) = (i as f64 * 0.25, j as f64 * 0.25);
            room.push([x, y, -1.0]);
            if i == 0 || j == 0 || i == 11 || j == 7 {
                room.push([x, y, 0.0]);
            }
        }
    }
    let points: Vec<ModelPoint> = room
        .iter()
        .enumerate()
        .map(|(k, &p)| ModelPoint {
            position: p,
            scan: (k % 3) as u32,
        })
        .collect();
    let mut pcd_ascii = format!(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n\
         WIDTH {n}\nHEIGHT 1\nVIEWPOINT 1 1 0.5 1 0 0 0\nPOINTS {n}\nDATA ascii\n",
        n = room.len()
    )
    .into_bytes();
    for p in &room {
        pcd_ascii.extend(format!("{} {} {}\n", p[0], p[1], p[2]).bytes());
    }
    let mut pcd_binary = format!(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n\
         WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary\n",
        n = room.len()
    )
    .into_bytes();
    for p in &room {
        for v in p {
            pcd_binary.extend((*v as f32).to_le_bytes());
        }
    }
    let mut ply_ascii = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nend_header\n",
        room.len()
    )
    .into_bytes();
    for p in &room {
        ply_ascii.extend(format!("{} {} {}\n", p[0], p[1], p[2]).bytes());
    }
    let tmp = tempfile::tempdir().unwrap();
    let e57_path = tmp.path().join("room.e57");
    {
        use e57::{Record, RecordDataType, RecordName, RecordValue};
        let mut writer = e57::E57Writer::from_file(&e57_path, "room").unwrap();
        let double = |name| Record {
            name,
            data_type: RecordDataType::F64,
        };
        let mut scan = writer
            .add_pointcloud(
                "scan",
                vec![
                    double(RecordName::CartesianX),
                    double(RecordName::CartesianY),
                    double(RecordName::CartesianZ),
                ],
            )
            .unwrap();
        for p in &room {
            scan.add_point(p.iter().map(|&c| RecordValue::Double(c)).collect())
                .unwrap();
        }
        scan.finalize().unwrap();
        writer.finalize().unwrap();
    }
    let files: [(u8, &str, Vec<u8>); 7] = [
        (0, "las", encode_las(&points, false).unwrap()),
        (1, "laz", encode_las(&points, true).unwrap()),
        (2, "e57", std::fs::read(&e57_path).unwrap()),
        (3, "ply", encode_ply(&points).unwrap()),
        (3, "ply-ascii", ply_ascii),
        (4, "pcd-ascii", pcd_ascii),
        (4, "pcd-binary", pcd_binary),
    ];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds/cloud_grid");
    std::fs::create_dir_all(&dir).unwrap();
    for (format, name, bytes) in files {
        // Plain, lowest ground with an absolute band, outliers and beams.
        for (k, flags) in [0u8, 4 | 8, 16 | 32 | 1].into_iter().enumerate() {
            let mut seed = vec![format, flags];
            seed.extend_from_slice(&bytes);
            std::fs::write(dir.join(format!("{name}-{k}")), seed).unwrap();
        }
    }
}

#[test]
fn record_load_inputs_replay_and_the_real_records_are_accepted() {
    use cpsplan_cli::experiment::store::parse_record;
    let plan = cpsplan_cli::experiment::parse_plan(
        record_load::EXPERIMENT,
        std::path::Path::new("fuzz.toml"),
    )
    .unwrap();
    let seeds = inputs("seeds", "record_load");
    assert_eq!(
        seeds.len(),
        plan.episodes.len(),
        "a real record per episode"
    );
    for file in &seeds {
        let bytes = std::fs::read(file).unwrap();
        let text = std::str::from_utf8(&bytes[2..]).unwrap();
        let index = bytes[0] as usize;
        // Accepted as the episode it names, refused as any other: the
        // target reaches the report, and the plan is the one the seeds are of.
        for claimed in 0..plan.episodes.len() {
            let got = parse_record(text, &plan, claimed);
            assert_eq!(
                got.is_ok(),
                claimed == index,
                "{}: {claimed}",
                file.display()
            );
        }
    }
    assert_eq!(replay("record_load", record_load::run), seeds.len());
}
