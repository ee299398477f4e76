//! Each subcommand, one module each: its arguments beside its work
//! ([`crate::cli`] gathers them into the command line).

pub mod bound;
pub mod campaign;
pub mod completions;
pub mod defaults;
pub mod experiment;
pub mod explore;
pub mod grid;
pub mod instruments;
pub mod maps;
pub mod plan;
pub mod report;

use std::path::Path;

use anyhow::{anyhow, bail, Result};
use cpsplan::config::number;
use cpsplan::mission::MemoryEstimate;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::world::{default_start, resample_for};
use cpsplan::{Config, OccupancyGrid, Point};

use crate::formats::config::{read_config_file, ConfigFile};
use crate::formats::rosmap::{is_yaml_path, load_any_with, yaml_beside, ReadLimits};
use crate::memory::memory_budget;
use crate::render::pictures_peak_bytes;
use crate::report::MapSource;

/// Reads a TOML configuration file, or the defaults.
pub(crate) fn read_config(path: Option<&Path>) -> Result<ConfigFile> {
    match path {
        Some(path) => {
            let limits = ReadLimits::default();
            Ok(read_config_file(path, limits.max_text_bytes)?)
        }
        None => Ok(ConfigFile {
            config: Config::default(),
            keys: Default::default(),
        }),
    }
}

/// Validates the configuration of a run; a problem with a value given by a
/// flag names the flag (`flags`: configuration key, flag, whether it was given).
pub(crate) fn validate(config: &Config, flags: &[(&str, &str, bool)]) -> Result<()> {
    config.validate().map_err(|e| {
        match flags
            .iter()
            .find(|(key, _, given)| *given && *key == e.key())
        {
            Some((_, flag, _)) => anyhow!("{flag}: {e}"),
            None => anyhow!(e),
        }
    })
}

/// Loads a map file (ROS YAML or plain image at `config.resolution`) within the
/// configuration's limits and resamples it to the planning resolution; a grid
/// beyond `limits.max_grid_cells` is refused before it is allocated.
pub(crate) fn load_planning_grid(path: &Path, config: &Config) -> Result<OccupancyGrid> {
    let grid = load_any_with(path, config.resolution, &ReadLimits::for_config(config))?;
    if let Some(w) = image_alone_warning(path, config.resolution) {
        eprintln!("warning: {w}");
    }
    resample_for(&grid, config).map_err(|e| anyhow!("{}: {e}", path.display()))
}

/// What is lost when `path`, an image with a map_server YAML beside it that
/// names it, is read alone at `resolution` m per pixel with origin 0: `None`
/// when it is a YAML, has none beside it, or the YAML says the same.
fn image_alone_warning(path: &Path, resolution: f64) -> Option<String> {
    if is_yaml_path(path) {
        return None;
    }
    let (yaml, meta) = yaml_beside(path)?;
    let [x, y, yaw] = meta.origin;
    if meta.resolution == resolution && x == 0.0 && y == 0.0 && yaw == 0.0 {
        return None;
    }
    Some(format!(
        "{} is read as a plain image at {} m per pixel with origin (0, 0); {} beside it gives \
         {} m per pixel and origin ({}, {}, yaw {}): give --map {} to use them",
        path.display(),
        number(resolution),
        yaml.display(),
        number(meta.resolution),
        number(x),
        number(y),
        number(yaw),
        yaml.display()
    ))
}

/// Refuses a run on `truth` under `config` whose estimated peak memory
/// ([`MemoryEstimate`], one scan, pictures at their largest) exceeds
/// `limits.max_memory_mb` or, without that limit, the machine's available memory.
pub(crate) fn check_memory(truth: &OccupancyGrid, config: &Config) -> Result<()> {
    let g = truth.geometry();
    let estimate = MemoryEstimate::for_grid(g.width, g.height, config)
        .with_pictures(pictures_peak_bytes(g, true));
    config
        .check_memory(estimate.mb(1), memory_budget().map(|b| (b.mb, b.source)))
        .map_err(|e| anyhow!(e))
}

/// Loads the ground truth at the planning resolution from `map`, or the built-in
/// map (the default one without either), with the start: `start`, the built-in
/// map's own, or the map's default start.
pub(crate) fn load_truth(
    map: Option<&Path>,
    builtin: Option<BuiltinMap>,
    start: Option<Point>,
    config: &Config,
) -> Result<(OccupancyGrid, MapSource, Point)> {
    let (truth, source, own_start) = match map {
        Some(path) => {
            let truth = load_planning_grid(path, config)?;
            (truth, MapSource::File(path.to_path_buf()), None)
        }
        None => {
            let map = builtin.unwrap_or(BuiltinMap::DEFAULT);
            let grid = map.generate(config.seed);
            let truth = resample_for(&grid, config)
                .map_err(|e| anyhow!("built-in map `{}`: {e}", map.name()))?;
            (truth, MapSource::Builtin(map), Some(map.default_start()))
        }
    };
    let start = match start.or(own_start) {
        Some(p) => p,
        None => match default_start(&truth) {
            Some(p) => p,
            None => bail!("map {} has no free cell to start from", source.label()),
        },
    };
    Ok((truth, source, start))
}
