//! The Eq. (1) scores of a step's candidates as the figure shows them: a colour
//! ramp over the eligible candidates' range, and short printed values.

use super::super::canvas::Rgb;
use super::super::marks::ramp;
use super::super::palette;
use super::StepView;

/// The colour of a candidate of score `g` on a ramp from `lo` to `hi`.
pub(in crate::render) fn score_colour(g: f64, lo: f64, hi: f64) -> Rgb {
    let t = if hi - lo > 1e-12 {
        (g - lo) / (hi - lo)
    } else {
        1.0
    };
    ramp(&palette::SCORE_RAMP, t)
}

/// The range of the eligible candidates' scores, for the colour ramp.
pub(super) struct ScoreRange {
    /// The lowest eligible score.
    pub lo: f64,
    /// The highest eligible score.
    pub hi: f64,
}

impl ScoreRange {
    /// The range of `step`'s eligible scores (0 to 0 when there are none).
    pub fn of(step: &StepView<'_>) -> Self {
        let (lo, hi) = step
            .plan
            .candidates
            .iter()
            .filter(|c| c.eligible && c.g.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
                (lo.min(c.g), hi.max(c.g))
            });
        if lo > hi {
            Self { lo: 0.0, hi: 0.0 }
        } else {
            Self { lo, hi }
        }
    }

    /// The colour of score `g`.
    pub fn colour(&self, g: f64) -> Rgb {
        score_colour(g, self.lo, self.hi)
    }
}

/// A score as printed: three significant digits for ordinary magnitudes.
pub(super) fn format_score(g: f64) -> String {
    let a = g.abs();
    if a >= 100.0 {
        format!("{g:.0}")
    } else if a >= 10.0 {
        format!("{g:.1}")
    } else if a >= 1.0 {
        format!("{g:.2}")
    } else {
        format!("{g:.3}")
    }
}
