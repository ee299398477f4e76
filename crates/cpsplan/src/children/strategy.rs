//! The child strategies beyond Eq. (2)'s weights (paper section V-A-2, Fig. 10):
//! (a) random spots, and (e) the spots that minimise the predicted error of the
//! parent's next pose.
//!
//! In: the step's maps; for `random` a cycle already placed by Eq. (2) (so known
//! to be feasible), for `min-error` the cycle's [`CycleFrame`] (its AND regions,
//! known to be placeable) and the CPS chain before the cycle. Out: the cycle with
//! the strategy's spots.
//!
//! # `min-error`
//!
//! For every choice of which children stay (a child may stay only where it already
//! stands in its AND region and its point has been measured), the moving children's
//! spots minimise `σ(J) + λ·travel`, where `σ(J)` is the square root of the
//! [`Objective`] (the next pose's `σx² + σy² + L²·σω²`) for the sum `J` of the
//! movers' information, `travel` the movers' straight-line distance to their spots
//! and `λ` the travel weight. The search ([`super::pair_search`]) runs on one
//! spot per [`SPOT_PITCH_M`] square of each AND region (the objective changes
//! little over such a square, and the search costs the square of the spots it
//! weighs); the winning spots are then polished at the grid's own resolution,
//! each mover in turn over the cells around its spot.

use std::collections::HashMap;

use nalgebra::Matrix3;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::and_region::{and_region, AndRegion, ChildReach};
use super::clearance::clearances;
use super::cycle::{spacing_of, CpsCycle, CycleChild, CycleFrame};
use super::maps::StepMaps;
use super::pair_search::{best_pair, best_single, descend, Gap, Spot, SEARCH_GAP};
use super::placement::Placement;
use super::spacing::Spacing;
use crate::accuracy::{Chain, Objective};
use crate::geom::Cell;
use crate::grid::GridGeometry;

/// The AND region of every child of `cycle`, as the cycle was planned.
fn regions(maps: &StepMaps, cycle: &CpsCycle, reach: &[ChildReach]) -> Vec<AndRegion> {
    let mutual = maps.mutual_view(cycle.parent_from, cycle.parent_to);
    reach.iter().map(|r| and_region(&mutual, r)).collect()
}

/// Strategy (a): every child that moves in `cycle` takes a random spot of its AND
/// region, clear of the others.
pub fn place_random(
    maps: &StepMaps,
    cycle: &CpsCycle,
    reach: &[ChildReach],
    rng: &mut ChaCha8Rng,
) -> CpsCycle {
    let g = *maps.knowledge().geometry();
    let spacing = spacing_of(maps, cycle.parent_from, cycle.parent_to);
    let regions = regions(maps, cycle, reach);
    let mut out = cycle.clone();
    let mut taken: Vec<Cell> = cycle
        .children
        .iter()
        .filter(|c| c.stays)
        .map(|c| c.to)
        .collect();
    for (i, child) in out.children.iter_mut().enumerate() {
        if child.stays {
            continue;
        }
        let free: Vec<Cell> = regions[i]
            .cells
            .iter()
            .map(|&j| g.cell(j as usize))
            .filter(|&c| taken.iter().all(|&t| spacing.ok(c, t)))
            .collect();
        if free.is_empty() {
            // No room left: the Eq. (2) spots, clear of each other by construction.
            return cycle.clone();
        }
        let cell = free[rng.random_range(0..free.len())];
        *child = moved(maps, child.from, cell, cycle.parent_to, regions[i].size());
        taken.push(cell);
    }
    fill_angles(&mut out);
    out
}

/// A child that moves from `from` to `to`, its Eq. (2) terms for the record.
fn moved(maps: &StepMaps, from: Cell, to: Cell, target: Cell, region: usize) -> CycleChild {
    let g = maps.knowledge().geometry();
    let cap = maps.params().eq2.clearance_cap;
    let clearance = clearances(maps.knowledge(), &[g.index(to) as u32], cap)[0];
    CycleChild {
        from,
        to,
        stays: false,
        path: vec![from, to],
        placement: Some(Placement {
            cell: to,
            clearance,
            distance: metres(g, to, target),
            theta: None,
        }),
        and_region_cells: region,
    }
}

fn metres(g: &GridGeometry, a: Cell, b: Cell) -> f64 {
    (a.x as f64 - b.x as f64).hypot(a.y as f64 - b.y as f64) * g.resolution
}

/// The Eq. (2) angle of every moving child to its pair partner (children 1–2, 3–4,
/// …), seen from the parent's target.
fn fill_angles(cycle: &mut CpsCycle) {
    let t = cycle.parent_to;
    let bearing = |c: Cell| (c.y as f64 - t.y as f64).atan2(c.x as f64 - t.x as f64);
    let cells: Vec<Cell> = cycle.children.iter().map(|c| c.to).collect();
    for (i, child) in cycle.children.iter_mut().enumerate() {
        let partner = i ^ 1;
        if let (Some(p), Some(&other)) = (child.placement.as_mut(), cells.get(partner)) {
            let d = (bearing(child.to) - bearing(other)).abs() % std::f64::consts::TAU;
            p.theta = Some(d.min(std::f64::consts::TAU - d));
        }
    }
}

/// The side of the squares of an AND region of which the `min-error` search
/// weighs one spot each, metres (the objective changes by well under the search's
/// gap across one; the polish then works at the grid's resolution).
pub const SPOT_PITCH_M: f64 = 0.3;

/// Rounds of the polish: each mover in turn takes its best cell around its spot.
const POLISH_ROUNDS: usize = 4;

/// Strategy (e): the spots, and whether each child stays, that minimise the
/// predicted error of the parent's next pose plus `travel_weight` (mm of σ per
/// metre of child travel) times the children's travel, over the AND regions of
/// `frame`; `chain` is the CPS chain before the cycle. `None` when no choice
/// fixes the next pose.
pub fn place_min_error(
    maps: &StepMaps,
    frame: &CycleFrame,
    chain: &Chain,
    travel_weight: f64,
) -> Option<CpsCycle> {
    let g = *maps.knowledge().geometry();
    let spacing = &frame.spacing;
    let regions = &frame.regions;
    let n = frame.children.len();
    let measured = chain.points();
    let here = &frame.children;
    let may_stay: Vec<usize> = (0..n)
        .filter(|&i| regions[i].contains(g.index(here[i])) && measured[i].is_some())
        .collect();
    let lambda = travel_weight * 1e-3;
    let to = g.cell_center(frame.parent_to);
    let sighted = chain.in_sight(maps.knowledge(), frame.parent_to, &maps.params().targets);
    let pitch = spot_pitch(&g);
    let lattice: Vec<Vec<u32>> = regions
        .iter()
        .map(|r| thinned(&g, &r.cells, pitch))
        .collect();
    // A mover's information depends on its cell only (not on who stays).
    let mut infos: HashMap<u32, Matrix3<f64>> = HashMap::new();
    let mut best: Option<Choice> = None;
    for mask in 0..(1usize << may_stay.len()) {
        let stayers: Vec<usize> = may_stay
            .iter()
            .enumerate()
            .filter(|&(b, _)| mask >> b & 1 == 1)
            .map(|(_, &i)| i)
            .collect();
        let hidden = stayers
            .iter()
            .enumerate()
            .any(|(k, &a)| stayers[..k].iter().any(|&b| !spacing.ok(here[a], here[b])));
        if hidden {
            continue;
        }
        let Some(objective) = Objective::with_targets(chain, to, &stayers, &sighted) else {
            continue;
        };
        let movers: Vec<usize> = (0..n).filter(|i| !stayers.contains(i)).collect();
        let stay_cells: Vec<Cell> = stayers.iter().map(|&s| here[s]).collect();
        // Each mover's lattice spots clear of the children that stay.
        let usable: Vec<Vec<u32>> = movers
            .iter()
            .map(|&i| {
                lattice[i]
                    .iter()
                    .copied()
                    .filter(|&j| clear_of(spacing, g.cell(j as usize), &stay_cells))
                    .collect()
            })
            .collect();
        // The information of the spots not met before, in parallel.
        let mut new: Vec<u32> = usable
            .iter()
            .flatten()
            .copied()
            .filter(|j| !infos.contains_key(j))
            .collect();
        new.sort_unstable();
        new.dedup();
        let computed: Vec<Matrix3<f64>> = new
            .par_iter()
            .map(|&j| objective.mover_info(g.cell_center(g.cell(j as usize))))
            .collect();
        infos.extend(new.into_iter().zip(computed));
        let spots: Vec<Vec<Spot>> = movers
            .iter()
            .zip(&usable)
            .map(|(&i, cells)| {
                cells
                    .iter()
                    .filter_map(|&j| infos.get(&j).map(|&info| spot_at(&g, j, info, here[i])))
                    .collect()
            })
            .collect();
        if spots.iter().any(Vec::is_empty) {
            continue;
        }
        let cost = |j: &Matrix3<f64>| objective.value(j).max(0.0).sqrt();
        let found = match spots.len() {
            0 => Some((cost(&Matrix3::zeros()), Vec::new(), 0.0)),
            1 => best_single(&spots[0], &Matrix3::zeros(), lambda, &cost, &[], spacing)
                .map(|(v, s)| (v, vec![s], 0.0)),
            2 => best_pair(
                &spots[0],
                &spots[1],
                lambda,
                &cost,
                spacing,
                Gap {
                    floor: objective.floor(),
                    share: SEARCH_GAP,
                },
            ),
            _ => descend(&spots, lambda, &cost, spacing).map(|(v, p)| (v, p, f64::NAN)),
        };
        let Some((value, picks, gap)) = found else {
            continue;
        };
        if !value.is_finite() {
            continue;
        }
        if best.as_ref().is_none_or(|b| value < b.value) {
            let cells = picks
                .iter()
                .enumerate()
                .map(|(k, &s)| spots[k][s].cell)
                .collect();
            best = Some(Choice {
                value,
                movers,
                cells,
                gap,
                objective,
                stay_cells,
            });
        }
    }
    let best = best?;
    let cells = polish(&best, regions, here, spacing, lambda, pitch, &g);
    let children = (0..n)
        .map(|i| match best.movers.iter().position(|&m| m == i) {
            Some(k) => moved(maps, here[i], cells[k], frame.parent_to, regions[i].size()),
            None => CycleChild::staying(here[i], regions[i].size()),
        })
        .collect();
    let mut out = CpsCycle {
        parent_from: frame.parent_from,
        parent_to: frame.parent_to,
        children,
        search_gap: Some(best.gap),
    };
    fill_angles(&mut out);
    Some(out)
}

/// The best choice of one stay mask: its value, the movers and their spots on the
/// lattice, the search's proven gap, and what the polish needs.
struct Choice {
    value: f64,
    movers: Vec<usize>,
    cells: Vec<Cell>,
    gap: f64,
    objective: Objective,
    stay_cells: Vec<Cell>,
}

/// [`SPOT_PITCH_M`] in cells of `g` (at least one).
fn spot_pitch(g: &GridGeometry) -> usize {
    let cells = (SPOT_PITCH_M / g.resolution).round();
    if cells >= 1.0 {
        cells as usize
    } else {
        1
    }
}

/// One cell per `pitch` × `pitch` square of the grid among `cells` (ascending
/// indices, as an AND region's): the member nearest the square's centre (the
/// lower index on a tie), ascending.
fn thinned(g: &GridGeometry, cells: &[u32], pitch: usize) -> Vec<u32> {
    if pitch <= 1 {
        return cells.to_vec();
    }
    debug_assert!(cells.windows(2).all(|w| w[0] < w[1]));
    // Ascending cells visit the squares one row of squares at a time: the
    // nearest member so far of each square of the current row, by column.
    let mut nearest: Vec<Option<(usize, u32)>> = vec![None; g.width.div_ceil(pitch)];
    let mut touched: Vec<usize> = Vec::new();
    let mut out: Vec<u32> = Vec::new();
    let mut flush = |nearest: &mut [Option<(usize, u32)>], touched: &mut Vec<usize>| {
        out.extend(
            touched
                .drain(..)
                .filter_map(|s| nearest[s].take().map(|(_, j)| j)),
        );
    };
    let mut square_row = None;
    for &j in cells {
        let c = g.cell(j as usize);
        let square = (c.x / pitch, c.y / pitch);
        if square_row != Some(square.1) {
            flush(&mut nearest, &mut touched);
            square_row = Some(square.1);
        }
        // Twice the offset from the square's centre, in cells.
        let off = |v: usize, s: usize| (2 * v).abs_diff(2 * s * pitch + pitch - 1);
        let d = off(c.x, square.0).pow(2) + off(c.y, square.1).pow(2);
        let entry = &mut nearest[square.0];
        match entry {
            Some(e) => *e = (*e).min((d, j)),
            None => {
                *entry = Some((d, j));
                touched.push(square.0);
            }
        }
    }
    flush(&mut nearest, &mut touched);
    out.sort_unstable();
    out
}

/// Whether a mover at `c` stands clear of every child in `others`.
fn clear_of(spacing: &Spacing, c: Cell, others: &[Cell]) -> bool {
    others.iter().all(|&o| spacing.ok(c, o))
}

/// The spot of cell `j` for a child at `from`.
fn spot_at(g: &GridGeometry, j: u32, info: Matrix3<f64>, from: Cell) -> Spot {
    let cell = g.cell(j as usize);
    Spot {
        cell,
        info,
        travel: metres(g, from, cell),
    }
}

/// The lattice spots of `choice` polished at the grid's resolution: each mover in
/// turn takes the best cell of its region within `pitch` cells of its spot, the
/// others fixed, until none moves (the value never rises: each spot is its own
/// neighbour).
fn polish(
    choice: &Choice,
    regions: &[AndRegion],
    here: &[Cell],
    spacing: &Spacing,
    lambda: f64,
    pitch: usize,
    g: &GridGeometry,
) -> Vec<Cell> {
    let mut cells = choice.cells.clone();
    if pitch <= 1 {
        return cells;
    }
    let objective = &choice.objective;
    let cost = |j: &Matrix3<f64>| objective.value(j).max(0.0).sqrt();
    let windows: Vec<Vec<Spot>> = choice
        .movers
        .iter()
        .zip(&cells)
        .map(|(&i, &c)| {
            let (x0, y0) = (c.x.saturating_sub(pitch), c.y.saturating_sub(pitch));
            let (x1, y1) = (
                (c.x + pitch).min(g.width - 1),
                (c.y + pitch).min(g.height - 1),
            );
            (y0..=y1)
                .flat_map(|y| (x0..=x1).map(move |x| Cell::new(x, y)))
                .filter(|&n| regions[i].contains(g.index(n)))
                .filter(|&n| clear_of(spacing, n, &choice.stay_cells))
                .map(|n| {
                    let info = objective.mover_info(g.cell_center(n));
                    spot_at(g, g.index(n) as u32, info, here[i])
                })
                .collect()
        })
        .collect();
    for _ in 0..POLISH_ROUNDS {
        let mut changed = false;
        for k in 0..cells.len() {
            let mut fixed = Matrix3::zeros();
            let mut others = Vec::with_capacity(cells.len());
            for (l, &c) in cells.iter().enumerate() {
                if l != k {
                    let at = windows[l].iter().find(|s| s.cell == c);
                    fixed += at.map_or_else(|| objective.mover_info(g.cell_center(c)), |s| s.info);
                    others.push(c);
                }
            }
            if let Some((_, s)) = best_single(&windows[k], &fixed, lambda, &cost, &others, spacing)
            {
                if windows[k][s].cell != cells[k] {
                    cells[k] = windows[k][s].cell;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    cells
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::HashSet;

    proptest! {
        /// The lattice keeps exactly one member of every square that has any,
        /// the one nearest the square's centre.
        #[test]
        fn one_cell_per_square_nearest_its_centre(
            cells in proptest::collection::btree_set(0u32..2_500, 0..400),
            pitch in 1usize..6,
        ) {
            let g = GridGeometry::new(50, 50, 0.1, crate::geom::Point::new(0.0, 0.0));
            let cells: Vec<u32> = cells.into_iter().collect();
            let kept = thinned(&g, &cells, pitch);
            prop_assert!(kept.windows(2).all(|w| w[0] < w[1]));
            let square = |j: u32| {
                let c = g.cell(j as usize);
                (c.x / pitch, c.y / pitch)
            };
            let squares: HashSet<_> = cells.iter().map(|&j| square(j)).collect();
            prop_assert_eq!(kept.len(), squares.len());
            let centre = |j: u32| {
                let c = g.cell(j as usize);
                let (sx, sy) = square(j);
                let mid = |s: usize| (s * pitch) as f64 + (pitch as f64 - 1.0) / 2.0;
                (c.x as f64 - mid(sx)).hypot(c.y as f64 - mid(sy))
            };
            for &k in &kept {
                prop_assert!(cells.binary_search(&k).is_ok());
                for &j in cells.iter().filter(|&&j| square(j) == square(k)) {
                    prop_assert!(centre(k) <= centre(j) + 1e-12);
                }
            }
        }
    }

    #[test]
    fn the_pitch_is_at_least_one_cell() {
        let at = |res: f64| {
            spot_pitch(&GridGeometry::new(
                10,
                10,
                res,
                crate::geom::Point::new(0.0, 0.0),
            ))
        };
        assert_eq!(at(0.1), 3);
        assert_eq!(at(0.05), 6);
        assert_eq!(at(1.0), 1);
    }
}
