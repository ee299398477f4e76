//! `cpsplan instruments`: the instrument presets with their figures.

use anyhow::Result;
use cpsplan::accuracy::{Instrument, ARCSEC};
use cpsplan::config::InstrumentModel;

/// Prints one line per preset.
pub fn run() -> Result<()> {
    println!(
        "{:<11} {:>9} {:>7} {:>8} {:>12}  source",
        "name", "distance", "ppm", "angle", "range m"
    );
    for m in InstrumentModel::ALL {
        let i = Instrument::preset(m);
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
