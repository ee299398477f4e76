//! Times the network adjustment on a recorded episode (docs/PERFORMANCE.md
//! "Closed networks"): the chain and the incremental adjustment cycle by cycle,
//! the smoothing pass, the fit of every measurement, one Monte Carlo run and its
//! whole-network Gauss–Newton.
//!
//! ```sh
//! cargo run --release -- explore --map ../shared/maps/cit_tsudanuma_campus.yaml \
//!     --place-targets 30 --out /tmp/campus
//! cargo run --release -p cpsplan --example network_timing -- /tmp/campus/episode.json
//! ```

use std::time::Instant;

use cpsplan::accuracy::{
    realisation, Chain, CycleGeometry, Instrument, Model, Network, NetworkGeometry, Script,
    TargetPoint,
};
use cpsplan::mission::{Episode, TargetOrigin};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: network_timing EPISODE.json")?;
    let episode: Episode = serde_json::from_str(&std::fs::read_to_string(&path)?)?;
    let model = Model::new(Instrument::from_config(&episode.config.instrument));
    // The network as the episode measured it.
    let mut net = NetworkGeometry {
        start: episode.start,
        targets: episode
            .targets
            .iter()
            .map(|t| TargetPoint {
                position: t.position,
                z: None,
                control_sigma: match t.origin {
                    TargetOrigin::Control => t.sigma_mm.map(|s| s * 1e-3),
                    _ => None,
                },
            })
            .collect(),
        at_start: episode
            .steps
            .first()
            .map(|s| s.targets.clone())
            .unwrap_or_default(),
        cycles: Vec::new(),
    };
    for s in &episode.steps[..episode.steps.len().saturating_sub(1)] {
        for c in &s.movement.cycles {
            net.cycles.push(CycleGeometry {
                to: c.parent_to,
                children: c.children.iter().map(|k| k.to).collect(),
                moved: c.children.iter().map(|k| !k.stays).collect(),
                here: c.left_targets.iter().map(|l| l.target).collect(),
                sighted: c.targets.clone(),
            });
        }
    }
    let n = net.children();
    let cycles = net.cycles.len();
    let measurements = Script::of(model, &net)
        .events()
        .iter()
        .filter(|e| matches!(e, cpsplan::accuracy::Event::Observe { .. }))
        .count();
    println!(
        "{path}: {} scans, {cycles} cycles, {} targets, {measurements} measurements",
        episode.steps.len(),
        net.targets.len()
    );
    let t = Instant::now();
    let mut chain = Chain::new(model, net.start, n);
    for &p in &net.targets {
        chain.add_target(p);
    }
    chain.sight_here(&net.at_start)?;
    let mut filtering = Vec::with_capacity(cycles);
    for c in &net.cycles {
        chain.sight_here(&c.here)?;
        chain.cycle_sighting(c.to, &c.children, &c.moved, &c.sighted)?;
        filtering.push(chain.pose().position_sigma());
    }
    let chain_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let mut network = Network::new(Script::new(model, net.start, n, &net.targets));
    network.script_mut().sight_here(&net.at_start);
    network.extend_nominal()?;
    for c in &net.cycles {
        network.script_mut().cycle(c);
        network.extend_nominal()?;
    }
    let incremental_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let smoothed = network.smooth()?;
    let smooth_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let fits = network.station_fits()?;
    let fits_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let r = realisation(&model, &net, episode.config.seed, 0, true)?;
    let run_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let _ = realisation(&model, &net, episode.config.seed, 0, false)?;
    let filtering_ms = t.elapsed().as_secs_f64() * 1e3;
    println!(
        "chain (filtering), every cycle:            {chain_ms:8.1} ms ({:.1} µs per cycle)",
        1e3 * chain_ms / cycles as f64
    );
    println!(
        "network, incremental, every cycle:         {incremental_ms:8.1} ms ({:.1} µs per cycle)",
        1e3 * incremental_ms / cycles as f64
    );
    println!("smoothing pass (every unknown's σ):        {smooth_ms:8.1} ms");
    println!("fit of every measurement:                  {fits_ms:8.1} ms");
    println!("one Monte Carlo run, filtering only:       {filtering_ms:8.1} ms");
    println!("one Monte Carlo run, with the whole network adjusted: {run_ms:8.1} ms");
    let stations = network.script().stations();
    let sigma_of = |v: usize| smoothed[v].as_ref().map(|c| (c[(0, 0)] + c[(1, 1)]).sqrt());
    let excess = stations[1..]
        .iter()
        .zip(&filtering)
        .filter_map(|(&v, &f)| Some(sigma_of(v)? / f - 1.0))
        .fold(f64::NEG_INFINITY, f64::max);
    println!(
        "largest excess of a station's smoothed σ over the chain's filtering σ: {excess:.1e} (relative)"
    );
    let worst = stations[1..]
        .iter()
        .filter_map(|&v| smoothed[v].as_ref())
        .map(|c| (c[(0, 0)] + c[(1, 1)]).sqrt())
        .fold(0.0, f64::max);
    println!(
        "worst smoothed σ of any station {:.1} mm; {} stations fitted; last filtering σ {:.1} mm; run 1's last smoothed error {:.1} mm",
        worst * 1e3,
        fits.iter().flatten().count(),
        chain.pose().position_sigma() * 1e3,
        r.smoothed
            .as_ref()
            .and_then(|s| s.last())
            .map_or(f64::NAN, |e| e[0].hypot(e[1]) * 1e3)
    );
    Ok(())
}
