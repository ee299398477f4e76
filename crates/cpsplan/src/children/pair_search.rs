//! The search behind the `min-error` strategy: the spots of the moving children
//! that minimise `σ(J) + λ·travel` (see [`super::strategy`]).
//!
//! In: each mover's candidate [`Spot`]s (cell, information `J(c)` about the next
//! pose, travel), the cost of a summed information, and the children's spacing.
//! Out: the chosen spot of every mover and its value.
//!
//! - One mover: every spot evaluated ([`best_single`]).
//! - Two: an exact best-first branch and bound over pairs of k-d tree nodes of the
//!   two sets ([`best_pair`]); a node's bound is a matrix `U ⪰ J(c)` for every spot
//!   of the node (`U = λ_max(Q^{-1/2} J Q^{-1/2})·Q` over the spots, `Q` the node's
//!   mean `J`), so `σ(U_a + U_b) + λ(t_a + t_b)` bounds every pair below (the
//!   objective decreases in `J`); pairs closer than two child radii are skipped.
//! - More: coordinate descent from a greedy start ([`descend`]), near-optimal but
//!   not proven.

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::sync::OnceLock;

use nalgebra::Matrix3;
use rayon::prelude::*;

use super::spacing::Spacing;
use crate::geom::Cell;

/// The ridges tried along a node's weakest direction, as shares of its largest
/// eigenvalue: any ridge gives a valid bound. Members whose weak directions spread
/// by an angle δ are bounded with a ridge and an overall scale both of order δ
/// (the ellipse that holds a fan of directions), so the bound tightens as nodes
/// shrink; a fixed ridge would leave the scale near 3 however small the node.
const BOUND_RIDGES: [f64; 4] = [1e-6, 1e-4, 1e-2, 0.1];

/// The pair search stops within this share of the cycle's own contribution to the
/// predicted σ (what the best pair adds to the floor no placement can remove): a
/// proven gap, since every pair not examined is bounded below.
pub const SEARCH_GAP: f64 = 0.02;

/// Pops of the branch and bound after which it returns the best pair found, with
/// the gap still open (measured in docs/PERFORMANCE.md).
const MAX_POPS: usize = 5_000;

/// Sets of at least this many spots are scanned in parallel.
const PARALLEL_SPOTS: usize = 2048;

/// Node bounds over at least this many members are computed two at a time.
const PARALLEL_BOUND: usize = 256;

/// Spots per set of the lattice whose pairs give the search's first incumbent.
const LATTICE_SPOTS: usize = 100;

/// One candidate spot of a moving child.
#[derive(Debug, Clone, Copy)]
pub(super) struct Spot {
    /// The cell.
    pub(super) cell: Cell,
    /// Its information about the next pose.
    pub(super) info: Matrix3<f64>,
    /// Straight-line distance from the child's cell, metres.
    pub(super) travel: f64,
}

/// The best spot of one mover given the others' information `fixed` and spots
/// `others` (kept two radii clear of): `(value, index)`.
pub(super) fn best_single(
    spots: &[Spot],
    fixed: &Matrix3<f64>,
    lambda: f64,
    cost: &(impl Fn(&Matrix3<f64>) -> f64 + Sync),
    others: &[Cell],
    spacing: &Spacing,
) -> Option<(f64, usize)> {
    let scan = |from: usize, chunk: &[Spot]| {
        let mut best: Option<(f64, usize)> = None;
        for (k, s) in chunk.iter().enumerate() {
            if !others.iter().all(|&o| spacing.ok(s.cell, o)) {
                continue;
            }
            let v = cost(&(fixed + s.info)) + lambda * s.travel;
            if best.is_none_or(|(b, _)| v < b) {
                best = Some((v, from + k));
            }
        }
        best
    };
    if spots.len() < PARALLEL_SPOTS {
        return scan(0, spots);
    }
    // Chunks in parallel, their winners taken in order: the first least value,
    // as the plain scan finds it (the cost is never NaN).
    spots
        .par_chunks(PARALLEL_SPOTS / 2)
        .enumerate()
        .map(|(c, chunk)| scan(c * (PARALLEL_SPOTS / 2), chunk))
        .collect::<Vec<_>>()
        .into_iter()
        .flatten()
        .fold(None, first_least)
}

/// The first of two `(value, index)` winners in scan order unless the second
/// is strictly less.
fn first_least(a: Option<(f64, usize)>, b: (f64, usize)) -> Option<(f64, usize)> {
    match a {
        Some(x) if b.0 < x.0 => Some(b),
        Some(x) => Some(x),
        None => Some(b),
    }
}

/// Coordinate descent for three or more movers: greedy start, then each mover's
/// best spot with the others fixed, until nothing improves.
pub(super) fn descend(
    spots: &[Vec<Spot>],
    lambda: f64,
    cost: &(impl Fn(&Matrix3<f64>) -> f64 + Sync),
    spacing: &Spacing,
) -> Option<(f64, Vec<usize>)> {
    let m = spots.len();
    let mut pick: Vec<Option<usize>> = vec![None; m];
    let total = |pick: &[Option<usize>], skip: usize| {
        let mut j = Matrix3::zeros();
        let mut cells = Vec::new();
        let mut travel = 0.0;
        for (k, p) in pick.iter().enumerate() {
            if let (Some(p), true) = (p, k != skip) {
                j += spots[k][*p].info;
                cells.push(spots[k][*p].cell);
                travel += spots[k][*p].travel;
            }
        }
        (j, cells, travel)
    };
    for k in 0..m {
        let (j, cells, _) = total(&pick, k);
        let (_, s) = best_single(&spots[k], &j, lambda, cost, &cells, spacing)?;
        pick[k] = Some(s);
    }
    for _round in 0..8 {
        let mut changed = false;
        for k in 0..m {
            let (j, cells, _) = total(&pick, k);
            let (_, s) = best_single(&spots[k], &j, lambda, cost, &cells, spacing)?;
            if Some(s) != pick[k] {
                pick[k] = Some(s);
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    let (j, _, travel) = total(&pick, usize::MAX);
    let picks: Vec<usize> = pick.into_iter().map(|p| p.unwrap_or(0)).collect();
    Some((cost(&j) + lambda * travel, picks))
}

/// A node of the k-d tree of one mover's spots: `items[lo..hi]`, a matrix bounding
/// every spot's information above, the least travel, and its two halves.
#[derive(Debug, Clone)]
struct Node {
    lo: usize,
    hi: usize,
    /// Computed when the search first needs it.
    bound: OnceLock<Matrix3<f64>>,
    travel: f64,
    halves: Option<(usize, usize)>,
}

/// The k-d tree of `spots`: nodes (root first) and the spot order it sorts them in.
fn tree(spots: &[Spot]) -> (Vec<Node>, Vec<usize>) {
    let mut order: Vec<usize> = (0..spots.len()).collect();
    let mut nodes = Vec::with_capacity(2 * spots.len());
    build(spots, &mut order, 0, spots.len(), &mut nodes);
    (nodes, order)
}

fn build(
    spots: &[Spot],
    order: &mut [usize],
    lo: usize,
    hi: usize,
    nodes: &mut Vec<Node>,
) -> usize {
    let id = nodes.len();
    nodes.push(Node {
        lo,
        hi,
        bound: OnceLock::new(),
        travel: spots[order[lo]].travel,
        halves: None,
    });
    if hi - lo > 1 {
        let (mut x0, mut x1, mut y0, mut y1) = (usize::MAX, 0, usize::MAX, 0);
        for &k in &order[lo..hi] {
            let c = spots[k].cell;
            x0 = x0.min(c.x);
            x1 = x1.max(c.x);
            y0 = y0.min(c.y);
            y1 = y1.max(c.y);
        }
        let mid = (lo + hi) / 2;
        let slice = &mut order[lo..hi];
        if x1 - x0 >= y1 - y0 {
            slice.select_nth_unstable_by_key(mid - lo, |&k| (spots[k].cell.x, spots[k].cell.y));
        } else {
            slice.select_nth_unstable_by_key(mid - lo, |&k| (spots[k].cell.y, spots[k].cell.x));
        }
        let a = build(spots, order, lo, mid, nodes);
        let b = build(spots, order, mid, hi, nodes);
        nodes[id].halves = Some((a, b));
        nodes[id].travel = nodes[a].travel.min(nodes[b].travel);
    }
    id
}

/// A matrix `U ⪰ J` for every `J` of `infos`: the node's mean information, made
/// definite by a ridge along its weakest direction only (a mover's information has
/// rank two: adding information in every direction would hide what a partner must
/// supply), scaled by the largest eigenvalue of each member whitened by it. The
/// ridge is chosen among a few sizes for the smallest scale.
fn upper_bound<'a>(infos: impl Iterator<Item = &'a Matrix3<f64>> + Clone) -> Matrix3<f64> {
    let Some(whitening) = Whitening::of(infos.clone()) else {
        return Matrix3::zeros();
    };
    let fallback = || Matrix3::identity() * infos.clone().map(|j| j.trace()).fold(0.0, f64::max);
    // The ridge by a cheap estimate of each whitened member's largest eigenvalue
    // (Gershgorin's bound); the scale then exactly.
    // Each ridge's rough scale, given up as soon as it cannot beat the best
    // so far; the chosen ridge keeps each member's Gershgorin bound and norm.
    let mut chosen: Option<(f64, Matrix3<f64>, Matrix3<f64>)> = None;
    let (mut rough, mut trial) = (Vec::new(), Vec::new());
    for ridge in BOUND_RIDGES {
        let Some((q, li)) = whitening.at(ridge) else {
            continue;
        };
        trial.clear();
        let mut max = 0.0;
        let mut beaten = false;
        for j in infos.clone() {
            let (bound, norm) = gershgorin(&(li * j * li.transpose()));
            max = f64::max(max, bound);
            if chosen
                .as_ref()
                .is_some_and(|(b, _, _)| max * (1.0 + ridge) >= *b)
            {
                beaten = true;
                break;
            }
            trial.push((bound, norm));
        }
        let score = max * (1.0 + ridge);
        if !beaten && chosen.as_ref().is_none_or(|(b, _, _)| score < *b) {
            chosen = Some((score, q, li));
            std::mem::swap(&mut rough, &mut trial);
        }
    }
    let Some((_, q, li)) = chosen else {
        return fallback();
    };
    // The exact scale: a member whose Gershgorin bound lies below the largest
    // eigenvalue found so far, by more than the trigonometric form's rounding
    // (under 1e-7 of the matrix's norm), cannot raise it.
    let mut scale = 0.0;
    for (j, &(bound, norm)) in infos.zip(&rough) {
        if bound + 1e-6 * norm < scale {
            continue;
        }
        scale = f64::max(scale, max_eigenvalue(&(li * j * li.transpose())));
    }
    // A little over, for rounding.
    q * (scale * (1.0 + 1e-9) + 1e-12)
}

/// A node's members' mean information, its weakest direction and its largest
/// eigenvalue: what a bound whitens the members by.
struct Whitening {
    mean: Matrix3<f64>,
    weakest: nalgebra::Vector3<f64>,
    top: f64,
}

impl Whitening {
    /// The whitening of `infos` (`None` when there are none).
    fn of<'a>(infos: impl Iterator<Item = &'a Matrix3<f64>>) -> Option<Self> {
        let mut mean = Matrix3::zeros();
        let mut count = 0.0;
        for j in infos {
            mean += j;
            count += 1.0;
        }
        if count == 0.0 {
            return None;
        }
        mean /= count;
        let eig = mean.symmetric_eigen();
        let (mut big, mut weak) = (0, 0);
        for k in 0..3 {
            if eig.eigenvalues[k] > eig.eigenvalues[big] {
                big = k;
            }
            if eig.eigenvalues[k] < eig.eigenvalues[weak] {
                weak = k;
            }
        }
        Some(Self {
            mean,
            weakest: eig.eigenvectors.column(weak).into_owned(),
            top: eig.eigenvalues[big].max(1e-300),
        })
    }

    /// With a ridge of `ridge` times the largest eigenvalue along the weakest
    /// direction: the definite matrix `Q` and the inverse of its Cholesky
    /// factor (`None` when `Q` is not definite).
    fn at(&self, ridge: f64) -> Option<(Matrix3<f64>, Matrix3<f64>)> {
        let v = &self.weakest;
        let q = self.mean
            + v * v.transpose() * (ridge * self.top)
            + Matrix3::identity() * (1e-15 * self.top);
        q.cholesky()
            .and_then(|c| c.l().try_inverse())
            .map(|li| (q, li))
    }
}

/// Gershgorin's bound on the eigenvalues of a symmetric 3×3 matrix, and its
/// largest absolute row sum (a norm, at least every eigenvalue's size;
/// infinite when an entry is not finite, so that nothing is skipped on it).
fn gershgorin(m: &Matrix3<f64>) -> (f64, f64) {
    let mut bound = f64::NEG_INFINITY;
    let mut norm = 0.0f64;
    for i in 0..3 {
        let off = (0..3)
            .filter(|&j| j != i)
            .map(|j| m[(i, j)].abs())
            .sum::<f64>();
        bound = bound.max(m[(i, i)] + off);
        norm = norm.max(m[(i, i)].abs() + off);
    }
    if !m.iter().all(|v| v.is_finite()) {
        norm = f64::INFINITY;
    }
    (bound, norm)
}

/// The largest eigenvalue of a symmetric 3×3 matrix (trigonometric form).
fn max_eigenvalue(m: &Matrix3<f64>) -> f64 {
    let p1 = m[(0, 1)].powi(2) + m[(0, 2)].powi(2) + m[(1, 2)].powi(2);
    let q = m.trace() / 3.0;
    if p1 <= 1e-300 {
        return m[(0, 0)].max(m[(1, 1)]).max(m[(2, 2)]);
    }
    let p2 = (m[(0, 0)] - q).powi(2) + (m[(1, 1)] - q).powi(2) + (m[(2, 2)] - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let b = (m - Matrix3::identity() * q) / p;
    let r = (b.determinant() / 2.0).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    q + 2.0 * p * phi.cos()
}

/// Computes the bounds of the halves `x` and `y` of a node at once, when both
/// are still to be computed and large (each is the same whichever thread
/// computes it).
fn both_bounds(
    t: &[Node],
    order: &[usize],
    spots: &[Spot],
    x: usize,
    y: usize,
    node_bound: &(impl Fn(&[Node], &[usize], &[Spot], usize) -> Matrix3<f64> + Sync),
) {
    let open = |n: usize| t[n].bound.get().is_none() && t[n].hi - t[n].lo >= PARALLEL_BOUND;
    if open(x) && open(y) {
        rayon::join(
            || node_bound(t, order, spots, x),
            || node_bound(t, order, spots, y),
        );
    }
}

/// A pair of nodes in the branch and bound's queue, smallest bound first.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pending {
    bound: f64,
    a: usize,
    b: usize,
}

impl Eq for Pending {}

impl Ord for Pending {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .bound
            .total_cmp(&self.bound)
            .then_with(|| (other.a, other.b).cmp(&(self.a, self.b)))
    }
}

impl PartialOrd for Pending {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// How far from the optimum the pair search may stop: a share of what the best
/// value found adds to the floor no placement can remove.
#[derive(Debug, Clone, Copy)]
pub(super) struct Gap {
    /// The floor no placement can remove.
    pub(super) floor: f64,
    /// The share of the value above the floor.
    pub(super) share: f64,
}

impl Gap {
    /// The allowed gap below a value `v`.
    fn of(&self, v: f64) -> f64 {
        (self.share * (v - self.floor)).max(0.0)
    }
}

/// The best pair of spots `(value, [index in a, index in b])`, two radii apart,
/// within `gap` of the exact optimum (exact with a zero share).
pub(super) fn best_pair(
    a: &[Spot],
    b: &[Spot],
    lambda: f64,
    cost: &(impl Fn(&Matrix3<f64>) -> f64 + Sync),
    spacing: &Spacing,
    gap: Gap,
) -> Option<(f64, Vec<usize>, f64)> {
    let (ta, oa) = tree(a);
    let (tb, ob) = tree(b);
    let value =
        |i: usize, j: usize| cost(&(a[i].info + b[j].info)) + lambda * (a[i].travel + b[j].travel);
    // An incumbent: every pair of a thinned lattice of both sets, then each
    // spot's best partner in turn over the full sets.
    let thin = |n: usize| (n / LATTICE_SPOTS).max(1);
    let (sa, sb) = (thin(a.len()), thin(b.len()));
    // Row by row in parallel, each row's first least value, then the rows'
    // in order: the pair a plain scan of the rows finds.
    let rows: Vec<usize> = (0..a.len()).step_by(sa).collect();
    let row_best = |&i: &usize| {
        let mut best: Option<(f64, usize)> = None;
        for j in (0..b.len()).step_by(sb) {
            if spacing.ok(a[i].cell, b[j].cell) {
                let v = value(i, j);
                if best.is_none_or(|(bv, _)| v < bv) {
                    best = Some((v, j));
                }
            }
        }
        best.map(|(v, j)| (v, i, j))
    };
    let mut best: Option<(f64, usize, usize)> = None;
    for (v, i, j) in rows
        .par_iter()
        .map(row_best)
        .collect::<Vec<_>>()
        .into_iter()
        .flatten()
    {
        if best.is_none_or(|(bv, _, _)| v < bv) {
            best = Some((v, i, j));
        }
    }
    if let Some((_, mut i, mut j)) = best {
        for _ in 0..3 {
            let Some((_, ii)) = best_single(a, &b[j].info, lambda, cost, &[b[j].cell], spacing)
            else {
                break;
            };
            i = ii;
            let Some((_, jj)) = best_single(b, &a[i].info, lambda, cost, &[a[i].cell], spacing)
            else {
                break;
            };
            j = jj;
        }
        let v = value(i, j);
        if best.is_none_or(|(bv, _, _)| v < bv) {
            best = Some((v, i, j));
        }
    }
    let node_bound = |t: &[Node], order: &[usize], spots: &[Spot], n: usize| {
        *t[n]
            .bound
            .get_or_init(|| upper_bound(order[t[n].lo..t[n].hi].iter().map(|&k| &spots[k].info)))
    };
    let bound = |na: usize, nb: usize| {
        let u = node_bound(&ta, &oa, a, na) + node_bound(&tb, &ob, b, nb);
        cost(&u) + lambda * (ta[na].travel + tb[nb].travel)
    };
    let mut queue = BinaryHeap::new();
    queue.push(Pending {
        bound: bound(0, 0),
        a: 0,
        b: 0,
    });
    let mut pops = 0;
    while let Some(p) = queue.pop() {
        if best.is_some_and(|(bv, _, _)| p.bound >= bv - gap.of(bv)) {
            break;
        }
        pops += 1;
        if pops > MAX_POPS {
            break;
        }
        let (na, nb) = (&ta[p.a], &tb[p.b]);
        match (na.halves, nb.halves) {
            (None, None) => {
                let (i, j) = (oa[na.lo], ob[nb.lo]);
                if spacing.ok(a[i].cell, b[j].cell) {
                    let v = value(i, j);
                    if best.is_none_or(|(bv, _, _)| v < bv) {
                        best = Some((v, i, j));
                    }
                }
            }
            (ha, hb) => {
                // Split the node with more spots.
                let split_a = match (ha, hb) {
                    (Some(_), None) => true,
                    (None, Some(_)) => false,
                    _ => na.hi - na.lo >= nb.hi - nb.lo,
                };
                let pairs = if split_a {
                    let (x, y) = ha.expect("split node has halves");
                    both_bounds(&ta, &oa, a, x, y, &node_bound);
                    [(x, p.b), (y, p.b)]
                } else {
                    let (x, y) = hb.expect("split node has halves");
                    both_bounds(&tb, &ob, b, x, y, &node_bound);
                    [(p.a, x), (p.a, y)]
                };
                for (x, y) in pairs {
                    let lb = bound(x, y);
                    if best.is_none_or(|(bv, _, _)| lb < bv - gap.of(bv)) {
                        queue.push(Pending {
                            bound: lb,
                            a: x,
                            b: y,
                        });
                    }
                }
            }
        }
    }
    // The gap still open: the least bound of the pairs not examined.
    let open = queue.peek().map(|p| p.bound);
    let proven = match (best, open) {
        (Some((bv, _, _)), Some(lb)) if pops > MAX_POPS => ((bv - lb) / (bv - gap.floor)).max(0.0),
        _ => 0.0,
    };
    if std::env::var_os("CPSPLAN_DEBUG_BB").is_some() {
        eprintln!("bb {} x {} pops {pops} gap {proven:.4}", a.len(), b.len());
        if a.len() * b.len() <= 400_000_000 {
            let mut ex = f64::INFINITY;
            for (i, sa) in a.iter().enumerate() {
                for (j, sb) in b.iter().enumerate() {
                    if spacing.ok(sa.cell, sb.cell) {
                        ex = ex.min(value(i, j));
                    }
                }
            }
            let bv = best.map_or(f64::NAN, |b| b.0);
            eprintln!(
                "exhaustive {ex} found {bv} excess {:.6}",
                (bv - ex) / (ex - gap.floor)
            );
        }
    }
    best.map(|(v, i, j)| (v, vec![i, j], proven))
}

#[cfg(test)]
mod tests;
