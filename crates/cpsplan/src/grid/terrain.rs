//! Where a robot of one size can drive on one knowledge map, with the connected
//! regions of its drivable cells: two cells are connected by a drivable path iff
//! they share a region, which replaces a travel-distance sweep per robot when only
//! reachability is asked (the AND region's "reachable from the child", section
//! IV-B).
//!
//! The travel sweep ([`super::travel`]) steps diagonally only where both cells beside
//! the step are passable, so its connected regions are exactly the 4-connected
//! regions of the passable cells.

use crate::geom::Cell;
use crate::grid::region::label4;
use crate::grid::travel::DistanceField;
use crate::grid::Traversability;
use crate::grid::{GridGeometry, OccupancyGrid};

/// Label of cells that are not passable.
pub const NO_REGION: u32 = u32::MAX;

/// The drivable cells of a robot and their connected regions.
#[derive(Debug, Clone)]
pub struct Terrain {
    /// Drivable cells of the robot.
    pub trav: Traversability,
    regions: Regions,
}

/// How a [`Terrain`] knows its regions.
#[derive(Debug, Clone)]
enum Regions {
    /// Per cell: the connected region of passable cells it belongs to, or
    /// [`NO_REGION`].
    Labelled(Vec<u32>),
    /// One region (0): the passable cells a travel sweep reached.
    Swept(DistanceField),
}

impl Terrain {
    /// The terrain of a robot of `radius` metres standing at `robot` (whose escape
    /// region counts as passable, see [`Traversability`]).
    pub fn new(knowledge: &OccupancyGrid, radius: f64, robot: Cell) -> Self {
        let trav = Traversability::new(knowledge, radius, robot);
        Self::labelled(trav, knowledge.geometry())
    }

    /// The terrain of robots of `radius` metres with no escape region
    /// ([`Traversability::without_escape`]): every region of the traversable cells
    /// labelled.
    pub fn without_escape(knowledge: &OccupancyGrid, radius: f64) -> Self {
        let trav = Traversability::without_escape(knowledge, radius);
        Self::labelled(trav, knowledge.geometry())
    }

    /// Every region of the passable cells of `trav` labelled.
    fn labelled(trav: Traversability, g: &GridGeometry) -> Self {
        let (region, _) = label4(g.width, g.height, |i| trav.passable[i]);
        Self {
            trav,
            regions: Regions::Labelled(region),
        }
    }

    /// The terrain of `trav` with only the region of a travel sweep over its
    /// passable cells (region 0): no labelling pass when the sweep has already
    /// been run (the parent's planning round runs it). The terrain keeps the
    /// sweep ([`Self::field`]).
    pub fn from_sweep(trav: Traversability, field: DistanceField) -> Self {
        Self {
            trav,
            regions: Regions::Swept(field),
        }
    }

    /// The travel sweep the terrain was made from, if it was
    /// ([`Self::from_sweep`]).
    pub fn field(&self) -> Option<&DistanceField> {
        match &self.regions {
            Regions::Swept(field) => Some(field),
            Regions::Labelled(_) => None,
        }
    }

    /// The region of cell `index`, if it is passable and labelled (for a
    /// terrain made [`from_sweep`](Self::from_sweep): if the sweep reached it).
    #[inline]
    pub fn region_of(&self, index: usize) -> Option<u32> {
        match &self.regions {
            Regions::Labelled(region) => {
                let r = *region.get(index)?;
                (r != NO_REGION).then_some(r)
            }
            Regions::Swept(field) => {
                let on = *self.trav.passable.get(index)? && field.reached(index);
                on.then_some(0)
            }
        }
    }

    /// [`Self::region_of`], with [`NO_REGION`] for none.
    #[inline]
    pub fn region(&self, index: usize) -> u32 {
        self.region_of(index).unwrap_or(NO_REGION)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::travel::{sweep, UNREACHED};
    use crate::grid::{CellState, GridGeometry};
    use crate::Point;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

        /// Same region iff the travel sweep connects the two cells.
        #[test]
        fn regions_are_what_the_sweep_reaches(
            rects in proptest::collection::vec((0usize..50, 0usize..40, 1usize..15, 1usize..15), 0..12),
            a in any::<prop::sample::Index>(),
        ) {
            let g = GridGeometry::new(50, 40, 0.1, Point::default());
            let mut k = OccupancyGrid::filled(g, CellState::Free);
            for (x, y, w, h) in rects {
                k.fill_rect(x, y, (x + w).min(50), (y + h).min(40), CellState::Occupied);
            }
            let t = Terrain::new(&k, 0.15, Cell::new(0, 0));
            let passable: Vec<usize> = (0..g.len()).filter(|&i| t.trav.passable[i]).collect();
            prop_assume!(!passable.is_empty());
            let s = passable[a.index(passable.len())];
            let field = sweep(&g, &t.trav.passable, &[s], UNREACHED);
            let swept = Terrain::from_sweep(t.trav.clone(), field.clone());
            for i in 0..g.len() {
                let same = t.region_of(i).is_some() && t.region_of(i) == t.region_of(s);
                prop_assert_eq!(same, field.reached(i), "cell {}", i);
                prop_assert_eq!(swept.region_of(i).is_some(), field.reached(i) && t.trav.passable[i]);
            }
        }
    }
}
