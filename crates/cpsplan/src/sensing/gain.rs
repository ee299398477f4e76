//! The expected gain in square metres (beyond the paper), calibrated against what
//! scans actually add, and the rule that says whether a position is worth a scan.
//!
//! `S` of Eq. (1) counts every Unknown cell in view with Unknown treated as empty,
//! so it counts the unknown space behind walls that are not yet seen: measured
//! over the built-in and shared maps, a scan added a median 8 % of its `S`
//! (docs/RESULTS.md). The estimate here counts only the Unknown cells in view
//! that lie within `parent.unknown_depth` of known free space (beyond that the
//! beam has most likely met a wall), scaled by `parent.gain_scale`, the measured
//! ratio of free area added to that count.

use crate::config::Config;
use crate::geom::Cell;
use crate::grid::distance::transform;
use crate::grid::{CellState, OccupancyGrid};

use super::visible_cells;

/// The gain estimate of one knowledge map.
#[derive(Debug, Clone)]
pub struct GainEstimate {
    /// Unknown cells within `unknown_depth` of a known-Free cell.
    near: Vec<bool>,
    /// Area of one cell, m².
    cell_m2: f64,
    /// `parent.gain_scale`.
    scale: f64,
    /// Known free area, m².
    known_free_m2: f64,
    /// `parent.min_gain_cells`, `parent.min_gain_m2` and the share.
    min_cells: usize,
    min_m2: f64,
    min_share: f64,
}

/// What a position is expected to add.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gain {
    /// `S` of Eq. (1): Unknown cells in view, Unknown treated as empty.
    pub s_cells: usize,
    /// Of those, the cells within `unknown_depth` of known free space.
    pub near_cells: usize,
    /// The calibrated estimate of the free area added, m².
    pub m2: f64,
}

impl GainEstimate {
    /// The estimate for `knowledge` with the parameters of `config.parent`.
    pub fn new(knowledge: &OccupancyGrid, config: &Config) -> Self {
        let g = knowledge.geometry();
        let k = knowledge.cells();
        let depth = config.parent.unknown_depth / g.resolution;
        let d = transform(g.width, g.height, |x, y| {
            k[y * g.width + x] == CellState::Free
        });
        let near = k
            .iter()
            .zip(&d)
            .map(|(&c, &d)| c == CellState::Unknown && (d as f64) <= depth + 1e-9)
            .collect();
        let cell_m2 = g.resolution * g.resolution;
        let free = k.iter().filter(|&&c| c == CellState::Free).count();
        Self {
            near,
            cell_m2,
            scale: config.parent.gain_scale,
            known_free_m2: free as f64 * cell_m2,
            min_cells: config.parent.min_gain_cells,
            min_m2: config.parent.min_gain_m2,
            min_share: config.parent.min_gain_share,
        }
    }

    /// The gain of a scan from `at` within `range_cells` (one visibility sweep,
    /// the rule of [`super::expected_gain`]).
    pub fn at(&self, knowledge: &OccupancyGrid, at: Cell, range_cells: f64) -> Gain {
        self.view(knowledge, at, range_cells, |_| {})
    }

    /// [`Self::at`], calling `on_near(index)` for every counted cell near known
    /// free space (the cells the estimate stands for).
    pub fn view(
        &self,
        knowledge: &OccupancyGrid,
        at: Cell,
        range_cells: f64,
        mut on_near: impl FnMut(usize),
    ) -> Gain {
        let k = knowledge.cells();
        let (mut s, mut near) = (0usize, 0usize);
        visible_cells(
            knowledge.geometry(),
            at,
            range_cells,
            |i| k[i] == CellState::Occupied,
            |i| {
                if k[i] == CellState::Unknown {
                    s += 1;
                    if self.near[i] {
                        near += 1;
                        on_near(i);
                    }
                }
                false
            },
        );
        Gain {
            s_cells: s,
            near_cells: near,
            m2: self.m2(near),
        }
    }

    /// The calibrated area, m², of `near_cells` cells.
    pub fn m2(&self, near_cells: usize) -> f64 {
        near_cells as f64 * self.cell_m2 * self.scale
    }

    /// The known free area, m².
    pub fn known_free_m2(&self) -> f64 {
        self.known_free_m2
    }

    /// The least estimated area, m², a scan must add to be planned: at least
    /// `parent.min_gain_m2` and `parent.min_gain_share` of the known free area.
    pub fn threshold_m2(&self) -> f64 {
        self.min_m2.max(self.min_share * self.known_free_m2)
    }

    /// Whether a scan with `gain` is worth planning: `S ≥ min_gain_cells` and
    /// the estimate at least [`Self::threshold_m2`].
    pub fn worth_a_scan(&self, gain: &Gain) -> bool {
        gain.s_cells >= self.min_cells && gain.m2 >= self.threshold_m2()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::grid::GridGeometry;

    #[test]
    fn counts_only_unknown_near_known_free_space() {
        // A corridor known up to x = 20, unknown beyond; depth 1 m = 10 cells.
        let g = GridGeometry::new(100, 10, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Unknown);
        k.fill_rect(0, 0, 100, 1, CellState::Occupied);
        k.fill_rect(0, 9, 100, 10, CellState::Occupied);
        k.fill_rect(0, 1, 20, 9, CellState::Free);
        let mut config = Config::default();
        config.parent.unknown_depth = 1.0;
        config.parent.gain_scale = 1.0;
        let e = GainEstimate::new(&k, &config);
        let gain = e.at(&k, Cell::new(10, 5), 200.0);
        assert_eq!(gain.s_cells, 80 * 8);
        assert_eq!(gain.near_cells, 10 * 8);
        assert!((gain.m2 - 0.8).abs() < 1e-9);
        assert!((e.known_free_m2() - 1.6).abs() < 1e-9);
        // The share rule: 50 % of 1.6 m² is 0.8 m², just met.
        config.parent.min_gain_m2 = 0.0;
        config.parent.min_gain_share = 0.5;
        assert!(GainEstimate::new(&k, &config).worth_a_scan(&gain));
        config.parent.min_gain_share = 0.51;
        assert!(!GainEstimate::new(&k, &config).worth_a_scan(&gain));
    }
}
