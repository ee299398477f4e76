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
    assert!(replay("cloud_grid", cloud_grid::run) >= 5);
}
