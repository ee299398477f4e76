//! Every planner against the oracle (`--planner oracle`, the explorer-aware
//! yardstick): for each condition whose experiment also ran the oracle on the
//! same map, start, parameters, children and instrument, the scans to 99 % of
//! the reachable free space and the campaign hours to 99 %, seed by seed over
//! the oracle's of the same seed: medians over the seeds, and the largest
//! ratio.

use cpsplan::config::Planner;

use super::medians::Spread;
use super::record::{EpisodeRecord, Outcome};
use super::summary::Condition;
use super::text::md_text;

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

/// Whether `a` and `b` differ in their planner only (and the seed), whether
/// the experiment set the planner on its `planners` axis or in a parameter set.
fn same_but_planner(a: &EpisodeRecord, b: &EpisodeRecord) -> bool {
    let (x, y) = (&a.episode, &b.episode);
    let mut cx = x.config.clone();
    cx.parent.planner = y.config.parent.planner;
    cx.seed = y.config.seed;
    x.map == y.map && x.start == y.start && x.instrument == y.instrument && cx == y.config
}

/// The median of `v` (0 for none).
fn median(v: Vec<f64>) -> f64 {
    Spread::of(v).map_or(0.0, |s| s.median)
}

/// The scan and clock at 99 % of a condition's episode and of the oracle's.
type Pair = ((f64, f64), (f64, f64));

/// One condition against its oracle.
#[derive(Debug, Clone, PartialEq)]
pub struct AgainstOracle {
    /// The condition's label.
    pub condition: String,
    /// Seeds that both reached 99 %.
    pub paired: usize,
    /// Median scans to 99 % over the seeds, the condition's and the oracle's.
    pub scans: (f64, f64),
    /// Per seed, scans to 99 % over the oracle's: median and largest.
    pub scan_ratio: (f64, f64),
    /// Median campaign hours to 99 %, the condition's and the oracle's.
    pub hours: (f64, f64),
    /// Per seed, hours to 99 % over the oracle's: median.
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
        let ratios: Vec<f64> = pairs.iter().map(|(a, b)| a.0 / b.0.max(1.0)).collect();
        let of = |f: &dyn Fn(&Pair) -> f64| median(pairs.iter().map(f).collect());
        out.push(AgainstOracle {
            condition: c.label.clone(),
            paired: pairs.len(),
            scans: (of(&|p| p.0 .0), of(&|p| p.1 .0)),
            scan_ratio: (
                median(ratios.clone()),
                ratios.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            ),
            hours: (of(&|p| p.0 .1), of(&|p| p.1 .1)),
            hour_ratio: of(&|p| p.0 .1 / p.1 .1.max(1e-9)),
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
        "| condition | seeds | to 99 %, median | oracle's | ÷ oracle (median, most) | hours to 99 %, median | oracle's | ÷ oracle, median |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {} | {:.1} | {:.1} | {:.2}, {:.2} | {:.2} | {:.2} | {:.2} |\n",
            md_text(&r.condition),
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
