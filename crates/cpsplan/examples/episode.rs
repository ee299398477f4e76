//! Runs one episode on a built-in map and prints its summary.
//!
//! `cargo run --release -p cpsplan --example episode -- office 0`

use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode, Config};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let map: BuiltinMap = args.next().unwrap_or_else(|| "office".into()).parse()?;
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
    if let Ok(v) = std::env::var("MIN_FRONTIER") {
        config.parent.min_frontier_cells = v.parse()?;
    }
    if let Ok(v) = std::env::var("MIN_GAIN") {
        config.parent.min_gain_cells = v.parse()?;
    }
    let truth = map.generate(seed);
    let t0 = std::time::Instant::now();
    let episode = run_episode(&truth, map.default_start(), &config, |s| {
        eprintln!(
            "scan {:3}  coverage {:.3}  walls {:.3}  candidates {:2}  border {}  new {}  chosen S {:?} L {:?} origin {:?}",
            s.scan,
            s.coverage,
            s.wall_coverage,
            s.plan.candidates.len(),
            s.plan.border_cells,
            s.outcome.new_free + s.outcome.new_occupied,
            s.plan.target().map(|t| t.s_cells),
            s.plan.target().and_then(|t| t.l_m.map(|l| l.round())),
            s.plan.target().map(|t| t.origin),
        );
    })?;
    println!("{}", serde_json::to_string_pretty(&episode.summary)?);
    if let (Ok(path), Some(k)) = (std::env::var("DUMP"), episode.knowledge.as_ref()) {
        let (w, h) = (k.width(), k.height());
        let mut img = vec![0u8; w * h];
        for y in 0..h {
            for x in 0..w {
                img[(h - 1 - y) * w + x] = match k.get(cpsplan::Cell::new(x, y)) {
                    cpsplan::CellState::Free => 255,
                    cpsplan::CellState::Occupied => 0,
                    cpsplan::CellState::Unknown => 170,
                };
            }
        }
        for s in &episode.steps {
            for dy in 0..5 {
                for dx in 0..5 {
                    let (x, y) = (s.cell.x + dx - 2, s.cell.y + dy - 2);
                    img[(h - 1 - y) * w + x] = 90;
                }
            }
        }
        let mut out = format!("P5\n{w} {h}\n255\n").into_bytes();
        out.extend(img);
        std::fs::write(path, out)?;
    }
    println!("wall time {:.0} ms", t0.elapsed().as_secs_f64() * 1e3);
    Ok(())
}
