//! Medians over seeds: each condition's scans, scans to 99 %, parent travel,
//! campaign hours and final σ as the median over its finished episodes with
//! the least and the most beside it, the form in which docs/RESULTS.md
//! compares planners (a mean of a few seeds hides a campaign that went wrong).

use super::record::Outcome;
use super::summary::{median, Condition};
use super::text::md_text;

/// A median with its spread over the seeds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spread {
    /// The median.
    pub median: f64,
    /// The least value.
    pub min: f64,
    /// The largest value.
    pub max: f64,
}

impl Spread {
    /// The median and range of `values`; `None` for none.
    pub fn of(mut values: Vec<f64>) -> Option<Spread> {
        if values.is_empty() {
            return None;
        }
        // Sorted by the median.
        let median = median(&mut values);
        Some(Spread {
            median,
            min: values[0],
            max: values[values.len() - 1],
        })
    }

    fn cell(spread: Option<Spread>, digits: usize) -> String {
        spread.map_or("—".into(), |s| {
            format!(
                "{:.digits$} ({:.digits$}–{:.digits$})",
                s.median, s.min, s.max
            )
        })
    }
}

/// One condition's medians over its finished episodes.
#[derive(Debug, Clone, PartialEq)]
pub struct Medians {
    /// The condition's label.
    pub condition: String,
    /// Finished episodes (seeds).
    pub finished: usize,
    /// Scans.
    pub scans: Option<Spread>,
    /// Scans to 99 % of the reachable free space (episodes that reached it).
    pub scans_to_99: Option<Spread>,
    /// Parent travel, m.
    pub parent_travel_m: Option<Spread>,
    /// Campaign time, h.
    pub campaign_time_h: Option<Spread>,
    /// Predicted 1σ of the last scan position, mm.
    pub final_sigma_mm: Option<Spread>,
}

/// The medians of `condition`.
pub fn medians(condition: &Condition<'_>) -> Medians {
    let finished: Vec<_> = condition
        .records
        .iter()
        .filter_map(|r| match &r.outcome {
            Outcome::Finished { summary, scans, .. } => Some((summary, scans)),
            Outcome::Failed { .. } => None,
        })
        .collect();
    let of = |f: &dyn Fn(&cpsplan::mission::Summary) -> Option<f64>| {
        Spread::of(finished.iter().filter_map(|(s, _)| f(s)).collect())
    };
    Medians {
        condition: condition.label.clone(),
        finished: finished.len(),
        scans: of(&|s| Some(s.scans as f64)),
        scans_to_99: Spread::of(
            finished
                .iter()
                .filter_map(|(_, scans)| scans.iter().find(|s| s.coverage >= 0.99))
                .map(|s| s.scan as f64)
                .collect(),
        ),
        parent_travel_m: of(&|s| Some(s.parent_travel_m)),
        campaign_time_h: of(&|s| Some(s.campaign_time_h)),
        final_sigma_mm: of(&|s| s.final_position_sigma_m.map(|v| 1e3 * v)),
    }
}

/// Every condition's medians as a Markdown table.
pub fn medians_markdown_table(conditions: &[Condition<'_>]) -> String {
    let mut out = String::from(
        "| condition | seeds | scans | to 99 % | parent travel m | campaign h | final σ mm |\n\
         |---|---:|---:|---:|---:|---:|---:|\n",
    );
    for m in conditions.iter().map(medians) {
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} |\n",
            md_text(&m.condition),
            m.finished,
            Spread::cell(m.scans, 0),
            Spread::cell(m.scans_to_99, 0),
            Spread::cell(m.parent_travel_m, 0),
            Spread::cell(m.campaign_time_h, 2),
            Spread::cell(m.final_sigma_mm, 1),
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_median_is_the_middle_value_and_the_spread_its_ends() {
        let s = Spread::of(vec![5.0, 1.0, 9.0, 2.0, 100.0]).unwrap();
        assert_eq!((s.median, s.min, s.max), (5.0, 1.0, 100.0));
        let even = Spread::of(vec![4.0, 1.0, 3.0, 2.0]).unwrap();
        assert_eq!(even.median, 2.5);
        assert_eq!(Spread::of(Vec::new()), None);
        assert_eq!(Spread::cell(Some(s), 1), "5.0 (1.0–100.0)");
    }
}
