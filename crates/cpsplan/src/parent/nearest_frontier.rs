//! The nearest-frontier baseline (`--planner frontier`, beyond the paper): the
//! frontier search and cost model of ROS explore_lite (m-explore), with its
//! default weights.
//!
//! In: the knowledge map and the parent's cell. Out: the frontiers reachable
//! through known-Free space, cheapest first. A frontier is a group of 8-connected
//! Unknown cells with a Free 4-neighbour, found by a breadth-first search over
//! the Free cells 4-connected to the parent; groups smaller than
//! `parent.frontier_min_size` metres (in cells) are dropped. Its cost is
//! `potential_scale · d · r − gain_scale · n · r`, with `d` the straight-line
//! distance in metres from the parent to its nearest cell, `n` its cell count and
//! `r` the resolution: with the defaults (10⁻³ and 1) the largest frontier wins
//! and distance only breaks ties, as explore_lite does. The robot is sent to the
//! frontier's centroid; here that is the drivable, reachable cell nearest to it.

use std::collections::VecDeque;

use super::border::flood_group;
use crate::config::ParentConfig;
use crate::geom::Cell;
use crate::grid::{CellState, GridGeometry, OccupancyGrid};

/// One frontier of the explore_lite search.
#[derive(Debug, Clone, PartialEq)]
pub struct FrontierGoal {
    /// Its Unknown cells.
    pub cells: usize,
    /// The mean of their centres, in cell units (`x + 0.5` is a cell's centre).
    pub centroid: [f64; 2],
    /// Straight-line distance from the parent's cell centre to its nearest cell
    /// centre, metres.
    pub min_distance_m: f64,
    /// explore_lite's cost (lower is better).
    pub cost: f64,
}

/// The frontiers reachable from `parent` through Free cells, cheapest first (ties
/// in the order the search met them).
pub fn frontier_goals(
    knowledge: &OccupancyGrid,
    parent: Cell,
    config: &ParentConfig,
) -> Vec<FrontierGoal> {
    let g = knowledge.geometry();
    let (w, h) = (g.width, g.height);
    let k = knowledge.cells();
    let n = k.len();
    let start = g.index(parent);
    if start >= n || k[start] != CellState::Free {
        return Vec::new();
    }
    let res = g.resolution;
    let min_cells = config.frontier_min_size / res;
    let mut visited = vec![false; n];
    let mut frontier = vec![false; n];
    let mut goals = Vec::new();
    let mut queue = VecDeque::from([start]);
    let mut group = Vec::new();
    visited[start] = true;
    let (px, py) = (parent.x as f64, parent.y as f64);
    let is_new_frontier = |i: usize, frontier: &[bool]| {
        k[i] == CellState::Unknown
            && !frontier[i]
            && neighbours4(i, w, h).any(|j| k[j] == CellState::Free)
    };
    while let Some(i) = queue.pop_front() {
        for j in neighbours4(i, w, h) {
            if k[j] == CellState::Free && !visited[j] {
                visited[j] = true;
                queue.push_back(j);
            } else if is_new_frontier(j, &frontier) {
                // A new frontier: its 8-connected Unknown cells with a Free
                // 4-neighbour.
                frontier[j] = true;
                flood_group(g, j, &mut group, |m| {
                    let new = is_new_frontier(m, &frontier);
                    if new {
                        frontier[m] = true;
                    }
                    new
                });
                let cells = group.len();
                let (mut sx, mut sy, mut nearest) = (0.0, 0.0, f64::INFINITY);
                for &f in &group {
                    let (fx, fy) = ((f % w) as f64, (f / w) as f64);
                    sx += fx + 0.5;
                    sy += fy + 0.5;
                    nearest = nearest.min((fx - px).hypot(fy - py) * res);
                }
                if cells as f64 >= min_cells {
                    goals.push(FrontierGoal {
                        cells,
                        centroid: [sx / cells as f64, sy / cells as f64],
                        min_distance_m: nearest,
                        cost: config.frontier_potential_scale * nearest * res
                            - config.frontier_gain_scale * cells as f64 * res,
                    });
                }
            }
        }
    }
    goals.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    goals
}

/// The cell with `valid(index)` whose centre is nearest to `point` (cell units),
/// the lowest index among equally near ones; `None` if no cell is valid.
pub fn nearest_valid_cell(
    g: &GridGeometry,
    point: [f64; 2],
    valid: impl Fn(usize) -> bool,
) -> Option<Cell> {
    let (w, h) = (g.width as i64, g.height as i64);
    if w == 0 || h == 0 {
        return None;
    }
    let cx = (point[0].floor() as i64).clamp(0, w - 1);
    let cy = (point[1].floor() as i64).clamp(0, h - 1);
    let d2 = |x: i64, y: i64| {
        let (dx, dy) = (x as f64 + 0.5 - point[0], y as f64 + 0.5 - point[1]);
        dx * dx + dy * dy
    };
    let mut best: Option<(f64, usize)> = None;
    for r in 0..w.max(h) {
        // Every cell of ring r is at least r − 1 from the point (which lies within
        // the clamped cell or beyond the grid's edge on its side).
        if let Some((b, _)) = best {
            let near = (r - 1).max(0) as f64;
            if near * near > b {
                break;
            }
        }
        let (x0, x1, y0, y1) = (cx - r, cx + r, cy - r, cy + r);
        let mut visit = |x: i64, y: i64| {
            if x < 0 || y < 0 || x >= w || y >= h {
                return;
            }
            let i = (y * w + x) as usize;
            if valid(i) {
                let d = d2(x, y);
                if best.is_none_or(|(b, bi)| (d, i) < (b, bi)) {
                    best = Some((d, i));
                }
            }
        };
        for x in x0..=x1 {
            visit(x, y0);
            if r > 0 {
                visit(x, y1);
            }
        }
        for y in y0 + 1..y1 {
            visit(x0, y);
            visit(x1, y);
        }
    }
    best.map(|(_, i)| Cell::new(i % g.width, i / g.width))
}

fn neighbours4(i: usize, w: usize, h: usize) -> impl Iterator<Item = usize> {
    let (x, y) = (i % w, i / w);
    [
        (x + 1 < w).then(|| i + 1),
        (x > 0).then(|| i - 1),
        (y + 1 < h).then(|| i + w),
        (y > 0).then(|| i - w),
    ]
    .into_iter()
    .flatten()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;

    /// A 20 × 10 map: Free on the left (x < 10) with a wall at x = 5 open only at
    /// y = 1, Unknown on the right.
    fn map() -> OccupancyGrid {
        let g = GridGeometry::new(20, 10, 0.1, Point::new(0.0, 0.0));
        let mut cells = vec![CellState::Unknown; 200];
        for y in 0..10 {
            for x in 0..10 {
                cells[y * 20 + x] = if x == 5 && y != 1 {
                    CellState::Occupied
                } else {
                    CellState::Free
                };
            }
        }
        OccupancyGrid::from_cells(g, cells).unwrap()
    }

    #[test]
    fn a_frontier_is_the_unknown_line_beside_the_reachable_free_space() {
        let mut config = ParentConfig::default();
        let goals = frontier_goals(&map(), Cell::new(1, 1), &config);
        assert_eq!(goals.len(), 1);
        let f = &goals[0];
        assert_eq!(f.cells, 10, "the column x = 10");
        assert_eq!(f.centroid, [10.5, 5.0]);
        assert!(
            (f.min_distance_m - 0.9).abs() < 1e-12,
            "{}",
            f.min_distance_m
        );
        let expect = 1e-3 * 0.9 * 0.1 - 10.0 * 0.1;
        assert!((f.cost - expect).abs() < 1e-12);
        // Groups below the minimum size are dropped.
        config.frontier_min_size = 1.05;
        assert!(frontier_goals(&map(), Cell::new(1, 1), &config).is_empty());
    }

    #[test]
    fn frontiers_behind_unknown_or_walls_are_not_found() {
        let mut m = map();
        // Close the wall's gap: the frontier is out of reach from x < 5.
        m.set(Cell::new(5, 1), CellState::Occupied);
        assert!(frontier_goals(&m, Cell::new(1, 1), &ParentConfig::default()).is_empty());
        assert_eq!(
            frontier_goals(&m, Cell::new(7, 1), &ParentConfig::default()).len(),
            1
        );
    }

    #[test]
    fn larger_frontiers_cost_less() {
        // Two separate Unknown pockets in a Free room: 1 and 6 cells.
        let g = GridGeometry::new(12, 12, 0.1, Point::new(0.0, 0.0));
        let mut cells = vec![CellState::Free; 144];
        cells[2 * 12 + 2] = CellState::Unknown;
        for x in 4..10 {
            cells[9 * 12 + x] = CellState::Unknown;
        }
        let m = OccupancyGrid::from_cells(g, cells).unwrap();
        let config = ParentConfig {
            frontier_min_size: 0.0,
            ..ParentConfig::default()
        };
        let goals = frontier_goals(&m, Cell::new(2, 3), &config);
        let sizes: Vec<usize> = goals.iter().map(|f| f.cells).collect();
        assert_eq!(sizes, [6, 1], "cheapest first, although farther");
    }

    #[test]
    fn the_nearest_valid_cell_is_found_from_any_point() {
        let g = GridGeometry::new(30, 20, 0.1, Point::new(0.0, 0.0));
        let valid = |i: usize| i % 30 == 25 && i / 30 == 3 || i % 30 == 2 && i / 30 == 18;
        for (p, expect) in [
            ([25.5, 3.5], Cell::new(25, 3)),
            ([0.0, 0.0], Cell::new(2, 18)),
            ([29.0, 0.0], Cell::new(25, 3)),
            ([-50.0, 40.0], Cell::new(2, 18)),
        ] {
            let got = nearest_valid_cell(&g, p, valid).unwrap();
            // Brute force.
            let brute = (0..600)
                .filter(|&i| valid(i))
                .min_by(|&a, &b| {
                    let d = |i: usize| {
                        let (x, y) = ((i % 30) as f64 + 0.5, (i / 30) as f64 + 0.5);
                        (x - p[0]).powi(2) + (y - p[1]).powi(2)
                    };
                    d(a).total_cmp(&d(b))
                })
                .unwrap();
            assert_eq!(got, expect, "{p:?}");
            assert_eq!(g.index(got), brute, "{p:?}");
        }
        assert_eq!(nearest_valid_cell(&g, [3.0, 3.0], |_| false), None);
    }
}
