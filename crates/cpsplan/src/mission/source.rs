//! Where an episode's scans and the team's arrivals come from: the ground
//! truth of a simulation ([`Simulated`]), or the scans a real team recorded
//! (a campaign, [`super::campaign`]). The loop of [`super::run_episode`] plans
//! the same way for both.

use super::team::Moved;
use crate::geom::Cell;
use crate::grid::OccupancyGrid;
use crate::sensing::{scan, ScanOutcome};

/// The scans and arrivals of an episode.
pub trait ScanSource {
    /// The ground truth, in a simulation (coverage, the oracle planner).
    fn truth(&self) -> Option<&OccupancyGrid>;

    /// The next scan, from `at`: records every cell it sees in `knowledge`
    /// and calls `on_new(index)` for each that was Unknown before.
    fn scan(
        &mut self,
        knowledge: &mut OccupancyGrid,
        at: Cell,
        range_cells: f64,
        on_new: &mut dyn FnMut(usize),
    ) -> ScanOutcome;

    /// Where the team stands for the next scan after the move `planned`, on
    /// `knowledge` (`None`: no further scan is known yet).
    fn arrive(&mut self, planned: Moved, knowledge: &OccupancyGrid) -> Option<Moved>;

    /// Where the team stands for the next scan although the plan stopped at
    /// `parent` with `children` (`None`: there is no next scan; a
    /// simulation stops where its plan does).
    fn forced(
        &mut self,
        parent: Cell,
        children: &[Cell],
        knowledge: &OccupancyGrid,
    ) -> Option<Moved>;
}

/// A simulation: scans see the ground truth, the team arrives where planned.
#[derive(Debug, Clone, Copy)]
pub struct Simulated<'a> {
    /// The solidified ground truth.
    pub truth: &'a OccupancyGrid,
}

impl ScanSource for Simulated<'_> {
    fn truth(&self) -> Option<&OccupancyGrid> {
        Some(self.truth)
    }

    fn scan(
        &mut self,
        knowledge: &mut OccupancyGrid,
        at: Cell,
        range_cells: f64,
        on_new: &mut dyn FnMut(usize),
    ) -> ScanOutcome {
        scan(self.truth, knowledge, at, range_cells, on_new)
    }

    fn arrive(&mut self, planned: Moved, _: &OccupancyGrid) -> Option<Moved> {
        Some(planned)
    }

    fn forced(&mut self, _: Cell, _: &[Cell], _: &OccupancyGrid) -> Option<Moved> {
        None
    }
}
