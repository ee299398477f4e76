//! The evaluation value of Eq. (1), `G = R·(1/P + α/L + β·S)`, in the paper's
//! literal form and in the normalized form that is the default (see
//! docs/DESIGN-CHOICES.md for why and for measured comparisons).

use crate::config::{Scoring, ALPHA_UNIT, BETA_UNIT};

/// The raw terms of Eq. (1) for one candidate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Terms {
    /// `R`: the candidate is known Free, reachable and has the robot's clearance.
    pub reachable: bool,
    /// `1/P`: metres from the candidate to the nearest known obstacle.
    pub clearance: f64,
    /// `L`: travel distance from the parent in metres.
    pub travel: f64,
    /// `S`: Unknown cells visible within range when Unknown is treated as empty.
    pub gain: usize,
}

/// `G` for every candidate, in order. Guards: `L` is floored at `min_travel` (one
/// cell) so that `1/L` stays finite; in normalized scoring a term whose maximum over
/// the reachable candidates is zero contributes zero. Candidates with `R = 0` score 0.
pub fn evaluate(
    terms: &[Terms],
    alpha: f64,
    beta: f64,
    scoring: Scoring,
    min_travel: f64,
) -> Vec<f64> {
    let travel = |t: &Terms| t.travel.max(min_travel);
    match scoring {
        Scoring::Literal => terms
            .iter()
            .map(|t| {
                if t.reachable {
                    t.clearance + alpha / travel(t) + beta * t.gain as f64
                } else {
                    0.0
                }
            })
            .collect(),
        Scoring::Normalized => {
            let live = terms.iter().filter(|t| t.reachable);
            let c_max = live.clone().map(|t| t.clearance).fold(0.0, f64::max);
            let l_min = live.clone().map(travel).fold(f64::INFINITY, f64::min);
            let s_max = live.map(|t| t.gain).max().unwrap_or(0) as f64;
            let (wa, wb) = (alpha / ALPHA_UNIT, beta / BETA_UNIT);
            terms
                .iter()
                .map(|t| {
                    if !t.reachable {
                        return 0.0;
                    }
                    let c = if c_max > 0.0 {
                        t.clearance / c_max
                    } else {
                        0.0
                    };
                    let l = l_min / travel(t);
                    let s = if s_max > 0.0 {
                        t.gain as f64 / s_max
                    } else {
                        0.0
                    };
                    c + wa * l + wb * s
                })
                .collect()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(clearance: f64, travel: f64, gain: usize) -> Terms {
        Terms {
            reachable: true,
            clearance,
            travel,
            gain,
        }
    }

    /// Near: short travel, small gain, wide clearance. Far: twice the travel, three
    /// times the gain.
    fn pair() -> [Terms; 2] {
        [t(2.0, 10.0, 3000), t(0.5, 20.0, 9000)]
    }

    fn best(g: &[f64]) -> usize {
        if g[0] >= g[1] {
            0
        } else {
            1
        }
    }

    #[test]
    fn normalized_regimes_follow_the_paper() {
        let p = pair();
        // α = 0: the largest new area wins.
        assert_eq!(best(&evaluate(&p, 0.0, 0.001, Scoring::Normalized, 0.1)), 1);
        // β = 0: the shortest travel wins.
        assert_eq!(best(&evaluate(&p, 0.01, 0.0, Scoring::Normalized, 0.1)), 0);
        // Defaults weigh area against travel: three times the area is worth twice
        // the way, ...
        assert_eq!(
            best(&evaluate(&p, 0.01, 0.001, Scoring::Normalized, 0.1)),
            1
        );
        // ... ten times the way is not.
        let far = [t(2.0, 3.0, 3000), t(0.5, 30.0, 9000)];
        assert_eq!(
            best(&evaluate(&far, 0.01, 0.001, Scoring::Normalized, 0.1)),
            0
        );
    }

    #[test]
    fn literal_beta_zero_maximises_clearance_not_travel() {
        // The pitfall the normalized form fixes: with β = 0 the literal form picks
        // the candidate with more clearance even when it is ten times farther.
        let p = [t(0.5, 3.0, 800), t(2.0, 30.0, 9000)];
        assert_eq!(best(&evaluate(&p, 0.01, 0.0, Scoring::Literal, 0.1)), 1);
        assert_eq!(best(&evaluate(&p, 0.01, 0.0, Scoring::Normalized, 0.1)), 0);
    }

    #[test]
    fn unreachable_scores_zero_and_zero_travel_is_guarded() {
        let mut p = pair();
        p[1].reachable = false;
        p[0].travel = 0.0;
        for s in [Scoring::Literal, Scoring::Normalized] {
            let g = evaluate(&p, 0.01, 0.001, s, 0.1);
            assert!(g[0].is_finite() && g[0] > 0.0);
            assert_eq!(g[1], 0.0);
        }
    }
}
