//! The legend of a step figure: what each colour, line and mark means, only for
//! what the step shows.

use cpsplan::parent::CandidateOrigin;

use super::super::chrome::{LegendItem, Swatch};
use super::super::marks::ramp;
use super::super::palette;
use super::scores::{format_score, ScoreRange};
use super::tint::and_region_colour;
use super::StepView;

/// Legend labels that depend on the step.
pub(super) struct LegendTexts {
    ramp: String,
}

impl LegendTexts {
    /// The texts for `step`.
    pub fn new(step: &StepView<'_>, scores: &ScoreRange) -> Self {
        let any = step.plan.candidates.iter().any(|c| c.eligible);
        let ramp = if !any {
            "candidate score G".to_owned()
        } else if scores.hi - scores.lo > 1e-12 {
            format!(
                "candidate G {} to {}",
                format_score(scores.lo),
                format_score(scores.hi)
            )
        } else {
            format!("candidate G {}", format_score(scores.hi))
        };
        Self { ramp }
    }
}

/// The legend items of `step` with `cycles` cycles whose AND regions cover the
/// window cells with `levels`.
pub(super) fn legend<'a>(
    step: &StepView<'_>,
    cycles: usize,
    levels: &[u8],
    texts: &'a LegendTexts,
) -> Vec<LegendItem<'a>> {
    const CHILD_LABELS: [&str; 4] = ["child 1", "child 2", "child 3", "child 4"];
    let item = |swatch, label| LegendItem { swatch, label };
    let mut legend = vec![
        item(Swatch::Cell(palette::FREE), "free"),
        item(Swatch::Cell(palette::OCCUPIED), "occupied"),
        item(Swatch::Cell(palette::UNKNOWN), "unknown"),
    ];
    if levels.contains(&1) {
        let label = if cycles > 1 {
            "AND region, cycle 1"
        } else {
            "AND region"
        };
        legend.push(item(Swatch::Cell(and_region_colour(1)), label));
    }
    if levels.iter().any(|&l| l > 1) {
        legend.push(item(Swatch::Cell(and_region_colour(2)), "later cycles"));
    }
    if step.parent_path().len() >= 2 {
        legend.push(item(Swatch::Line(palette::TRAJECTORY), "parent path"));
    }
    if step.movement.subgoal_retrieval {
        legend.push(item(
            Swatch::Dashed(palette::SUBGOAL),
            "Visibility Graph path",
        ));
        legend.push(item(Swatch::Subgoal, "subgoal"));
    }
    let children = step
        .children
        .len()
        .max(step.movement.cycles.first().map_or(0, |c| c.children.len()));
    for (i, label) in CHILD_LABELS.iter().enumerate().take(children) {
        legend.push(item(Swatch::Line(palette::CHILDREN[i]), label));
    }
    if cycles > 0 {
        legend.push(item(Swatch::Dashed(palette::MUTED_TEXT), "line of sight"));
    }
    legend.push(item(Swatch::Dot(palette::TRAJECTORY), "parent"));
    if !step.plan.candidates.is_empty() {
        legend.push(item(Swatch::Ramp(&palette::SCORE_RAMP), &texts.ramp));
    }
    if step
        .plan
        .candidates
        .iter()
        .any(|c| c.eligible && c.origin == CandidateOrigin::Viewpoint)
    {
        legend.push(item(
            Swatch::Square(ramp(&palette::SCORE_RAMP, 0.5)),
            "viewpoint (square)",
        ));
    }
    if step.plan.candidates.iter().any(|c| !c.eligible) {
        legend.push(item(Swatch::SmallDot(palette::INELIGIBLE), "not eligible"));
    }
    if step.target().is_some() {
        legend.push(item(
            Swatch::Ring(ramp(&palette::SCORE_RAMP, 1.0)),
            "target",
        ));
    }
    if !step.movement.rejected.is_empty() {
        legend.push(item(
            Swatch::Cross(ramp(&palette::SCORE_RAMP, 1.0)),
            "rejected",
        ));
    }
    legend
}
