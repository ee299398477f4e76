//! `cpsplan instruments`: the instrument presets with their figures.

use anyhow::Result;
use clap::Args;
use cpsplan::accuracy::{Instrument, ARCSEC};
use cpsplan::config::InstrumentModel;
use serde::Serialize;

/// Options of `cpsplan instruments`.
#[derive(Debug, Args)]
pub struct InstrumentsArgs {
    /// Print a JSON array (name, description, distance_sigma_mm, distance_ppm,
    /// angle_sigma_arcsec, min_range_m, max_range_m) instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// One preset as `--json` prints it.
#[derive(Debug, Serialize)]
struct PresetJson {
    name: &'static str,
    description: &'static str,
    distance_sigma_mm: f64,
    distance_ppm: f64,
    angle_sigma_arcsec: f64,
    min_range_m: f64,
    max_range_m: f64,
}

/// Prints one line (or one JSON object) per preset.
pub fn run(args: &InstrumentsArgs) -> Result<()> {
    let presets = InstrumentModel::ALL.map(Instrument::preset);
    if args.json {
        let all: Vec<PresetJson> = presets
            .iter()
            .map(|i| PresetJson {
                name: i.name,
                description: i.description,
                distance_sigma_mm: round(i.distance_sigma * 1e3),
                distance_ppm: round(i.distance_ppm * 1e6),
                angle_sigma_arcsec: round(i.angle_sigma / ARCSEC),
                min_range_m: i.min_range,
                max_range_m: i.max_range,
            })
            .collect();
        println!("{}", serde_json::to_string_pretty(&all)?);
        return Ok(());
    }
    println!(
        "{:<11} {:>9} {:>7} {:>8} {:>12}  source",
        "name", "distance", "ppm", "angle", "range m"
    );
    for i in &presets {
        println!(
            "{:<11} {:>7.1}mm {:>7.1} {:>7.1}\u{2033} {:>5.1}-{:<6.0}  {}",
            i.name,
            i.distance_sigma * 1e3,
            i.distance_ppm * 1e6,
            i.angle_sigma / ARCSEC,
            i.min_range,
            i.max_range,
            i.description
        );
    }
    Ok(())
}

/// `v` to a millionth (unit conversions leave 1.0000000000000002).
fn round(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}
