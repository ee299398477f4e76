//! What targets can do for an open route with the paper's Eq. (2) geometry
//! (docs/ACCURACY.md "What closures can do, and what they cannot"): 40 cycles
//! along a straight corridor, 15 m each, the children 3 m short of the next
//! station (Eq. 2's `Dt`) and 2.2 m to either side; a target left at a child's
//! spot every cycle, measured by the next `k` stations. Prints the last
//! station's σ and heading σ and the worst smoothed σ for each `k`.
//!
//! ```sh
//! cargo run --release -p cpsplan --example open_corridor
//! ```

use cpsplan::accuracy::{
    CycleGeometry, Instrument, Model, Network, NetworkGeometry, Script, TargetPoint, ARCSEC,
};
use cpsplan::config::InstrumentConfig;
use cpsplan::geom::Point;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = Model::new(Instrument::from_config(&InstrumentConfig::default()));
    let cycles = 40;
    println!("| later stations measuring each target | last σ (mm) | last heading σ (″) | worst smoothed σ (mm) | last σ / route |");
    println!("|---|---:|---:|---:|---:|");
    for lookback in [0usize, 1, 2, 3, 5, usize::MAX] {
        let mut net = NetworkGeometry {
            start: Point::new(0.0, 0.0),
            ..NetworkGeometry::default()
        };
        for c in 0..cycles {
            let x = 15.0 * c as f64;
            let kids = vec![Point::new(x + 13.0, 2.2), Point::new(x + 13.0, -2.2)];
            let mut cycle =
                CycleGeometry::plain(Point::new(x + 15.0, 0.0), kids.clone(), vec![true, true]);
            if lookback > 0 {
                net.targets.push(TargetPoint::free(kids[0]));
                let n = net.targets.len();
                cycle.here = vec![n - 1];
                cycle.sighted = (n.saturating_sub(lookback)..n).collect();
            }
            net.cycles.push(cycle);
        }
        let network = Network::nominal(Script::of(model, &net))?;
        let smoothed = network.smooth()?;
        let stations = network.script().stations();
        let last = network
            .current_covariance(*stations.last().ok_or("no station")?)?
            .ok_or("not current")?;
        let worst = stations[1..]
            .iter()
            .filter_map(|&v| smoothed[v].as_ref())
            .map(|c| (c[(0, 0)] + c[(1, 1)]).sqrt())
            .fold(0.0, f64::max);
        let sigma = (last[(0, 0)] + last[(1, 1)]).sqrt();
        let label = if lookback == usize::MAX {
            "every later one".to_string()
        } else {
            lookback.to_string()
        };
        println!(
            "| {label} | {:.0} | {:.0} | {:.0} | {:.3} % |",
            sigma * 1e3,
            last[(2, 2)].sqrt() / ARCSEC,
            worst * 1e3,
            100.0 * sigma / (15.0 * cycles as f64)
        );
    }
    Ok(())
}
