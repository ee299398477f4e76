//! Draws coverage against scans for explored reports: the curve that the stop
//! rule's defaults are chosen on (docs/HISTORY.md "Gain and stop").
//!
//! `cargo run --release -p cpsplan-cli --example coverage_curves -- OUT.png
//! "TITLE" LABEL=REPORT_DIR...` (each report's `metrics.csv`).

use std::error::Error;

use cpsplan_cli::render::{Chart, Series, SERIES_COLOURS as COLOURS};

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let out = args.next().ok_or("usage: OUT.png TITLE LABEL=DIR...")?;
    let title = args.next().ok_or("usage: OUT.png TITLE LABEL=DIR...")?;
    let mut series = Vec::new();
    for (k, spec) in args.enumerate() {
        let (label, dir) = spec.split_once('=').ok_or("each series is LABEL=DIR")?;
        let mut reader = csv::Reader::from_path(format!("{dir}/metrics.csv"))?;
        let headers = reader.headers()?.clone();
        let col = headers
            .iter()
            .position(|h| h == "coverage")
            .ok_or("metrics.csv has no coverage column")?;
        let mut points = Vec::new();
        for (i, row) in reader.records().enumerate() {
            let c: f64 = row?.get(col).ok_or("short row")?.parse()?;
            points.push(((i + 1) as f64, 100.0 * c));
        }
        series.push(Series {
            label: format!("{label} ({} scans)", points.len()),
            points,
            colour: COLOURS[k % COLOURS.len()],
            dashed: k % 2 == 1,
            band: Vec::new(),
        });
    }
    let chart = Chart {
        title,
        subtitle: "coverage of the reachable free space after each scan".into(),
        x_label: "scan".into(),
        y_label: "coverage (%)".into(),
        series,
    };
    std::fs::write(&out, chart.png()?)?;
    Ok(())
}
