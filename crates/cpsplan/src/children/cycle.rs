//! One CPS cycle (paper Fig. 1) planned on the knowledge map: the children move
//! into the AND region of the parent's current and next position while the parent
//! stands, then the parent moves while they stand (section IV-B).
//!
//! In: the step's [`StepMaps`], the parent's two positions, the children's cells.
//! Out: where every child stands during the cycle ([`CpsCycle`]), or why no cycle
//! can be planned ([`CycleError`]). A child already in its AND region stays
//! (section IV-B); the others are placed jointly by Eq. (2) ([`place_children`]).
//! When a moving child has no AND region at all, the caller retrieves subgoals
//! (section IV-C). How the children drive to their spots is planned by
//! [`crate::motion`].

use thiserror::Error;

use super::and_region::{and_region, AndRegion, ChildReach};
use super::clearance::clearances;
use super::maps::StepMaps;
use super::placement::{place_children, Placement, Spot};
use super::spacing::Spacing;
use crate::geom::Cell;

/// What one child does during a cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleChild {
    /// Where it stands before the cycle.
    pub from: Cell,
    /// Where it stands while the parent moves.
    pub to: Cell,
    /// It was already in its AND region and stays.
    pub stays: bool,
    /// Its path, `from` first (a single cell when it stays; `from` and `to` until
    /// [`crate::motion`] plans the drive).
    pub path: Vec<Cell>,
    /// Eq. (2) terms of its spot (`None` when it stays).
    pub placement: Option<Placement>,
    /// Size of its AND region in cells.
    pub and_region_cells: usize,
}

/// A planned cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct CpsCycle {
    /// The parent's position during the children's move.
    pub parent_from: Cell,
    /// The parent's position after its move.
    pub parent_to: Cell,
    /// One entry per child, in order.
    pub children: Vec<CycleChild>,
    /// Strategy `min-error`: the share of the cycle's predicted error that the
    /// search's branch and bound left unproven (0: within
    /// [`SEARCH_GAP`](crate::children::SEARCH_GAP) of the optimum over the AND
    /// regions; NaN: three or more movers, coordinate descent).
    pub search_gap: Option<f64>,
}

/// Why a cycle cannot be planned directly.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum CycleError {
    /// A child that must move has no AND region it can reach.
    #[error("child {child} has no reachable AND region between the two parent positions")]
    NoAndRegion {
        /// Index of the child.
        child: usize,
    },
    /// Places exist, but not enough of them for every child at once.
    #[error("the AND region has no room for every child")]
    NoJointPlacement,
}

/// The children's places for the cycle from `parent_from` to `parent_to` (paths
/// not yet planned: each moving child's path is just its two ends); `reach[i]` is
/// child `i`'s [`ChildReach`]. [`frame_cycle`] then [`CycleFrame::place_eq2`].
pub fn place_cycle(
    maps: &StepMaps,
    parent_from: Cell,
    parent_to: Cell,
    children: &[Cell],
    reach: &[ChildReach],
) -> Result<CpsCycle, CycleError> {
    frame_cycle(maps, parent_from, parent_to, children, reach)?.place_eq2(maps)
}

/// A cycle before its spots are chosen (section IV-B): the children's AND
/// regions, which children stay, and the cells each moving child may take.
#[derive(Debug, Clone)]
pub struct CycleFrame {
    /// The parent's position during the children's move.
    pub parent_from: Cell,
    /// The parent's position after its move.
    pub parent_to: Cell,
    /// Where the children stand before the cycle.
    pub children: Vec<Cell>,
    /// Every child's AND region.
    pub regions: Vec<AndRegion>,
    /// The children that move, in order.
    movers: Vec<usize>,
    /// Per mover, the cells of its AND region clear of the children that stay.
    usable: Vec<Vec<u32>>,
    /// Where the children may stand together.
    pub(super) spacing: Spacing,
}

/// The frame of the cycle from `parent_from` to `parent_to`: a child in its AND
/// region stays, unless a child that stays already hides it (or it hides one)
/// from the parent's new position; a child that must move and has no AND region
/// is [`CycleError::NoAndRegion`].
pub fn frame_cycle(
    maps: &StepMaps,
    parent_from: Cell,
    parent_to: Cell,
    children: &[Cell],
    reach: &[ChildReach],
) -> Result<CycleFrame, CycleError> {
    let g = *maps.knowledge().geometry();
    let mutual = maps.mutual_view(parent_from, parent_to);
    let regions: Vec<_> = reach.iter().map(|r| and_region(&mutual, r)).collect();
    let spacing = spacing_of(maps, parent_from, parent_to);
    let mut stays: Vec<bool> = Vec::with_capacity(children.len());
    for (i, (&c, r)) in children.iter().zip(&regions).enumerate() {
        let clear = (0..i)
            .filter(|&k| stays[k])
            .all(|k| spacing.ok(c, children[k]));
        stays.push(r.contains(g.index(c)) && clear);
    }
    if let Some(child) = (0..children.len()).find(|&i| !stays[i] && regions[i].size() == 0) {
        return Err(CycleError::NoAndRegion { child });
    }
    let movers: Vec<usize> = (0..children.len()).filter(|&i| !stays[i]).collect();
    let staying: Vec<Cell> = (0..children.len())
        .filter(|&s| stays[s])
        .map(|s| children[s])
        .collect();
    // Keep clear of children that stay, and off their lines of sight.
    let usable = movers
        .iter()
        .map(|&i| {
            regions[i]
                .cells
                .iter()
                .copied()
                .filter(|&j| {
                    let c = g.cell(j as usize);
                    staying.iter().all(|&s| spacing.ok(c, s))
                })
                .collect()
        })
        .collect();
    Ok(CycleFrame {
        parent_from,
        parent_to,
        children: children.to_vec(),
        regions,
        movers,
        usable,
        spacing,
    })
}

/// Where the children of the cycle from `parent_from` to `parent_to` may stand
/// together, on the step's maps.
pub(super) fn spacing_of(maps: &StepMaps, parent_from: Cell, parent_to: Cell) -> Spacing {
    let g = maps.knowledge().geometry();
    Spacing {
        parents: vec![parent_from, parent_to],
        radius: maps.params().child_radius / g.resolution,
        marker: maps.params().marker_radius / g.resolution,
    }
}

impl CycleFrame {
    /// Whether [`place_eq2`](Self::place_eq2) would place every moving child,
    /// known without Eq. (2) for up to two movers (some spot each, and for two
    /// some pair of spots [`apart`](super::apart): Eq. (2)'s exact search finds a pair exactly
    /// when one exists); `None` for three or more (pairs placed in turn may
    /// leave no room for the last).
    pub fn placeable(&self, maps: &StepMaps) -> Option<bool> {
        let g = maps.knowledge().geometry();
        match self.usable.as_slice() {
            [] => Some(true),
            [a] => Some(!a.is_empty()),
            [a, b] => Some(a.iter().any(|&p| {
                let p = g.cell(p as usize);
                b.iter().any(|&q| self.spacing.ok(p, g.cell(q as usize)))
            })),
            _ => None,
        }
    }

    /// The cycle with the moving children's spots chosen jointly by Eq. (2)
    /// ([`place_children`]); [`CycleError::NoJointPlacement`] when they do not
    /// all fit.
    pub fn place_eq2(&self, maps: &StepMaps) -> Result<CpsCycle, CycleError> {
        let params = maps.params();
        let g = *maps.knowledge().geometry();
        let parents = [self.parent_from, self.parent_to];
        // Clearance (Eq. 2's 1/P) of every cell any moving child may take, at once.
        let mut candidates: Vec<u32> = self
            .movers
            .iter()
            .flat_map(|&i| self.regions[i].cells.iter().copied())
            .collect();
        candidates.sort_unstable();
        candidates.dedup();
        let clearance = clearances(maps.knowledge(), &candidates, params.eq2.clearance_cap);
        let clearance_of = |j: u32| {
            let k = candidates.binary_search(&j);
            clearance[k.expect("every region cell is a candidate")]
        };
        let spots: Vec<Vec<Spot>> = self
            .usable
            .iter()
            .map(|cells| {
                cells
                    .iter()
                    .map(|&j| Spot {
                        cell: g.cell(j as usize),
                        clearance: clearance_of(j),
                    })
                    .collect()
            })
            .collect();
        let placed = place_children(
            &g,
            &spots,
            self.parent_to,
            params.child_radius,
            params.marker_radius,
            &parents,
            &params.eq2,
        );
        let mut out: Vec<CycleChild> = self
            .children
            .iter()
            .zip(&self.regions)
            .map(|(&c, r)| CycleChild::staying(c, r.size()))
            .collect();
        for (k, &i) in self.movers.iter().enumerate() {
            let Some(p) = placed[k] else {
                return Err(CycleError::NoJointPlacement);
            };
            let from = self.children[i];
            out[i] = CycleChild {
                from,
                to: p.cell,
                stays: false,
                path: vec![from, p.cell],
                placement: Some(p),
                and_region_cells: self.regions[i].size(),
            };
        }
        Ok(CpsCycle {
            parent_from: self.parent_from,
            parent_to: self.parent_to,
            children: out,
            search_gap: None,
        })
    }
}

impl CycleChild {
    /// A child that stays at `at` through the cycle; its AND region has `region`
    /// cells.
    pub fn staying(at: Cell, region: usize) -> Self {
        Self {
            from: at,
            to: at,
            stays: true,
            path: vec![at],
            placement: None,
            and_region_cells: region,
        }
    }
}

/// Cycle fixtures shared by the tests of the CPS stages.
#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::children::params::CycleParams;
    use crate::children::placement::Eq2;
    use crate::grid::fixtures::{l_corridor, u_corridor};
    use crate::grid::{CellState, OccupancyGrid};
    use crate::sensing::{certain_view, LinkRule};

    /// Cycle parameters with the paper's Eq. (2) targets.
    pub(crate) fn params() -> CycleParams {
        CycleParams {
            child_radius: 0.25,
            link: LinkRule {
                min: 1.3,
                max: 20.0,
                clearance: 0.05,
            },
            targets: LinkRule {
                min: 1.3,
                max: 3000.0,
                clearance: 0.05,
            },
            eq2: Eq2 {
                alpha_c: 1.0,
                beta_c: 1.0,
                theta_t: std::f64::consts::FRAC_PI_2,
                d_t: 3.0,
                clearance_cap: 5.0,
            },
            marker_radius: 0.1,
            strategy: crate::config::ChildStrategy::Balanced,
            travel_weight: 0.01,
        }
    }

    /// The cycle from `from` to `to` planned on fresh maps of `k`.
    pub(crate) fn plan_cycle(
        k: &OccupancyGrid,
        from: Cell,
        to: Cell,
        children: &[Cell],
        params: &CycleParams,
    ) -> Result<CpsCycle, CycleError> {
        let maps = StepMaps::new(k, from, params.child_radius, params);
        let reach: Vec<ChildReach> = children.iter().map(|&c| maps.reach(c)).collect();
        place_cycle(&maps, from, to, children, &reach)
    }

    #[test]
    fn children_end_where_both_parent_positions_see_them() {
        let k = l_corridor();
        let (from, to) = (Cell::new(20, 15), Cell::new(105, 100));
        let children = [Cell::new(10, 10), Cell::new(10, 20)];
        let cycle = plan_cycle(&k, from, to, &children, &params()).unwrap();
        let link = params().link;
        for c in &cycle.children {
            assert!(!c.stays);
            let sees = certain_view(&k, c.to, link);
            let g = k.geometry();
            assert!(sees[g.index(from)] && sees[g.index(to)], "{:?}", c.to);
            assert_eq!(c.path.first(), Some(&c.from));
            assert_eq!(c.path.last(), Some(&c.to));
        }
        assert_ne!(cycle.children[0].to, cycle.children[1].to);
    }

    #[test]
    fn a_child_already_in_the_region_stays() {
        let k = l_corridor();
        let (from, to) = (Cell::new(20, 15), Cell::new(60, 15));
        // Both parent positions see the whole horizontal arm.
        let children = [Cell::new(40, 10), Cell::new(10, 20)];
        let cycle = plan_cycle(&k, from, to, &children, &params()).unwrap();
        assert!(cycle.children[0].stays);
        assert_eq!(cycle.children[0].to, children[0]);
        assert_eq!(cycle.children[0].path, vec![children[0]]);
    }

    proptest::proptest! {
        /// Whether Eq. (2) places every moving child is known without it for up
        /// to two movers: on rooms cluttered at random, with the parent's two
        /// positions and the children anywhere free, `placeable` says exactly
        /// whether `place_eq2` succeeds.
        #[test]
        fn placeable_is_whether_eq2_places(
            blocks in proptest::collection::vec((0usize..36, 0usize..26, 1usize..8, 1usize..8), 0..5),
            spots in proptest::collection::vec((1usize..39, 1usize..29), 4),
        ) {
            let g = crate::grid::GridGeometry::new(40, 30, 0.1, crate::geom::Point::default());
            let mut k = OccupancyGrid::filled(g, CellState::Occupied);
            k.fill_rect(1, 1, 39, 29, CellState::Free);
            for &(x, y, w, h) in &blocks {
                k.fill_rect(x, y, (x + w).min(39), (y + h).min(29), CellState::Occupied);
            }
            let cells: Vec<Cell> = spots.iter().map(|&(x, y)| Cell::new(x, y)).collect();
            proptest::prop_assume!(cells.iter().all(|&c| k.get(c) == CellState::Free));
            let (from, to, children) = (cells[0], cells[1], &cells[2..]);
            let params = params();
            let maps = StepMaps::new(&k, from, params.child_radius, &params);
            let reach: Vec<ChildReach> = children.iter().map(|&c| maps.reach(c)).collect();
            if let Ok(frame) = frame_cycle(&maps, from, to, children, &reach) {
                let placed = frame.place_eq2(&maps);
                proptest::prop_assert_eq!(frame.placeable(&maps), Some(placed.is_ok()));
            }
        }
    }

    #[test]
    fn no_and_region_asks_for_subgoals() {
        let k = u_corridor();
        let err = plan_cycle(
            &k,
            Cell::new(15, 10),
            Cell::new(105, 10),
            &[Cell::new(15, 20), Cell::new(15, 30)],
            &params(),
        )
        .unwrap_err();
        assert_eq!(err, CycleError::NoAndRegion { child: 0 });
    }
}
