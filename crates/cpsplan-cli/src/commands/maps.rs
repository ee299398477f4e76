//! `cpsplan maps`: the built-in maps, listed or exported.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use cpsplan::world::builtin::BuiltinMap;

use crate::args::parse_seed;
use crate::formats::rosmap::encode_map;
use crate::render::render_map;
use crate::report::{write_temp, TempFile};

/// Options of `cpsplan maps`.
#[derive(Debug, Args)]
pub struct MapsArgs {
    /// Write every built-in map as ROS map_server PGM+YAML and a PNG preview here.
    #[arg(long, value_name = "DIR")]
    pub export: Option<PathBuf>,
    /// Print the list as a JSON array (name, description, default start x, y).
    #[arg(long, conflicts_with = "export")]
    pub json: bool,
    /// Seed of the maps' layouts.
    #[arg(long, value_name = "N", default_value_t = 0, allow_hyphen_values = true, value_parser = parse_seed)]
    pub seed: u64,
}

/// Lists the built-in maps, or exports them with `--export`.
pub fn run(args: &MapsArgs) -> Result<()> {
    match &args.export {
        None if args.json => {
            let all: Vec<serde_json::Value> = BuiltinMap::ALL
                .iter()
                .map(|map| {
                    let p = map.default_start();
                    serde_json::json!({
                        "name": map.name(),
                        "description": map.description(),
                        "start": { "x": p.x, "y": p.y },
                    })
                })
                .collect();
            println!("{}", serde_json::to_string_pretty(&all)?);
        }
        None => {
            for map in BuiltinMap::ALL {
                let p = map.default_start();
                println!(
                    "{:8} {} (start {:.1},{:.1})",
                    map.name(),
                    map.description(),
                    p.x,
                    p.y
                );
            }
        }
        Some(dir) => {
            let existed = dir.is_dir();
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create directory {}", dir.display()))?;
            let written = export_all(dir, args.seed);
            if written.is_err() && !existed {
                // Only if nothing is in it: a directory we made, left empty.
                let _ = std::fs::remove_dir(dir);
            }
            for path in written? {
                println!("wrote {}", path.display());
            }
        }
    }
    Ok(())
}

/// Writes every built-in map into `dir`, all or nothing: each file goes to a
/// temporary name first (a full disk removes them all), then every one is
/// renamed into place. Returns the YAML files.
fn export_all(dir: &Path, seed: u64) -> Result<Vec<PathBuf>> {
    let mut files: Vec<(PathBuf, TempFile)> = Vec::new();
    let mut yamls = Vec::new();
    for map in BuiltinMap::ALL {
        let name = map.name();
        let grid = map.generate(seed);
        let yaml_path = dir.join(format!("{name}.yaml"));
        let encoded = encode_map(&grid, &yaml_path, &[])?;
        let png = render_map(
            &grid,
            &format!("cpsplan built-in map `{name}` (seed {seed})"),
        )?;
        let png_path = dir.join(format!("{name}.png"));
        for (path, bytes) in [
            (encoded.image_path, encoded.pgm),
            (yaml_path.clone(), encoded.yaml.into_bytes()),
            (png_path, png),
        ] {
            let tmp = write_temp(&path, &bytes)?;
            files.push((path, tmp));
        }
        yamls.push(yaml_path);
    }
    for (path, tmp) in files {
        tmp.persist(&path)?;
    }
    Ok(yamls)
}
