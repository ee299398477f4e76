//! `cpsplan maps`: the built-in maps, listed or exported.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::OccupancyGrid;

use crate::args::parse_seed;
use crate::formats::rosmap::save_map;
use crate::render::render_map;
use crate::report::write_atomic;

/// Options of `cpsplan maps`.
#[derive(Debug, Args)]
pub struct MapsArgs {
    /// Write every built-in map as ROS map_server PGM+YAML and a PNG preview here.
    #[arg(long, value_name = "DIR")]
    pub export: Option<PathBuf>,
    /// Seed of the maps' layouts.
    #[arg(long, value_name = "N", default_value_t = 0, allow_hyphen_values = true, value_parser = parse_seed)]
    pub seed: u64,
}

/// Lists the built-in maps, or exports them with `--export`.
pub fn run(args: &MapsArgs) -> Result<()> {
    match &args.export {
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
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create directory {}", dir.display()))?;
            for map in BuiltinMap::ALL {
                let grid = map.generate(args.seed);
                export_map(&grid, dir, map.name(), args.seed)?;
                println!(
                    "wrote {}",
                    dir.join(format!("{}.yaml", map.name())).display()
                );
            }
        }
    }
    Ok(())
}

fn export_map(grid: &OccupancyGrid, dir: &Path, name: &str, seed: u64) -> Result<()> {
    save_map(grid, &dir.join(format!("{name}.yaml")))?;
    let png = render_map(
        grid,
        &format!("cpsplan built-in map `{name}` (seed {seed})"),
    )?;
    write_atomic(&dir.join(format!("{name}.png")), &png)?;
    Ok(())
}
