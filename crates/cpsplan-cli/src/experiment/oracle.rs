//! Every planner against the oracle (`--planner oracle`, the explorer-aware
//! yardstick): for each condition whose experiment also ran the oracle on the
//! same map, start, parameters, children and instrument, the scans to 99 % of
//! the reachable free space and the campaign hours to 99 %, seed by seed over
//! the oracle's of the same seed.

use cpsplan::config::Planner;

use super::record::{EpisodeRecord, Outcome};
use super::summary::Condition;

/// The scan and the campaign clock at which `r` first covered `share` of the
/// reachable free space.
fn reached(r: &EpisodeRecord, share: f64) -> Option<(f64, f64)> {
    let Outcome::Finished { scans, .. } = &r.outcome else {
        return None;
    };
    scans
        .iter()
        .find(|s| s.coverage >= share)
        .map(|s| (s.scan as f64, s.clock_h))
}

/// Whether `a` and `b` differ in their planner only (and the seed).
fn same_but_planner(a: &EpisodeRecord, b: &EpisodeRecord) -> bool {
    let (x, y) = (&a.episode, &b.episode);
    x.map == y.map
        && x.start == y.start
        && x.parameters == y.parameters
        && x.child_strategy == y.child_strategy
        && x.instrument == y.instrument
}

/// One condition against its oracle.
#[derive(Debug, Clone, PartialEq)]
pub struct AgainstOracle {
    /// The condition's label.
    pub condition: String,
    /// Seeds that both reached 99 %.
    pub paired: usize,
    /// Mean scans to 99 %, the condition's and the oracle's.
    pub scans: (f64, f64),
    /// Per seed, scans to 99 % over the oracle's: mean and largest.
    pub scan_ratio: (f64, f64),
    /// Mean campaign hours to 99 %, the condition's and the oracle's.
    pub hours: (f64, f64),
    /// Per seed, hours to 99 % over the oracle's: mean.
    pub hour_ratio: f64,
}

/// Every non-oracle condition of `conditions` against its oracle counterpart
/// (none when the experiment ran no oracle).
pub fn against_oracle(conditions: &[Condition<'_>]) -> Vec<AgainstOracle> {
    let oracles: Vec<&Condition<'_>> = conditions
        .iter()
        .filter(|c| {
            c.records
                .iter()
                .all(|r| r.episode.planner == Planner::Oracle)
        })
        .collect();
    let mut out = Vec::new();
    for c in conditions {
        let Some(first) = c.records.first() else {
            continue;
        };
        if first.episode.planner == Planner::Oracle {
            continue;
        }
        let Some(oracle) = oracles.iter().find(|o| {
            o.records
                .first()
                .is_some_and(|r| same_but_planner(r, first))
        }) else {
            continue;
        };
        let mut pairs = Vec::new();
        for r in &c.records {
            let Some(o) = oracle
                .records
                .iter()
                .find(|o| o.episode.seed == r.episode.seed)
            else {
                continue;
            };
            if let (Some(a), Some(b)) = (reached(r, 0.99), reached(o, 0.99)) {
                pairs.push((a, b));
            }
        }
        if pairs.is_empty() {
            continue;
        }
        let n = pairs.len() as f64;
        let mean = |v: &mut dyn Iterator<Item = f64>| v.sum::<f64>() / n;
        let ratios: Vec<f64> = pairs.iter().map(|(a, b)| a.0 / b.0.max(1.0)).collect();
        out.push(AgainstOracle {
            condition: c.label.clone(),
            paired: pairs.len(),
            scans: (
                mean(&mut pairs.iter().map(|p| p.0 .0)),
                mean(&mut pairs.iter().map(|p| p.1 .0)),
            ),
            scan_ratio: (
                mean(&mut ratios.iter().copied()),
                ratios.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            ),
            hours: (
                mean(&mut pairs.iter().map(|p| p.0 .1)),
                mean(&mut pairs.iter().map(|p| p.1 .1)),
            ),
            hour_ratio: mean(&mut pairs.iter().map(|p| p.0 .1 / p.1 .1.max(1e-9))),
        });
    }
    out
}

/// The table against the oracle as Markdown; `None` without an oracle.
pub fn oracle_markdown_table(conditions: &[Condition<'_>]) -> Option<String> {
    let rows = against_oracle(conditions);
    if rows.is_empty() {
        return None;
    }
    let mut out = String::from(
        "| condition | seeds | to 99 % | oracle's | ÷ oracle (mean, most) | hours to 99 % | oracle's | ÷ oracle |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {} | {:.1} | {:.1} | {:.2}, {:.2} | {:.2} | {:.2} | {:.2} |\n",
            r.condition,
            r.paired,
            r.scans.0,
            r.scans.1,
            r.scan_ratio.0,
            r.scan_ratio.1,
            r.hours.0,
            r.hours.1,
            r.hour_ratio
        ));
    }
    Some(out)
}
