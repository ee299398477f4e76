//! A fixed relative error on the travel term `L` (beyond the paper; sensitivity
//! studies, `parent.travel_jitter`).
//!
//! An approximate `L` (a coarse travel graph, say) is off by a different small
//! share at every candidate. [`TravelJitter`] makes such an error on purpose:
//! the travel from the parent to a cell is multiplied by a factor in
//! `[1, 1 + amount]` drawn once per cell and seed, a leg of the tour between two
//! cells by one drawn per pair. The factors are fixed for an episode, so a
//! candidate seen again in a later round keeps its error, as a real approximation
//! would; with `amount = 0` every factor is exactly 1 and the plans are the exact
//! `L`'s bit for bit.

use crate::config::Config;

/// Multiplies the travel term by a fixed pseudo-random factor in
/// `[1, 1 + amount]` per cell (per pair of cells) and seed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TravelJitter {
    amount: f64,
    seed: u64,
}

impl TravelJitter {
    /// No error: every factor is 1.
    pub const NONE: Self = Self {
        amount: 0.0,
        seed: 0,
    };

    /// Factors in `[1, 1 + amount]` drawn with `seed` (a negative or non-finite
    /// amount counts as 0).
    pub fn new(amount: f64, seed: u64) -> Self {
        let amount = if amount.is_finite() {
            amount.max(0.0)
        } else {
            0.0
        };
        Self { amount, seed }
    }

    /// The jitter of `parent.travel_jitter` under the episode's seed.
    pub fn from_config(config: &Config) -> Self {
        Self::new(config.parent.travel_jitter, config.seed)
    }

    /// Whether every factor is exactly 1.
    pub fn is_exact(&self) -> bool {
        self.amount == 0.0
    }

    /// The factor of the travel from the parent to the cell of index `cell`.
    pub fn to(&self, cell: usize) -> f64 {
        self.factor(cell as u64, u64::MAX)
    }

    /// The factor of the leg between the cells of indices `a` and `b` (the same
    /// both ways).
    pub fn between(&self, a: usize, b: usize) -> f64 {
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        self.factor(lo as u64, hi as u64)
    }

    fn factor(&self, a: u64, b: u64) -> f64 {
        if self.is_exact() {
            return 1.0;
        }
        let h = mix(mix(mix(self.seed) ^ a) ^ b);
        // The top 53 bits as a share in [0, 1).
        1.0 + self.amount * ((h >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// SplitMix64's finaliser: a well-spread 64-bit hash of `z`.
fn mix(z: u64) -> u64 {
    let mut z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_lie_in_the_bound_are_symmetric_and_spread() {
        let j = TravelJitter::new(0.05, 7);
        let mut sum = 0.0;
        let n = 10_000;
        for i in 0..n {
            let f = j.to(i);
            assert!((1.0..=1.05).contains(&f), "{f}");
            sum += f;
            let (a, b) = (i, (i * 7919 + 13) % 100_003);
            assert_eq!(j.between(a, b), j.between(b, a));
            assert!((1.0..=1.05).contains(&j.between(a, b)));
        }
        // Spread over the bound, not stuck at one end: the mean near 1.025.
        let mean = sum / n as f64;
        assert!((mean - 1.025).abs() < 0.001, "mean {mean}");
        // Another seed draws other factors; the leg and the travel to a cell differ.
        assert_ne!(j.to(5), TravelJitter::new(0.05, 8).to(5));
        assert_ne!(j.to(5), j.between(5, 5));
    }

    #[test]
    fn no_jitter_is_exactly_one() {
        for j in [
            TravelJitter::NONE,
            TravelJitter::new(0.0, 3),
            TravelJitter::new(-1.0, 3),
            TravelJitter::new(f64::NAN, 3),
        ] {
            for i in [0, 1, 99, usize::MAX] {
                assert_eq!(j.to(i), 1.0);
                assert_eq!(j.between(i, 4), 1.0);
            }
        }
        // The exact L stays exact, even unreachable.
        assert_eq!(f64::INFINITY * TravelJitter::NONE.to(3), f64::INFINITY);
    }
}
