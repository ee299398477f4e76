//! What an experiment's records add up to: its conditions (every axis but the
//! seed), each condition's per-scan curves over its seeds (median and range),
//! and its headline figures.

use serde::Serialize;

use super::record::{BoundRecord, EpisodeRecord, Outcome, ScanRecord};
use super::text::{csv_safe, md_cells, md_text};
use crate::html::escape;

/// The episodes of one condition: the same map, start, parameter set, planner,
/// child strategy and instrument, over seeds.
#[derive(Debug, Clone)]
pub struct Condition<'a> {
    /// The episodes' label without the seed (`office/alpha0`).
    pub label: String,
    /// The map's short name (the label's first part).
    pub map: String,
    /// The rest of the label (`alpha0`), or `all` when only the map and the seed vary.
    pub within_map: String,
    /// Its records, in episode order.
    pub records: Vec<&'a EpisodeRecord>,
}

/// `records` grouped by condition, in the order of their first episodes.
pub fn conditions(records: &[EpisodeRecord]) -> Vec<Condition<'_>> {
    let mut out: Vec<Condition<'_>> = Vec::new();
    for r in records {
        let label = match r.episode.label.rsplit_once('/') {
            Some((rest, seed)) if seed.starts_with("seed") => rest.to_string(),
            _ => r.episode.label.clone(),
        };
        match out.iter_mut().find(|c| c.label == label) {
            Some(c) => c.records.push(r),
            None => {
                let (map, within) = match label.split_once('/') {
                    Some((m, w)) => (m.to_string(), w.to_string()),
                    None => (label.clone(), "all".to_string()),
                };
                out.push(Condition {
                    label,
                    map,
                    within_map: within,
                    records: vec![r],
                });
            }
        }
    }
    out
}

/// A per-scan figure of the records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    /// Coverage of the reachable free space, %.
    Coverage,
    /// Parent travel so far, m.
    Travel,
    /// Predicted radial 1σ of the scan position, mm.
    Error,
    /// The campaign clock, h.
    Clock,
}

impl Metric {
    fn of(self, s: &ScanRecord) -> Option<f64> {
        match self {
            Metric::Coverage => Some(100.0 * s.coverage),
            Metric::Travel => Some(s.parent_travel_m),
            Metric::Error => s.position_sigma_m.map(|v| 1e3 * v),
            Metric::Clock => Some(s.clock_h),
        }
    }

    /// The axis label.
    pub fn axis(self) -> &'static str {
        match self {
            Metric::Coverage => "coverage of the reachable free space, %",
            Metric::Travel => "parent travel, m",
            Metric::Error => "predicted position error (1\u{3c3}), mm",
            Metric::Clock => "campaign time, h",
        }
    }

    /// The short name used in file names.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Coverage => "coverage",
            Metric::Travel => "travel",
            Metric::Error => "error",
            Metric::Clock => "time",
        }
    }
}

/// Per scan number: the median of a metric over a condition's episodes and the
/// middle half of them (the quartiles). An episode that ended before a scan
/// keeps its last value there.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// `(scan, median)`.
    pub median: Vec<(f64, f64)>,
    /// `(scan, first quartile, third quartile)`.
    pub quartiles: Vec<(f64, f64, f64)>,
}

/// The values of `metric` for every scan of every finished episode, carried to
/// the longest episode's length; `None` if no episode has the metric.
fn columns(records: &[&EpisodeRecord], metric: Metric) -> Option<Vec<Vec<f64>>> {
    let series: Vec<Vec<f64>> = records
        .iter()
        .filter_map(|r| match &r.outcome {
            Outcome::Finished { scans, .. } => {
                let v: Vec<f64> = scans.iter().filter_map(|s| metric.of(s)).collect();
                (v.len() == scans.len() && !v.is_empty()).then_some(v)
            }
            Outcome::Failed { .. } => None,
        })
        .collect();
    let longest = series.iter().map(Vec::len).max()?;
    Some(
        (0..longest)
            .map(|k| {
                series
                    .iter()
                    .map(|v| v[k.min(v.len() - 1)])
                    .collect::<Vec<f64>>()
            })
            .collect(),
    )
}

/// The `q`-quantile of sorted `values`, linearly interpolated between ranks.
fn quantile(sorted: &[f64], q: f64) -> f64 {
    let at = q * (sorted.len() - 1) as f64;
    let (lo, hi) = (at.floor() as usize, at.ceil() as usize);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (at - lo as f64)
}

/// The median of `values` (sorted in place; not empty).
pub(super) fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    quantile(values, 0.5)
}

/// The curve of `metric` against the scan number over a condition's episodes.
pub fn curve(condition: &Condition<'_>, metric: Metric) -> Option<Curve> {
    let columns = columns(&condition.records, metric)?;
    let mut out = Curve {
        median: Vec::with_capacity(columns.len()),
        quartiles: Vec::with_capacity(columns.len()),
    };
    for (k, mut col) in columns.into_iter().enumerate() {
        let x = (k + 1) as f64;
        let m = median(&mut col);
        out.median.push((x, m));
        out.quartiles
            .push((x, quantile(&col, 0.25), quantile(&col, 0.75)));
    }
    Some(out)
}

/// The median of `y` against the median of `x`, scan by scan (coverage against
/// travel).
pub fn curve_against(condition: &Condition<'_>, x: Metric, y: Metric) -> Option<Vec<(f64, f64)>> {
    let xs = columns(&condition.records, x)?;
    let ys = columns(&condition.records, y)?;
    Some(
        xs.into_iter()
            .zip(ys)
            .map(|(mut a, mut b)| (median(&mut a), median(&mut b)))
            .collect(),
    )
}

/// The known-map greedy cover's coverage (%) against the number of stations,
/// the median over the distinct bounds of `records` (those of every seed of a
/// built-in map, for instance), a bound that ended carrying its last value;
/// `None` if no record has a bound.
pub fn greedy_bound_curve(records: &[&EpisodeRecord]) -> Option<Vec<(f64, f64)>> {
    let mut curves: Vec<Vec<f64>> = Vec::new();
    for r in records {
        let c = r.bound.as_ref().map(BoundRecord::greedy_curve);
        if let Some(c) = c.filter(|c| !c.is_empty()) {
            if !curves.contains(&c) {
                curves.push(c);
            }
        }
    }
    let longest = curves.iter().map(Vec::len).max()?;
    Some(
        (0..longest)
            .map(|k| {
                let mut col: Vec<f64> = curves
                    .iter()
                    .map(|c| 100.0 * c[k.min(c.len() - 1)])
                    .collect();
                ((k + 1) as f64, median(&mut col))
            })
            .collect(),
    )
}

/// Mean and sample standard deviation (0 for one value); `None` for none.
fn mean_sd(values: &[f64]) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let sd = if values.len() > 1 {
        (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    Some((mean, sd))
}

/// The headline figures of one condition (means over its finished episodes).
#[derive(Debug, Clone, Serialize)]
pub struct Headline {
    /// The condition's label.
    #[serde(serialize_with = "csv_safe")]
    pub condition: String,
    /// Episodes recorded.
    pub episodes: usize,
    /// Of those, episodes that could not run.
    pub failed: usize,
    /// Scans: mean, standard deviation, least, most.
    pub scans_mean: Option<f64>,
    /// Standard deviation of the scans.
    pub scans_sd: Option<f64>,
    /// Fewest scans.
    pub scans_min: Option<usize>,
    /// Most scans.
    pub scans_max: Option<usize>,
    /// Scans to reach 90 % coverage (episodes that reached it).
    pub scans_to_90_mean: Option<f64>,
    /// Scans to reach 99 % coverage (episodes that reached it).
    pub scans_to_99_mean: Option<f64>,
    /// Final coverage.
    pub coverage_mean: Option<f64>,
    /// Free space covered per scan, m² (coverage per scan, paper Fig. 9).
    pub area_per_scan_m2_mean: Option<f64>,
    /// Free space covered per metre of parent travel, m² (coverage per metre).
    pub area_per_travel_m2_per_m_mean: Option<f64>,
    /// Parent travel, m.
    pub parent_travel_m_mean: Option<f64>,
    /// Its standard deviation.
    pub parent_travel_m_sd: Option<f64>,
    /// The children's travel, summed, m.
    pub child_travel_m_mean: Option<f64>,
    /// CPS cycles.
    pub cps_cycles_mean: Option<f64>,
    /// Moves with subgoals.
    pub subgoal_retrievals_mean: Option<f64>,
    /// Predicted 1σ of the last scan position, mm.
    pub final_sigma_mm_mean: Option<f64>,
    /// Its standard deviation.
    pub final_sigma_mm_sd: Option<f64>,
    /// Mean of each episode's worst filtering σ of any scan, mm.
    pub worst_sigma_mm_mean: Option<f64>,
    /// Mean of each episode's worst smoothed σ of any scan, mm.
    pub worst_smoothed_sigma_mm_mean: Option<f64>,
    /// That σ as % of the parent's travel.
    pub error_percent_of_travel_mean: Option<f64>,
    /// Campaign time, h.
    pub campaign_time_h_mean: Option<f64>,
    /// Its standard deviation.
    pub campaign_time_h_sd: Option<f64>,
    /// The known-map greedy cover's stations for 90 % of the coverable cells
    /// (`bound = true`).
    pub bound_greedy_90_mean: Option<f64>,
    /// The LP lower bound's stations for 90 %.
    pub bound_lower_90_mean: Option<f64>,
    /// Scans to 90 % over the greedy stations for 90 %, per episode.
    pub scans_to_90_per_greedy_mean: Option<f64>,
    /// The greedy cover's stations for 99 %.
    pub bound_greedy_99_mean: Option<f64>,
    /// The LP lower bound's stations for 99 %.
    pub bound_lower_99_mean: Option<f64>,
    /// Scans to 99 % over the greedy stations for 99 %, per episode.
    pub scans_to_99_per_greedy_mean: Option<f64>,
}

impl Headline {
    /// Whether the condition's records carry a computed bound.
    pub fn has_bound(&self) -> bool {
        self.bound_greedy_90_mean.is_some()
    }
}

/// The headline figures of `condition`.
pub fn headline(condition: &Condition<'_>) -> Headline {
    // Each finished episode's summary, scans and free space covered, m².
    let finished: Vec<(&cpsplan::mission::Summary, &Vec<ScanRecord>, f64)> = condition
        .records
        .iter()
        .filter_map(|r| match &r.outcome {
            Outcome::Finished { summary, scans, .. } => {
                let cell = r.episode.config.resolution.powi(2);
                let covered = summary.coverage * summary.reachable_free_cells as f64 * cell;
                Some((summary.as_ref(), scans, covered))
            }
            Outcome::Failed { .. } => None,
        })
        .collect();
    let area_per = |per: &dyn Fn(&cpsplan::mission::Summary) -> f64| {
        let v: Vec<f64> = finished
            .iter()
            .filter(|(s, _, _)| per(s) > 0.0)
            .map(|(s, _, covered)| covered / per(s))
            .collect();
        mean_sd(&v).map(|m| m.0)
    };
    let of = |f: &dyn Fn(&cpsplan::mission::Summary) -> Option<f64>| {
        let v: Vec<f64> = finished.iter().filter_map(|(s, _, _)| f(s)).collect();
        mean_sd(&v)
    };
    let to = |share: f64| {
        let v: Vec<f64> = finished
            .iter()
            .filter_map(|(_, scans, _)| scans.iter().find(|s| s.coverage >= share))
            .map(|s| s.scan as f64)
            .collect();
        mean_sd(&v).map(|m| m.0)
    };
    // The bound's figures for `share`, and each episode's scans to `share`
    // over the greedy stations for it.
    let against = |share: f64| {
        let mut greedy = Vec::new();
        let mut lower = Vec::new();
        let mut ratio = Vec::new();
        for r in &condition.records {
            let Some(level) = r.bound.as_ref().and_then(|b| b.level(share)) else {
                continue;
            };
            greedy.push(level.greedy_stations as f64);
            lower.push(level.lower_bound_stations as f64);
            if let Outcome::Finished { scans, .. } = &r.outcome {
                if let Some(s) = scans.iter().find(|s| s.coverage >= share) {
                    if level.greedy_stations > 0 {
                        ratio.push(s.scan as f64 / level.greedy_stations as f64);
                    }
                }
            }
        }
        let m = |v: &[f64]| mean_sd(v).map(|m| m.0);
        (m(&greedy), m(&lower), m(&ratio))
    };
    let (greedy_90, lower_90, per_greedy_90) = against(0.9);
    let (greedy_99, lower_99, per_greedy_99) = against(0.99);
    let scans = of(&|s| Some(s.scans as f64));
    let travel = of(&|s| Some(s.parent_travel_m));
    let sigma = of(&|s| s.final_position_sigma_m.map(|v| 1e3 * v));
    let time = of(&|s| Some(s.campaign_time_h));
    Headline {
        condition: condition.label.clone(),
        episodes: condition.records.len(),
        failed: condition.records.len() - finished.len(),
        scans_mean: scans.map(|m| m.0),
        scans_sd: scans.map(|m| m.1),
        scans_min: finished.iter().map(|(s, _, _)| s.scans).min(),
        scans_max: finished.iter().map(|(s, _, _)| s.scans).max(),
        scans_to_90_mean: to(0.9),
        scans_to_99_mean: to(0.99),
        coverage_mean: of(&|s| Some(s.coverage)).map(|m| m.0),
        area_per_scan_m2_mean: area_per(&|s| s.scans as f64),
        area_per_travel_m2_per_m_mean: area_per(&|s| s.parent_travel_m),
        parent_travel_m_mean: travel.map(|m| m.0),
        parent_travel_m_sd: travel.map(|m| m.1),
        child_travel_m_mean: of(&|s| {
            (!s.child_travel_m.is_empty()).then(|| s.child_travel_m.iter().fold(0.0, |a, b| a + b))
        })
        .map(|m| m.0),
        cps_cycles_mean: of(&|s| Some(s.cps_cycles as f64)).map(|m| m.0),
        subgoal_retrievals_mean: of(&|s| Some(s.subgoal_retrievals as f64)).map(|m| m.0),
        final_sigma_mm_mean: sigma.map(|m| m.0),
        final_sigma_mm_sd: sigma.map(|m| m.1),
        worst_sigma_mm_mean: of(&|s| s.worst_position_sigma_m.map(|v| 1e3 * v)).map(|m| m.0),
        worst_smoothed_sigma_mm_mean: of(&|s| s.worst_smoothed_sigma_m.map(|v| 1e3 * v))
            .map(|m| m.0),
        error_percent_of_travel_mean: of(&|s| s.error_percent_of_travel).map(|m| m.0),
        campaign_time_h_mean: time.map(|m| m.0),
        campaign_time_h_sd: time.map(|m| m.1),
        bound_greedy_90_mean: greedy_90,
        bound_lower_90_mean: lower_90,
        scans_to_90_per_greedy_mean: per_greedy_90,
        bound_greedy_99_mean: greedy_99,
        bound_lower_99_mean: lower_99,
        scans_to_99_per_greedy_mean: per_greedy_99,
    }
}

fn cell(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |v| format!("{v:.digits$}"))
}

fn pm(mean: Option<f64>, sd: Option<f64>, digits: usize) -> String {
    match (mean, sd) {
        (Some(m), Some(s)) => format!("{m:.digits$} ± {s:.digits$}"),
        _ => "—".into(),
    }
}

/// The headline table as Markdown.
pub fn markdown_table(rows: &[Headline]) -> String {
    let mut out = String::from(
        "| condition | episodes | scans | to 90 % | to 99 % | coverage | m² per scan | \
         parent travel, m | m² per m | children's travel, m | CPS cycles | moves with subgoals | \
         final σ, mm | σ / travel | worst σ scanned / smoothed, mm | campaign, h |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let episodes = if r.failed > 0 {
            format!("{} ({} failed)", r.episodes, r.failed)
        } else {
            r.episodes.to_string()
        };
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            md_text(&r.condition),
            episodes,
            pm(r.scans_mean, r.scans_sd, 1),
            cell(r.scans_to_90_mean, 1),
            cell(r.scans_to_99_mean, 1),
            r.coverage_mean
                .map_or("—".into(), |c| format!("{:.2} %", 100.0 * c)),
            cell(r.area_per_scan_m2_mean, 1),
            pm(r.parent_travel_m_mean, r.parent_travel_m_sd, 0),
            cell(r.area_per_travel_m2_per_m_mean, 2),
            cell(r.child_travel_m_mean, 0),
            cell(r.cps_cycles_mean, 1),
            cell(r.subgoal_retrievals_mean, 1),
            pm(r.final_sigma_mm_mean, r.final_sigma_mm_sd, 1),
            r.error_percent_of_travel_mean
                .map_or("—".into(), |v| format!("{v:.4} %")),
            match (r.worst_sigma_mm_mean, r.worst_smoothed_sigma_mm_mean) {
                (Some(a), Some(b)) => format!("{a:.1} / {b:.1}"),
                _ => "—".into(),
            },
            pm(r.campaign_time_h_mean, r.campaign_time_h_sd, 1),
        ));
    }
    out
}

/// The table against the known-map bound as Markdown: the rows with a bound
/// only; `None` if none has one.
pub fn bound_markdown_table(rows: &[Headline]) -> Option<String> {
    let with: Vec<&Headline> = rows.iter().filter(|r| r.has_bound()).collect();
    if with.is_empty() {
        return None;
    }
    let mut out = String::from(
        "| condition | to 90 % | greedy 90 % | LP bound 90 % | to 90 % ÷ greedy | to 99 % | \
         greedy 99 % | LP bound 99 % | to 99 % ÷ greedy |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in with {
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            md_text(&r.condition),
            cell(r.scans_to_90_mean, 1),
            cell(r.bound_greedy_90_mean, 1),
            cell(r.bound_lower_90_mean, 1),
            cell(r.scans_to_90_per_greedy_mean, 2),
            cell(r.scans_to_99_mean, 1),
            cell(r.bound_greedy_99_mean, 1),
            cell(r.bound_lower_99_mean, 1),
            cell(r.scans_to_99_per_greedy_mean, 2),
        ));
    }
    Some(out)
}

/// The headline table as an HTML table (the cells of [`markdown_table`]).
pub fn html_table(rows: &[Headline]) -> String {
    html_of_markdown(&markdown_table(rows))
}

/// A Markdown table of this module as an HTML table.
pub fn html_of_markdown(md: &str) -> String {
    let mut out = String::from("<table>\n");
    for (k, line) in md.lines().enumerate() {
        if k == 1 {
            continue; // the Markdown alignment row
        }
        let tag = if k == 0 { "th" } else { "td" };
        out.push_str("<tr>");
        for cell in md_cells(line) {
            out.push_str(&format!("<{tag}>{}</{tag}>", escape(&cell)));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</table>\n");
    out
}

/// The headline table as CSV.
pub fn csv_table(rows: &[Headline]) -> anyhow::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r)?;
    }
    w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::experiment::spec::parse_plan;
    use cpsplan::mission::{StopReason, Summary};
    use cpsplan::Point;

    /// A finished record of episode `index` of `plan` with the given coverages
    /// of 10 000 reachable free cells (100 m² at the default 0.1 m), 10 m of
    /// travel between scans.
    pub(crate) fn record(
        plan: &crate::experiment::Plan,
        index: usize,
        coverage: &[f64],
    ) -> EpisodeRecord {
        let scans: Vec<ScanRecord> = coverage
            .iter()
            .enumerate()
            .map(|(k, &c)| ScanRecord {
                scan: k + 1,
                position: Point::new(0.0, 0.0),
                coverage: c,
                wall_coverage: c,
                parent_travel_m: 10.0 * k as f64,
                clock_h: 0.1 * (k + 1) as f64,
                position_sigma_m: None,
                monte_carlo_error_m: None,
                cps_cycles: 0,
                subgoal_retrieval: false,
            })
            .collect();
        let summary = Summary {
            scans: scans.len(),
            coverage: *coverage.last().unwrap(),
            wall_coverage: 1.0,
            connected_coverage: 1.0,
            reachable_free_cells: 10_000,
            connected_free_cells: 1,
            map_free_cells: 1,
            parent_travel_m: scans.last().unwrap().parent_travel_m,
            stop_reason: StopReason::Complete,
            seed: plan.episodes[index].seed,
            cps_cycles: 0,
            subgoal_retrievals: 0,
            child_travel_m: Vec::new(),
            instrument: "gpt-9005a".into(),
            final_position_sigma_m: None,
            error_percent_of_travel: None,
            monte_carlo_runs: 0,
            monte_carlo_mean_error_m: None,
            campaign_time_h: scans.last().unwrap().clock_h,
            campaign_time: Default::default(),
            planner: plan.episodes[index].planner,
            worst_position_sigma_m: None,
            worst_smoothed_sigma_m: None,
            final_smoothed_sigma_m: None,
            monte_carlo_smoothed_mean_error_m: None,
            targets_placed: 0,
            closures: 0,
            closure_moves: 0,
            sigma_violations: Vec::new(),
        };
        let spec = &plan.episodes[index];
        let mut r = EpisodeRecord::failed("x", spec, String::new(), 0.0);
        r.outcome = Outcome::Finished {
            start: Point::new(0.0, 0.0),
            summary: Box::new(summary),
            scans,
        };
        r
    }

    #[test]
    fn conditions_gather_the_seeds_and_curves_carry_ended_episodes() {
        let plan = parse_plan(
            "name = \"x\"\nmaps = [\"builtin:site\", \"builtin:office\"]\nseeds = [0, 1, 2]\n",
            std::path::Path::new("x.toml"),
        )
        .unwrap();
        let records = vec![
            record(&plan, 0, &[0.5, 0.9, 1.0]),
            record(&plan, 1, &[0.3, 0.95]),
            record(&plan, 2, &[0.4, 0.6, 0.8, 0.99]),
            record(&plan, 3, &[1.0]),
        ];
        let c = conditions(&records);
        assert_eq!(c.len(), 2);
        assert_eq!((c[0].label.as_str(), c[0].map.as_str()), ("site", "site"));
        assert_eq!(c[0].within_map, "all");
        assert_eq!(c[0].records.len(), 3);
        let curve = curve(&c[0], Metric::Coverage).unwrap();
        // Scan 3: 100, 95 (carried), 80 → median 95; scan 4: 100, 95, 99.
        assert_eq!(curve.median.len(), 4);
        assert!(
            (curve.median[2].1 - 95.0).abs() < 1e-9,
            "{:?}",
            curve.median
        );
        assert!((curve.median[3].1 - 99.0).abs() < 1e-9);
        // Scan 1: 30, 40, 50.
        assert_eq!(curve.quartiles[0], (1.0, 35.0, 45.0));
        assert_eq!(quantile(&[1.0, 2.0, 3.0, 4.0], 0.5), 2.5);
        assert_eq!(quantile(&[7.0], 0.25), 7.0);
        assert!(curve_against(&c[0], Metric::Travel, Metric::Coverage).is_some());
        assert!(
            super::curve(&c[0], Metric::Error).is_none(),
            "no error without children"
        );
        let h = headline(&c[0]);
        assert_eq!(h.episodes, 3);
        assert_eq!((h.scans_min, h.scans_max), (Some(2), Some(4)));
        assert!((h.scans_mean.unwrap() - 3.0).abs() < 1e-12);
        // 90 %: scans 2, 2, 4 → 8/3; 99 %: scans 3 and 4 (the second never got there).
        assert!((h.scans_to_90_mean.unwrap() - 8.0 / 3.0).abs() < 1e-12);
        assert!((h.scans_to_99_mean.unwrap() - 3.5).abs() < 1e-12);
        // Covered 100, 95 and 99 m² in 3, 2 and 4 scans over 20, 10 and 30 m.
        let per_scan = (100.0 / 3.0 + 95.0 / 2.0 + 99.0 / 4.0) / 3.0;
        assert!((h.area_per_scan_m2_mean.unwrap() - per_scan).abs() < 1e-9);
        let per_m = (100.0 / 20.0 + 95.0 / 10.0 + 99.0 / 30.0) / 3.0;
        assert!((h.area_per_travel_m2_per_m_mean.unwrap() - per_m).abs() < 1e-9);
        let md = markdown_table(std::slice::from_ref(&h));
        assert!(
            md.lines().nth(2).unwrap().starts_with(
                "| site | 3 | 3.0 ± 1.0 | 2.7 | 3.5 | 98.00 % | 35.2 | 20 ± 10 | 5.93 |"
            ),
            "{md}"
        );
        let csv = String::from_utf8(csv_table(&[h]).unwrap()).unwrap();
        assert_eq!(csv.lines().count(), 2);
    }
}
