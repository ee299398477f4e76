//! One CPS cycle (paper Fig. 1) planned on the knowledge map: the children move
//! into the AND region of the parent's current and next position while the parent
//! stands, then the parent moves while they stand (sections IV-B and IV-D).
//!
//! A child already in its AND region stays (section IV-B); the others are placed
//! jointly by Eq. (2) ([`place_children`]); each moving child drives along the
//! Voronoi edges of the known map ([`super::voronoi::voronoi_path`]). When a moving child has no
//! AND region at all, the cycle cannot be planned and the caller retrieves
//! subgoals (section IV-C).

use thiserror::Error;

use super::and_region::{and_region, ChildReach, LinkRange};
use super::children::{place_children, Eq2, Placement, Spot};
use super::cps_maps::CpsMaps;
use crate::geom::Cell;
use crate::world::OccupancyGrid;

/// Parameters of a cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleParams {
    /// Radius of every child, metres.
    pub child_radius: f64,
    /// The instrument's range limits for parent–child links.
    pub link: LinkRange,
    /// Eq. (2) weights and targets.
    pub eq2: Eq2,
}

/// What one child does during a cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleChild {
    /// Where it stands before the cycle.
    pub from: Cell,
    /// Where it stands while the parent moves.
    pub to: Cell,
    /// It was already in its AND region and stays.
    pub stays: bool,
    /// Its path, `from` first (a single cell when it stays).
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

/// Plans the cycle that takes the parent from `parent_from` to `parent_to` with the
/// children now at `children`, including the children's Voronoi paths.
pub fn plan_cycle(
    knowledge: &OccupancyGrid,
    parent_from: Cell,
    parent_to: Cell,
    children: &[Cell],
    params: &CycleParams,
) -> Result<CpsCycle, CycleError> {
    let maps = CpsMaps::new(knowledge, parent_from, params.child_radius, params);
    let reach: Vec<ChildReach> = children.iter().map(|&c| maps.reach(c)).collect();
    let mut cycle = place_cycle(&maps, parent_from, parent_to, children, &reach)?;
    drive_children(&maps, &mut cycle)?;
    Ok(cycle)
}

/// The children's places for the cycle from `parent_from` to `parent_to` (paths
/// not yet planned: each moving child's path is just its two ends); `reach[i]` is
/// child `i`'s [`ChildReach`].
pub fn place_cycle(
    maps: &CpsMaps,
    parent_from: Cell,
    parent_to: Cell,
    children: &[Cell],
    reach: &[ChildReach],
) -> Result<CpsCycle, CycleError> {
    let params = maps.params();
    let g = *maps.knowledge().geometry();
    let mutual = maps.mutual_view(parent_from, parent_to);
    let regions: Vec<_> = reach.iter().map(|r| and_region(&mutual, r)).collect();
    let stays: Vec<bool> = children
        .iter()
        .zip(&regions)
        .map(|(&c, r)| r.contains(g.index(c)))
        .collect();
    if let Some(child) = (0..children.len()).find(|&i| !stays[i] && regions[i].size() == 0) {
        return Err(CycleError::NoAndRegion { child });
    }
    let movers: Vec<usize> = (0..children.len()).filter(|&i| !stays[i]).collect();
    let staying: Vec<Cell> = (0..children.len())
        .filter(|&s| stays[s])
        .map(|s| children[s])
        .collect();
    let sep2 = (2.0 * params.child_radius / g.resolution).powi(2);
    // Clearance (Eq. 2's 1/P) of every cell any moving child may take, at once.
    let mut candidates: Vec<u32> = movers
        .iter()
        .flat_map(|&i| regions[i].cells.iter().copied())
        .collect();
    candidates.sort_unstable();
    candidates.dedup();
    let clearance = maps.clearances(&candidates);
    let clearance_of = |j: u32| {
        let k = candidates.binary_search(&j);
        clearance[k.expect("every region cell is a candidate")]
    };
    let spots: Vec<Vec<Spot>> = movers
        .iter()
        .map(|&i| {
            regions[i]
                .cells
                .iter()
                .map(|&j| (j, g.cell(j as usize)))
                // Keep clear of children that stay.
                .filter(|&(_, c)| {
                    staying.iter().all(|s| {
                        let (dx, dy) = (c.x as f64 - s.x as f64, c.y as f64 - s.y as f64);
                        dx * dx + dy * dy >= sep2
                    })
                })
                .map(|(j, cell)| Spot {
                    cell,
                    clearance: clearance_of(j),
                })
                .collect()
        })
        .collect();
    let placed = place_children(&g, &spots, parent_to, params.child_radius, &params.eq2);
    let mut out: Vec<CycleChild> = children
        .iter()
        .zip(&regions)
        .map(|(&c, r)| CycleChild {
            from: c,
            to: c,
            stays: true,
            path: vec![c],
            placement: None,
            and_region_cells: r.size(),
        })
        .collect();
    for (k, &i) in movers.iter().enumerate() {
        let Some(p) = placed[k] else {
            return Err(CycleError::NoJointPlacement);
        };
        out[i] = CycleChild {
            from: children[i],
            to: p.cell,
            stays: false,
            path: vec![children[i], p.cell],
            placement: Some(p),
            and_region_cells: regions[i].size(),
        };
    }
    Ok(CpsCycle {
        parent_from,
        parent_to,
        children: out,
    })
}

/// Plans every moving child's path along the Voronoi edges of the children's
/// diagram in `maps`.
pub fn drive_children(maps: &CpsMaps, cycle: &mut CpsCycle) -> Result<(), CycleError> {
    for child in cycle.children.iter_mut().filter(|c| !c.stays) {
        child.path = maps
            .child_path(child.from, child.to)
            .ok_or(CycleError::NoJointPlacement)?;
    }
    Ok(())
}

/// Fixtures shared by the tests of the CPS modules.
#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::planning::and_region::certain_view;
    use crate::world::{CellState, GridGeometry};

    /// Cycle parameters with the paper's Eq. (2) targets.
    pub(crate) fn params() -> CycleParams {
        CycleParams {
            child_radius: 0.25,
            link: LinkRange {
                min: 1.3,
                max: 20.0,
            },
            eq2: Eq2 {
                alpha_c: 1.0,
                beta_c: 1.0,
                theta_t: std::f64::consts::FRAC_PI_2,
                d_t: 3.0,
                clearance_cap: 5.0,
            },
        }
    }

    /// An L-shaped corridor, 2 m wide.
    pub(crate) fn l_corridor() -> OccupancyGrid {
        let g = GridGeometry::new(120, 120, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Occupied);
        k.fill_rect(5, 5, 115, 25, CellState::Free);
        k.fill_rect(95, 5, 115, 115, CellState::Free);
        k
    }

    /// A U-shaped corridor 2 m wide: the two ends share no line of sight.
    pub(crate) fn u_corridor() -> OccupancyGrid {
        let g = GridGeometry::new(120, 120, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Occupied);
        k.fill_rect(5, 5, 25, 115, CellState::Free);
        k.fill_rect(5, 95, 115, 115, CellState::Free);
        k.fill_rect(95, 5, 115, 115, CellState::Free);
        k
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
