//! Runs one episode on a built-in map, prints one line per scan to stderr and the
//! summary with the wall time to stdout.
//!
//! `cargo run --release -p cpsplan --example episode -- office 0 [ALPHA BETA]`
//! (`CHILDREN=N` sets the number of children; default: the configuration's two).

use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode, Config};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let map: BuiltinMap = args.next().unwrap_or_else(|| "site".into()).parse()?;
    let seed: u64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(0);
    let mut config = Config {
        seed,
        ..Config::default()
    };
    if let Some(a) = args.next() {
        config.parent.alpha = a.parse()?;
    }
    if let Some(b) = args.next() {
        config.parent.beta = b.parse()?;
    }
    if let Some(n) = std::env::var_os("CHILDREN") {
        config.children.count = n.to_string_lossy().parse()?;
    }
    let truth = map.generate(seed);
    let t0 = std::time::Instant::now();
    let episode = run_episode(&truth, map.default_start(), &config, |s| {
        let target = s.plan.target();
        eprintln!(
            "scan {:3}  coverage {:.3}  walls {:.3}  new {:6}  candidates {:2}  target S {:?} L {:?}",
            s.scan,
            s.coverage,
            s.wall_coverage,
            s.outcome.new_free + s.outcome.new_occupied,
            s.plan.candidates.len(),
            target.map(|t| t.s_cells),
            target.and_then(|t| t.l_m.map(|l| (l * 10.0).round() / 10.0)),
        );
    })?;
    let elapsed = t0.elapsed();
    println!("{}", serde_json::to_string_pretty(&episode.summary)?);
    println!("wall time {:.0} ms", elapsed.as_secs_f64() * 1e3);
    Ok(())
}
