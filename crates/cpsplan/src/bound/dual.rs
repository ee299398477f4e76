//! A lower bound on the fewest stations: the Lagrangian dual of the covering LP
//! relaxation, raised by subgradient ascent.
//!
//! The partial cover of a share `q` of the `N` targets, relaxed:
//! `min Σ_j x_j` over `x ∈ [0, 1]`, `z ∈ [0, 1]`, with `Σ_{j ∋ i} x_j ≥ z_i` for
//! every target and `Σ_i z_i ≥ m = ⌈qN⌉`. Moving the coverage rows into the
//! objective with multipliers `u ≥ 0` gives, for *every* `u`,
//!
//! `L(u) = Σ_j min(0, 1 − Σ_{i ∈ S_j} u_i) + (sum of the m smallest u_i)`,
//!
//! a lower bound on the LP's optimum and so on any cover's size (weak duality).
//! The ascent starts from a maximal dual packing (targets seen by the fewest
//! stations first) and takes Polyak steps toward the greedy cover's size; the best
//! value met is reported, or `m` over the largest view when that is more. Its
//! ceiling is a bound on whole stations.

use rayon::prelude::*;

/// Target → stations that see it (compressed rows).
struct Inverted {
    start: Vec<usize>,
    stations: Vec<u32>,
}

impl Inverted {
    fn new(sets: &[Vec<u32>], targets: usize) -> Self {
        let mut start = vec![0usize; targets + 1];
        for s in sets {
            for &t in s {
                start[t as usize + 1] += 1;
            }
        }
        for i in 0..targets {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut stations = vec![0u32; start[targets]];
        for (j, s) in sets.iter().enumerate() {
            for &t in s {
                stations[fill[t as usize]] = j as u32;
                fill[t as usize] += 1;
            }
        }
        Self { start, stations }
    }

    fn of(&self, t: usize) -> &[u32] {
        &self.stations[self.start[t]..self.start[t + 1]]
    }
}

/// A maximal dual packing: `y ≥ 0` with `Σ_{i ∈ S_j} y_i ≤ 1` for every station,
/// raised target by target, those seen by the fewest stations first.
fn packing(sets: &[Vec<u32>], inv: &Inverted, targets: &[u32]) -> Vec<f64> {
    let mut order: Vec<u32> = targets.to_vec();
    order.sort_by_key(|&t| (inv.of(t as usize).len(), t));
    let mut cap = vec![1.0f64; sets.len()];
    let mut y = vec![0.0f64; inv.start.len() - 1];
    for t in order {
        let js = inv.of(t as usize);
        let v = js
            .iter()
            .map(|&j| cap[j as usize])
            .fold(f64::INFINITY, f64::min);
        if v.is_finite() && v > 0.0 {
            y[t as usize] = v;
            for &j in js {
                cap[j as usize] -= v;
            }
        }
    }
    y
}

/// `L(u)` and the stations with negative reduced cost (`x_j = 1`), for the `m`
/// smallest multipliers among `targets`; also the targets with `z_i = 1`.
fn lagrangian(
    sets: &[Vec<u32>],
    u: &[f64],
    targets: &[u32],
    m: usize,
) -> (f64, Vec<usize>, Vec<u32>) {
    let loads: Vec<f64> = sets
        .par_iter()
        .map(|s| s.iter().map(|&t| u[t as usize]).sum::<f64>())
        .collect();
    let mut chosen = Vec::new();
    let mut value = 0.0;
    for (j, &l) in loads.iter().enumerate() {
        if l > 1.0 {
            value += 1.0 - l;
            chosen.push(j);
        }
    }
    let mut order: Vec<u32> = targets.to_vec();
    let m = m.min(order.len());
    if m < order.len() && m > 0 {
        order.select_nth_unstable_by(m - 1, |&a, &b| {
            u[a as usize].total_cmp(&u[b as usize]).then(a.cmp(&b))
        });
    }
    order.truncate(m);
    value += order.iter().map(|&t| u[t as usize]).sum::<f64>();
    (value, chosen, order)
}

/// The best Lagrangian bound found for covering at least `m` of `targets` (the
/// targets some station sees) with `sets`, after at most `iterations` steps;
/// `upper` is a known cover's size (the greedy one), the ascent's aim.
pub fn lower_bound(
    sets: &[Vec<u32>],
    n_targets: usize,
    targets: &[u32],
    m: usize,
    upper: usize,
    iterations: usize,
) -> f64 {
    if m == 0 || targets.is_empty() {
        return 0.0;
    }
    let inv = Inverted::new(sets, n_targets);
    let mut u = packing(sets, &inv, targets);
    let mut best = f64::NEG_INFINITY;
    let mut lambda = 2.0;
    let mut since = 0;
    let mut g = vec![0.0f64; n_targets];
    for _ in 0..iterations.max(1) {
        let (value, chosen, z) = lagrangian(sets, &u, targets, m);
        if value > best + 1e-9 {
            best = value;
            since = 0;
        } else {
            since += 1;
            if since >= 8 {
                lambda /= 2.0;
                since = 0;
            }
        }
        if upper as f64 - best < 1e-6 || lambda < 1e-4 {
            break;
        }
        // Subgradient: z_i − Σ_{j ∋ i} x_j.
        g.iter_mut().for_each(|v| *v = 0.0);
        for &t in &z {
            g[t as usize] += 1.0;
        }
        for &j in &chosen {
            for &t in &sets[j] {
                g[t as usize] -= 1.0;
            }
        }
        let norm: f64 = targets.iter().map(|&t| g[t as usize].powi(2)).sum();
        if norm == 0.0 {
            break;
        }
        let step = lambda * (upper as f64 - value).max(1e-3) / norm;
        for &t in targets {
            let t = t as usize;
            u[t] = (u[t] + step * g[t]).max(0.0);
        }
    }
    // Also: k stations see at most k times the largest view.
    let largest = sets.iter().map(Vec::len).max().unwrap_or(0).max(1);
    best.max(m as f64 / largest as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::cover::lazy_greedy;
    use proptest::prelude::*;

    /// The fewest sets covering at least `m` targets, by brute force.
    fn optimum(sets: &[Vec<u32>], n: usize, m: usize) -> usize {
        (0u32..1 << sets.len())
            .filter(|mask| {
                let mut c = vec![false; n];
                for (j, s) in sets.iter().enumerate() {
                    if mask & (1 << j) != 0 {
                        s.iter().for_each(|&t| c[t as usize] = true);
                    }
                }
                c.iter().filter(|&&v| v).count() >= m
            })
            .map(|mask| mask.count_ones() as usize)
            .min()
            .unwrap_or(usize::MAX)
    }

    #[test]
    fn disjoint_sets_need_every_one() {
        let sets = vec![vec![0, 1], vec![2, 3], vec![4, 5]];
        let lb = lower_bound(&sets, 6, &[0, 1, 2, 3, 4, 5], 6, 3, 200);
        assert!((lb - 3.0).abs() < 1e-6, "{lb}");
        // Four of six targets: two sets.
        let lb = lower_bound(&sets, 6, &[0, 1, 2, 3, 4, 5], 4, 2, 200);
        assert!(lb > 1.0 + 1e-6 && lb <= 2.0 + 1e-9, "{lb}");
    }

    proptest! {
        #[test]
        fn never_above_the_optimum_and_close_to_it(
            sets in prop::collection::vec(prop::collection::btree_set(0u32..16, 1..6), 1..10),
            share in 0.5f64..=1.0,
        ) {
            let sets: Vec<Vec<u32>> = sets.into_iter().map(|s| s.into_iter().collect()).collect();
            let mut seen: Vec<u32> = sets.iter().flatten().copied().collect();
            seen.sort_unstable();
            seen.dedup();
            let m = (share * seen.len() as f64).ceil() as usize;
            let best = optimum(&sets, 16, m);
            let greedy = lazy_greedy(&sets, 16).iter().position(|p| p.covered >= m).map_or(0, |k| k + 1);
            let lb = lower_bound(&sets, 16, &seen, m, greedy, 300);
            prop_assert!(lb <= best as f64 + 1e-9, "bound {} above optimum {}", lb, best);
            prop_assert!(lb > 0.0, "bound {} not positive", lb);
        }
    }
}
