//! ROS map_server maps: the shared real maps, P2/P5/PNG variants, negate, raw mode,
//! save/load round trips and bad inputs.

use std::collections::HashSet;
use std::fs;
use std::path::{Path, PathBuf};

use cpsplan::world::resample_conservative;
use cpsplan::{Cell, CellState, GridGeometry, OccupancyGrid, Point};
use cpsplan_cli::formats::rosmap::{
    load_any, load_image_map, load_map, save_map, FormatError, MapMetadata, MapMode,
};
use proptest::prelude::*;
use proptest::test_runner::FileFailurePersistence;

const MAPS_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/maps");

/// The table in maps/SOURCES.md: (YAML stem, width, height, resolution, free, occ, unknown).
const EXPECTED: &[(&str, usize, usize, f64, f64, f64, f64)] = &[
    ("aces_building", 1129, 1134, 0.05, 0.255, 0.014, 0.730),
    ("aws_bookstore", 384, 384, 0.05, 0.420, 0.034, 0.547),
    ("aws_small_house", 500, 500, 0.05, 0.252, 0.014, 0.734),
    ("aws_small_warehouse", 1536, 1504, 0.02, 0.253, 0.006, 0.740),
    (
        "cit_tsudanuma_campus",
        5500,
        4416,
        0.05,
        0.262,
        0.007,
        0.732,
    ),
    ("intel_lab", 888, 848, 0.05, 0.283, 0.017, 0.700),
    ("mit_csail_3rd_floor", 1597, 1208, 0.05, 0.180, 0.011, 0.810),
    (
        "mit_stata_basement",
        1300,
        1300,
        0.0504,
        0.163,
        0.009,
        0.828,
    ),
    ("nav2_depot", 604, 307, 0.05, 0.968, 0.032, 0.000),
    ("nav2_warehouse", 1006, 1674, 0.03, 0.845, 0.018, 0.137),
    ("turtlebot3_world", 384, 384, 0.05, 0.054, 0.005, 0.941),
    ("utexas_gdc_floor3", 1857, 1255, 0.05, 0.331, 0.030, 0.639),
    ("willow_garage", 566, 608, 0.10, 0.317, 0.002, 0.681),
    ("yujin_rnd_office", 732, 389, 0.05, 0.214, 0.024, 0.762),
];

/// The shared real maps' YAML files, or `None` after saying, past the test
/// harness's capture, that `test` is skipped.
fn shared_maps(test: &str) -> Option<Vec<PathBuf>> {
    let dir = Path::new(MAPS_DIR);
    if !dir.is_dir() {
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED {test}: needs the shared real maps in ../shared/maps (see README)"
        );
        return None;
    }
    let mut yamls: Vec<PathBuf> = fs::read_dir(dir)
        .expect("read maps dir")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    yamls.sort();
    Some(yamls)
}

fn fraction(grid: &OccupancyGrid, state: CellState) -> f64 {
    grid.count(state) as f64 / grid.cells().len() as f64
}

#[test]
fn every_shared_map_loads_with_the_documented_fractions() {
    let Some(yamls) = shared_maps("every_shared_map_loads_with_the_documented_fractions") else {
        return;
    };
    assert!(!yamls.is_empty(), "no YAML files in {MAPS_DIR}");
    let mut checked = 0;
    for yaml in &yamls {
        let grid = load_map(yaml).unwrap_or_else(|e| panic!("{e}"));
        let meta = MapMetadata::read(yaml).unwrap();
        let g = grid.geometry();
        assert_eq!(g.resolution, meta.resolution);
        assert_eq!(g.origin, Point::new(meta.origin[0], meta.origin[1]));
        assert_eq!(g.yaw, meta.origin[2]);
        let (free, occ, unk) = (
            fraction(&grid, CellState::Free),
            fraction(&grid, CellState::Occupied),
            fraction(&grid, CellState::Unknown),
        );
        let stem = yaml.file_stem().unwrap().to_str().unwrap();
        println!(
            "{stem:24} {}x{} res {} free {free:.3} occ {occ:.3} unk {unk:.3}",
            g.width, g.height, g.resolution
        );
        let Some(&(_, w, h, res, ef, eo, eu)) = EXPECTED.iter().find(|e| e.0 == stem) else {
            println!("note: {stem} is not in the table; only checked that it loads");
            assert!(occ > 0.0 && free > 0.0, "{stem}: implausible map");
            continue;
        };
        assert_eq!((g.width, g.height), (w, h), "{stem}: size");
        assert!((g.resolution - res).abs() < 1e-12, "{stem}: resolution");
        for (name, got, want) in [("free", free, ef), ("occ", occ, eo), ("unknown", unk, eu)] {
            assert!(
                (got - want).abs() <= 0.01,
                "{stem}: {name} fraction {got:.4}, SOURCES.md says {want}"
            );
        }
        checked += 1;
    }
    assert_eq!(
        checked,
        EXPECTED.len(),
        "every map of SOURCES.md is present"
    );
    let depot = load_map(&Path::new(MAPS_DIR).join("nav2_depot.yaml")).unwrap();
    assert_eq!(
        depot.count(CellState::Unknown),
        0,
        "free_thresh 0.25: no unknown"
    );
    let stata = MapMetadata::read(&Path::new(MAPS_DIR).join("mit_stata_basement.yaml")).unwrap();
    // The YAML really says 3.14, not π: the map is rotated by 179.91°.
    #[allow(clippy::approx_constant)]
    let yaw = 3.14;
    assert_eq!(stata.origin, [25.9, 48.5, yaw]);
}

#[test]
fn shared_maps_resampled_keep_every_obstacle() {
    let Some(yamls) = shared_maps("shared_maps_resampled_keep_every_obstacle") else {
        return;
    };
    for yaml in &yamls {
        let grid = load_map(yaml).unwrap();
        let coarse = resample_conservative(&grid, 0.1);
        let (src, dst) = (grid.geometry(), coarse.geometry());
        let (ew, eh) = src.extent();
        assert!(dst.extent().0 >= ew - 1e-9 && dst.extent().0 < ew + 0.1 + 1e-9);
        assert!(dst.extent().1 >= eh - 1e-9 && dst.extent().1 < eh + 0.1 + 1e-9);
        let mut blocks = HashSet::new();
        for (i, &s) in grid.cells().iter().enumerate() {
            if s != CellState::Occupied {
                continue;
            }
            let centre = src.cell_center(src.cell(i));
            let c = dst.world_to_cell(centre).unwrap_or_else(|| {
                panic!("{}: centre of {:?} outside", yaml.display(), src.cell(i))
            });
            assert_eq!(coarse.get(c), CellState::Occupied, "{}", yaml.display());
            blocks.insert(c);
        }
        let occupied = coarse.count(CellState::Occupied);
        assert!(occupied >= blocks.len(), "{}", yaml.display());
        // Free coarse cells hold only free source centres: never more free area.
        let coarse_free_area = fraction(&coarse, CellState::Free) * dst.extent().0 * dst.extent().1;
        let free_area = fraction(&grid, CellState::Free) * ew * eh;
        assert!(coarse_free_area <= free_area + 1e-6, "{}", yaml.display());
        println!(
            "{:24} {} occupied source cells -> {} occupied blocks of {}",
            yaml.file_stem().unwrap().to_string_lossy(),
            grid.count(CellState::Occupied),
            occupied,
            coarse.cells().len()
        );
    }
}

/// Pixel rows (top first) used by the small hand-written maps below.
const PIXELS: [[u8; 4]; 3] = [[0, 254, 205, 100], [255, 128, 50, 200], [254, 254, 0, 205]];

fn write_yaml(dir: &Path, name: &str, image: &str, extra: &str) -> PathBuf {
    let path = dir.join(name);
    fs::write(
        &path,
        format!(
            "image: {image}\nresolution: 0.5\norigin: [1.0, -2, 0.25]\n\
             occupied_thresh: 0.65\nfree_thresh: 0.196\n{extra}"
        ),
    )
    .unwrap();
    path
}

fn write_p5(path: &Path) {
    let mut bytes = b"P5\n# a comment\n4 3\n255\n".to_vec();
    bytes.extend(PIXELS.iter().flatten());
    fs::write(path, bytes).unwrap();
}

fn write_p2(path: &Path) {
    let mut text = String::from("P2\n# CREATOR: hand\n4 3\n255\n");
    for row in PIXELS {
        let row: Vec<String> = row.iter().map(|v| v.to_string()).collect();
        text.push_str(&row.join(" "));
        text.push('\n');
    }
    fs::write(path, text).unwrap();
}

#[test]
fn p2_ascii_loads_like_p5_and_rows_are_flipped() {
    let dir = tempfile::tempdir().unwrap();
    write_p5(&dir.path().join("b.pgm"));
    write_p2(&dir.path().join("a.pgm"));
    let p5 = load_map(&write_yaml(dir.path(), "b.yaml", "b.pgm", "negate: 0\n")).unwrap();
    let p2 = load_map(&write_yaml(dir.path(), "a.yaml", "a.pgm", "negate: 0\n")).unwrap();
    assert_eq!(p2, p5);
    let g = p5.geometry();
    assert_eq!((g.width, g.height, g.resolution), (4, 3, 0.5));
    assert_eq!((g.origin, g.yaw), (Point::new(1.0, -2.0), 0.25));
    use CellState::{Free as F, Occupied as O, Unknown as U};
    // Grid row 0 is the image's last row.
    assert_eq!(p5.cells(), &[F, F, O, U, F, U, O, U, O, F, U, U]);
    assert_eq!(p5.get(Cell::new(0, 2)), O);
}

#[test]
fn negate_inverts_occupancy() {
    let dir = tempfile::tempdir().unwrap();
    write_p5(&dir.path().join("m.pgm"));
    let plain = load_map(&write_yaml(
        dir.path(),
        "plain.yaml",
        "m.pgm",
        "negate: false\n",
    ))
    .unwrap();
    for flag in ["1", "true"] {
        let yaml = write_yaml(
            dir.path(),
            "neg.yaml",
            "m.pgm",
            &format!("negate: {flag}\n"),
        );
        let neg = load_map(&yaml).unwrap();
        for (i, v) in PIXELS.iter().rev().flatten().enumerate() {
            let p = f64::from(*v) / 255.0;
            let want = if p > 0.65 {
                CellState::Occupied
            } else if p < 0.196 {
                CellState::Free
            } else {
                CellState::Unknown
            };
            assert_eq!(neg.cells()[i], want, "value {v}, negate {flag}");
        }
        assert_eq!(neg.get(Cell::new(0, 2)), CellState::Free); // black is free
        assert_eq!(plain.get(Cell::new(0, 2)), CellState::Occupied);
        assert_eq!(neg.get(Cell::new(1, 2)), CellState::Occupied); // 254 is occupied
    }
    let bad = write_yaml(dir.path(), "bad.yaml", "m.pgm", "negate: 2\n");
    let e = load_map(&bad).unwrap_err().to_string();
    assert!(e.contains("negate") && e.contains("bad.yaml"), "{e}");
}

#[test]
fn raw_mode_reads_percentages() {
    let dir = tempfile::tempdir().unwrap();
    write_p5(&dir.path().join("m.pgm"));
    let yaml = write_yaml(dir.path(), "raw.yaml", "m.pgm", "mode: raw\nnegate: 0\n");
    assert_eq!(MapMetadata::read(&yaml).unwrap().mode, MapMode::Raw);
    let grid = load_map(&yaml).unwrap();
    for (i, v) in PIXELS.iter().rev().flatten().enumerate() {
        let want = match v {
            0 => CellState::Free,
            100 => CellState::Occupied,
            _ => CellState::Unknown,
        };
        assert_eq!(grid.cells()[i], want, "value {v}");
    }
}

#[test]
fn png_colour_types_average_rgb_and_ignore_alpha() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (4u32, 3u32);
    let gray: Vec<u8> = PIXELS.iter().flatten().copied().collect();
    let expected = {
        let p = dir.path().join("ref.pgm");
        write_p5(&p);
        load_image_map(&p, 0.05).unwrap()
    };
    let la: Vec<u8> = gray.iter().flat_map(|&v| [v, 0]).collect();
    // RGB channels differ but average to the gray value where possible.
    let rgb: Vec<u8> = gray
        .iter()
        .flat_map(|&v| {
            let d = v.min(255 - v).min(30);
            [v - d, v, v + d]
        })
        .collect();
    let rgba: Vec<u8> = rgb.chunks(3).flat_map(|p| [p[0], p[1], p[2], 7]).collect();
    let cases = [
        ("gray.png", image::ColorType::L8, gray.clone()),
        ("la.png", image::ColorType::La8, la),
        ("rgb.png", image::ColorType::Rgb8, rgb),
        ("rgba.png", image::ColorType::Rgba8, rgba),
    ];
    for (name, color, data) in cases {
        let path = dir.path().join(name);
        image::save_buffer(&path, &data, w, h, color).unwrap();
        let grid = load_image_map(&path, 0.05).unwrap();
        assert_eq!(grid, expected, "{name}");
        assert_eq!(
            load_any(&path, 0.05).unwrap(),
            expected,
            "{name} via load_any"
        );
    }
    let g = expected.geometry();
    assert_eq!(
        (g.origin, g.yaw, g.resolution),
        (Point::new(0.0, 0.0), 0.0, 0.05)
    );
}

#[test]
fn image_path_may_be_absolute_and_load_any_reads_yaml() {
    let dir = tempfile::tempdir().unwrap();
    let img = dir.path().join("sub").join("m.pgm");
    fs::create_dir(img.parent().unwrap()).unwrap();
    write_p5(&img);
    let abs = write_yaml(dir.path(), "abs.yml", &img.display().to_string(), "");
    let rel = write_yaml(dir.path(), "rel.yaml", "sub/m.pgm", "unknown_key: [1, 2]\n");
    let a = load_any(&abs, 99.0).unwrap();
    assert_eq!(a, load_any(&rel, 99.0).unwrap());
    assert_eq!(a.resolution(), 0.5);
}

#[test]
fn save_writes_trinary_pgm_and_yaml_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let mut geometry = GridGeometry::new(3, 2, 0.05, Point::new(-10.0, 2.5));
    geometry.yaw = 3.25;
    let grid = OccupancyGrid::from_cells(
        geometry,
        vec![
            CellState::Free,
            CellState::Occupied,
            CellState::Unknown,
            CellState::Occupied,
            CellState::Free,
            CellState::Free,
        ],
    )
    .unwrap();
    let yaml = dir.path().join("out.yaml");
    save_map(&grid, &yaml).unwrap();
    let mut names: Vec<String> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["out.pgm", "out.yaml"]);
    let pgm = fs::read(dir.path().join("out.pgm")).unwrap();
    assert_eq!(pgm, b"P5\n3 2\n255\n\x00\xfe\xfe\xfe\x00\xcd");
    let text = fs::read_to_string(&yaml).unwrap();
    assert!(
        text.starts_with("image: out.pgm\nresolution: 0.05\n"),
        "{text}"
    );
    assert!(text.contains("origin: [-10.0, 2.5, 3.25]\n"), "{text}");
    assert!(
        text.contains("negate: 0\n") && text.contains("mode: trinary\n"),
        "{text}"
    );
    assert_eq!(load_map(&yaml).unwrap(), grid);

    // Overwriting works; an unwritable target fails and leaves nothing behind.
    save_map(&grid, &yaml).unwrap();
    let missing_dir = dir.path().join("no_such_dir").join("x.yaml");
    let e = save_map(&grid, &missing_dir).unwrap_err().to_string();
    assert!(e.contains("no_such_dir"), "{e}");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 2);
    let e = save_map(&grid, &dir.path().join("x.pgm"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("x.pgm"), "{e}");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 2);
}

#[test]
fn awkward_names_and_numbers_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let origins = [
        (0.1 + 0.2, -1e-7, -0.0),
        (1e21, -3.5999999999999943, std::f64::consts::PI),
        (123456.789, 5e-324, -2.0),
    ];
    for (k, (x, y, yaw)) in origins.into_iter().enumerate() {
        let mut g = GridGeometry::new(2, 3, [0.0504, 0.1 + 0.2, 1e-3][k], Point::new(x, y));
        g.yaw = yaw;
        let grid = OccupancyGrid::filled(g, CellState::Unknown);
        let yaml = dir
            .path()
            .join(["a map #1.yaml", "b: x.yaml", "-c.yaml"][k]);
        save_map(&grid, &yaml).unwrap();
        let back = load_map(&yaml).unwrap();
        assert_eq!(back, grid);
        assert_eq!(back.geometry().yaw.to_bits(), yaw.to_bits(), "sign of zero");
    }
}

fn arb_grid() -> impl Strategy<Value = OccupancyGrid> {
    (
        1usize..40,
        1usize..40,
        prop::sample::select(vec![0.01, 0.02, 0.025, 0.03, 0.05, 0.0504, 0.1, 0.25]),
        -500.0f64..500.0,
        -500.0f64..500.0,
        -std::f64::consts::PI..std::f64::consts::PI,
    )
        .prop_flat_map(|(w, h, res, x, y, yaw)| {
            let states = prop::collection::vec(
                prop::sample::select(vec![
                    CellState::Free,
                    CellState::Occupied,
                    CellState::Unknown,
                ]),
                w * h,
            );
            states.prop_map(move |cells| {
                let mut g = GridGeometry::new(w, h, res, Point::new(x, y));
                g.yaw = yaw;
                OccupancyGrid::from_cells(g, cells).unwrap()
            })
        })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 64,
        failure_persistence: Some(Box::new(FileFailurePersistence::WithSource("regressions"))),
        ..ProptestConfig::default()
    })]

    #[test]
    fn save_then_load_is_identity(grid in arb_grid()) {
        let dir = tempfile::tempdir().unwrap();
        let yaml = dir.path().join("map.yaml");
        save_map(&grid, &yaml).unwrap();
        let back = load_map(&yaml).unwrap();
        prop_assert_eq!(back, grid);
    }
}

fn assert_err_names(result: Result<OccupancyGrid, FormatError>, needles: &[&str]) {
    let e = result.expect_err("should fail").to_string();
    for n in needles {
        assert!(e.contains(n), "error {e:?} should mention {n:?}");
    }
}

#[test]
fn bad_inputs_give_errors_naming_the_file_or_key() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_p5(&d.join("m.pgm"));

    assert_err_names(load_map(&d.join("absent.yaml")), &["absent.yaml"]);
    assert_err_names(load_any(&d.join("absent.png"), 0.05), &["absent.png"]);

    let no_res = d.join("nores.yaml");
    fs::write(&no_res, "image: m.pgm\norigin: [0, 0, 0]\n").unwrap();
    assert_err_names(load_map(&no_res), &["nores.yaml", "resolution"]);

    let no_image = d.join("noimage.yaml");
    fs::write(&no_image, "resolution: 0.1\norigin: [0, 0, 0]\n").unwrap();
    assert_err_names(load_map(&no_image), &["noimage.yaml", "image"]);

    let no_origin = d.join("noorigin.yaml");
    fs::write(&no_origin, "image: m.pgm\nresolution: 0.1\n").unwrap();
    assert_err_names(load_map(&no_origin), &["noorigin.yaml", "origin"]);

    for (name, res) in [
        ("neg.yaml", "-0.05"),
        ("zero.yaml", "0"),
        ("nan.yaml", ".nan"),
    ] {
        let p = d.join(name);
        fs::write(
            &p,
            format!("image: m.pgm\nresolution: {res}\norigin: [0, 0, 0]\n"),
        )
        .unwrap();
        assert_err_names(load_map(&p), &[name, "resolution"]);
    }

    let thresh = d.join("thresh.yaml");
    fs::write(
        &thresh,
        "image: m.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nfree_thresh: 0.7\noccupied_thresh: 0.65\n",
    )
    .unwrap();
    assert_err_names(load_map(&thresh), &["thresh.yaml", "free_thresh"]);
    fs::write(
        &thresh,
        "image: m.pgm\nresolution: 0.1\norigin: [0, 0, 0]\noccupied_thresh: 1.5\n",
    )
    .unwrap();
    assert_err_names(load_map(&thresh), &["thresh.yaml", "occupied_thresh"]);

    let mode = d.join("mode.yaml");
    fs::write(
        &mode,
        "image: m.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nmode: fancy\n",
    )
    .unwrap();
    assert_err_names(load_map(&mode), &["mode.yaml", "mode"]);

    let short_origin = d.join("short.yaml");
    fs::write(
        &short_origin,
        "image: m.pgm\nresolution: 0.1\norigin: [0]\n",
    )
    .unwrap();
    assert_err_names(load_map(&short_origin), &["short.yaml", "origin"]);

    let no_img = d.join("noimg.yaml");
    fs::write(
        &no_img,
        "image: nowhere.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n",
    )
    .unwrap();
    assert_err_names(load_map(&no_img), &["nowhere.pgm"]);

    let garbage = d.join("garbage.pgm");
    fs::write(&garbage, b"\x00\x01garbage\xff\xfe not an image").unwrap();
    let gy = d.join("garbage.yaml");
    fs::write(
        &gy,
        "image: garbage.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n",
    )
    .unwrap();
    assert_err_names(load_map(&gy), &["garbage.pgm"]);
    assert_err_names(load_image_map(&garbage, 0.1), &["garbage.pgm"]);

    // Right magic, broken body.
    let truncated = d.join("truncated.pgm");
    fs::write(&truncated, b"P5\n400 300\n255\n\x00\x01").unwrap();
    assert_err_names(load_image_map(&truncated, 0.1), &["truncated.pgm"]);
    let bad_png = d.join("bad.png");
    fs::write(&bad_png, b"\x89PNG\r\n\x1a\n\x00\x00\x00\x0dIHDR broken").unwrap();
    assert_err_names(load_image_map(&bad_png, 0.1), &["bad.png"]);
    let empty = d.join("empty.pgm");
    fs::write(&empty, b"").unwrap();
    assert_err_names(load_image_map(&empty, 0.1), &["empty.pgm"]);

    let not_yaml = d.join("notyaml.yaml");
    fs::write(&not_yaml, "image: [unclosed\n  resolution: : :\n").unwrap();
    assert_err_names(load_map(&not_yaml), &["notyaml.yaml"]);
    let wrong_type = d.join("wrongtype.yaml");
    fs::write(
        &wrong_type,
        "image: m.pgm\nresolution: fine\norigin: [0, 0, 0]\n",
    )
    .unwrap();
    assert_err_names(load_map(&wrong_type), &["wrongtype.yaml"]);
    let list = d.join("list.yaml");
    fs::write(&list, "- 1\n- 2\n").unwrap();
    assert_err_names(load_map(&list), &["list.yaml"]);
    let blank = d.join("blank.yaml");
    fs::write(&blank, "").unwrap();
    assert_err_names(load_map(&blank), &["blank.yaml"]);

    assert_err_names(
        load_image_map(&d.join("m.pgm"), -1.0),
        &["m.pgm", "resolution"],
    );
    assert_err_names(
        load_image_map(&d.join("m.pgm"), f64::INFINITY),
        &["resolution"],
    );
}
