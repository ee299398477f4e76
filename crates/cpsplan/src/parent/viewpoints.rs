//! Viewpoints that look through openings into unknown space (beyond the paper;
//! after the viewpoints of FUEL, Zhou et al., RA-L 2021): for every group of the
//! significant border (8-connected), positions on rings around the group's
//! centre, kept where the parent can stand and reach, scored by how many of the
//! group's border cells they see; the best of each group becomes a candidate
//! beside the band's k-means centroids (`parent.viewpoints`).
//!
//! The band's centroids stand within `band_width` of the border and, in a
//! cluster of 24 m² of band, often beside a door rather than in front of it: a
//! room is then scanned once from outside and again from inside. A viewpoint is
//! chosen for what it sees of the opening, from up to [`RADII_M`]'s largest
//! radius away.
//!
//! In an episode the groups' looks are kept across scans
//! ([`super::Frontier::viewpoints`]): what a ring position's sight lines show
//! depends only on the known walls within the group's bounding box grown by
//! the largest ring, so a group that no scan changed there keeps its counts,
//! and only whether a position is valid and its travel (the tie-break) are
//! asked again. Counts cut short (a position that could no longer reach the
//! best's count) are kept as bounds. The answers are those of a fresh search.
//!
//! In: the knowledge map, the significant border, which cells are valid
//! positions. Out: per group, the best viewpoint's cell and the border cells it
//! sees.

use std::collections::HashMap;
use std::sync::Mutex;

use rayon::prelude::*;

use super::border::flood_group;
use crate::geom::Cell;
use crate::grid::line::segment_clear;
use crate::grid::window::Window;
use crate::grid::{CellState, OccupancyGrid};

/// Radii of the rings around a group's centre, metres.
pub const RADII_M: [f64; 4] = [1.0, 2.5, 5.0, 8.0];

/// Positions per ring.
pub const ANGLES: usize = 16;

/// At most this many of a group's border cells (evenly spaced) are tested for
/// sight.
pub const SAMPLED_BORDER: usize = 48;

/// Groups smaller than this many border cells get no viewpoint.
pub const MIN_GROUP: usize = 5;

/// One group's best viewpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Viewpoint {
    /// Where the parent would stand.
    pub cell: Cell,
    /// How many of the group's tested border cells it sees.
    pub sees: usize,
    /// How many were tested.
    pub tested: usize,
}

/// The best viewpoint of every group of `significant` (border cell indices,
/// sorted) on `knowledge`, among positions for which `valid(index)` holds
/// (drivable and reachable), within `range_cells` of the border cells they see;
/// `cost(index)` orders equals (the nearer first).
pub fn viewpoints(
    knowledge: &OccupancyGrid,
    significant: &[usize],
    range_cells: f64,
    valid: impl Fn(usize) -> bool + Sync,
    cost: impl Fn(usize) -> f64 + Sync,
) -> Vec<Viewpoint> {
    viewpoints_kept(
        knowledge,
        significant,
        |_| true,
        range_cells,
        valid,
        cost,
        None,
    )
}

/// [`viewpoints`], with what earlier calls found out about each group's ring
/// positions taken from and given back to `kept` (the same answers).
/// `maybe_significant(index)` is a quick test that may say a cell is
/// significant when it is not, never the other way round (it spares the search
/// of the list).
pub(super) fn viewpoints_kept(
    knowledge: &OccupancyGrid,
    significant: &[usize],
    maybe_significant: impl Fn(usize) -> bool,
    range_cells: f64,
    valid: impl Fn(usize) -> bool + Sync,
    cost: impl Fn(usize) -> f64 + Sync,
    kept: Option<&KeptLooks>,
) -> Vec<Viewpoint> {
    let g = *knowledge.geometry();
    // Taken, per place in `significant`.
    let mut taken = vec![false; significant.len()];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut group = Vec::new();
    for (at, &start) in significant.iter().enumerate() {
        if std::mem::replace(&mut taken[at], true) {
            continue;
        }
        flood_group(&g, start, &mut group, |j| {
            maybe_significant(j)
                && match significant.binary_search(&j) {
                    Ok(p) => !std::mem::replace(&mut taken[p], true),
                    Err(_) => false,
                }
        });
        if group.len() >= MIN_GROUP {
            groups.push(group.clone());
        }
    }
    let mut store = kept.map(KeptLooks::take).unwrap_or_default();
    let mut looks: Vec<(Vec<usize>, GroupLook)> = groups
        .into_iter()
        .map(|group| {
            let look = match store.remove(&group) {
                Some(look) if look.range_cells.to_bits() == range_cells.to_bits() => look,
                _ => GroupLook::new(knowledge, &group, range_cells),
            };
            (group, look)
        })
        .collect();
    // Each group's search is independent: in parallel, in the groups' order.
    let found = looks
        .par_iter_mut()
        .filter_map(|(_, look)| look.best(knowledge, &valid, &cost))
        .collect();
    if let Some(k) = kept {
        k.put(looks);
    }
    found
}

/// What is known of a ring position's sight of its group.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Known {
    /// Not counted yet.
    Untested,
    /// It sees this many of the tested border cells.
    Exact(usize),
    /// It sees fewer than this many (its count was cut short there).
    Below(usize),
}

/// One border group's ring positions and what their sight lines showed: all of
/// it depends only on the knowledge map within [`GroupLook::window`], so it
/// holds until a scan changes something there. Kept under the group's border
/// cells, in flood order.
#[derive(Debug, Clone)]
pub(super) struct GroupLook {
    /// The evenly spaced border cells whose sight is tested.
    tested: Vec<Cell>,
    /// The tested cells' centre, grid units.
    centre: (f64, f64),
    /// The group's outward normal (toward the Unknown cells beside it) and its
    /// length.
    normal: (f64, f64, f64),
    /// The ring positions in order (radius, then angle): the cell and the exact
    /// point, `None` off the grid.
    positions: Vec<Option<(Cell, f64, f64)>>,
    /// What each position's count showed so far.
    known: Vec<Known>,
    /// The cells the look depends on: the group's bounding box grown by the
    /// largest ring and a cell.
    window: Window,
    /// The range the counts were made for, cells.
    range_cells: f64,
}

impl GroupLook {
    /// The look of one border group (cell indices) with nothing counted yet.
    fn new(knowledge: &OccupancyGrid, cells: &[usize], range_cells: f64) -> Self {
        let g = *knowledge.geometry();
        let k = knowledge.cells();
        let step = cells.len().div_ceil(SAMPLED_BORDER).max(1);
        let tested: Vec<Cell> = cells.iter().step_by(step).map(|&i| g.cell(i)).collect();
        let (cx, cy) = tested
            .iter()
            .fold((0.0, 0.0), |(x, y), c| (x + c.x as f64, y + c.y as f64));
        let (cx, cy) = (cx / tested.len() as f64, cy / tested.len() as f64);
        let (mut nx, mut ny) = (0.0f64, 0.0f64);
        for &i in cells {
            let c = g.cell(i);
            for (dx, dy) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
                let beside = g.checked_cell(c.x as i64 + dx, c.y as i64 + dy);
                if beside.is_some_and(|n| k[g.index(n)] == CellState::Unknown) {
                    nx += dx as f64;
                    ny += dy as f64;
                }
            }
        }
        let mut positions = Vec::with_capacity(RADII_M.len() * ANGLES);
        for r in RADII_M {
            let rc = r / g.resolution;
            for a in 0..ANGLES {
                let t = a as f64 * std::f64::consts::TAU / ANGLES as f64;
                let (x, y) = (cx + rc * t.cos(), cy + rc * t.sin());
                let on = x >= 0.0 && y >= 0.0 && x < g.width as f64 && y < g.height as f64;
                positions.push(on.then(|| (Cell::new(x as usize, y as usize), x, y)));
            }
        }
        let reach = (RADII_M[RADII_M.len() - 1] / g.resolution).ceil() as usize + 1;
        let window = Window::bounding(&g, cells)
            .expect("a group has cells")
            .grow(reach, &g);
        Self {
            known: vec![Known::Untested; positions.len()],
            tested,
            centre: (cx, cy),
            normal: (nx, ny, nx.hypot(ny)),
            positions,
            window,
            range_cells,
        }
    }

    /// The best viewpoint of the group, if any position sees any of it,
    /// counting only the sight lines no earlier count has settled.
    fn best(
        &mut self,
        knowledge: &OccupancyGrid,
        valid: &impl Fn(usize) -> bool,
        cost: &impl Fn(usize) -> f64,
    ) -> Option<Viewpoint> {
        let g = *knowledge.geometry();
        let k = knowledge.cells();
        let r2 = self.range_cells * self.range_cells;
        let (cx, cy) = self.centre;
        let (nx, ny, norm) = self.normal;
        let tested = &self.tested;
        // (cells seen, facing in tenths, cost, cell): the most seen, then the
        // squarest look through the group (toward its normal), then the nearest;
        // equals keep the smaller ring.
        let mut best: Option<(usize, i64, f64, Cell)> = None;
        for (position, known) in self.positions.iter().zip(self.known.iter_mut()) {
            let Some((cell, x, y)) = *position else {
                continue;
            };
            let i = g.index(cell);
            if !valid(i) {
                continue;
            }
            // A position that cannot reach the best's count loses whatever the
            // rest of its sight lines give: it is counted only until then.
            let need = best.map_or(1, |b| b.0);
            let sees = match *known {
                Known::Exact(sees) => sees,
                Known::Below(below) if below <= need => continue,
                _ => {
                    let mut sees = 0;
                    let mut cut = false;
                    for (n, b) in tested.iter().enumerate() {
                        if sees + (tested.len() - n) < need {
                            cut = true;
                            break;
                        }
                        let (dx, dy) = (b.x as f64 - cell.x as f64, b.y as f64 - cell.y as f64);
                        if dx * dx + dy * dy <= r2
                            && segment_clear(&g, cell, *b, |j| k[j] != CellState::Occupied)
                        {
                            sees += 1;
                        }
                    }
                    *known = if cut {
                        Known::Below(need)
                    } else {
                        Known::Exact(sees)
                    };
                    sees
                }
            };
            if sees < need {
                continue;
            }
            let (lx, ly) = (cx - x, cy - y);
            let facing = if norm > 0.0 {
                ((lx * nx + ly * ny) / (lx.hypot(ly).max(1e-9) * norm) * 10.0).round() as i64
            } else {
                0
            };
            let better = match best {
                None => sees > 0,
                Some((s, f, c, _)) => {
                    (sees, facing) > (s, f) || ((sees, facing) == (s, f) && cost(i) < c)
                }
            };
            if better {
                best = Some((sees, facing, cost(i), cell));
            }
        }
        best.map(|(sees, _, _, cell)| Viewpoint {
            cell,
            sees,
            tested: tested.len(),
        })
    }
}

/// The border groups' looks kept across scans (FUEL's incremental frontier
/// structure, in small): a planning round takes them, the groups it finds
/// unchanged keep what their sight lines showed, and [`Self::forget`] drops
/// the looks a scan may have changed.
#[derive(Debug, Default)]
pub(super) struct KeptLooks {
    looks: Mutex<HashMap<Vec<usize>, GroupLook>>,
}

impl Clone for KeptLooks {
    /// A copy starts with nothing kept (the answers stay the same).
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl KeptLooks {
    /// Takes every kept look out.
    fn take(&self) -> HashMap<Vec<usize>, GroupLook> {
        self.looks
            .lock()
            .map(|mut l| std::mem::take(&mut *l))
            .unwrap_or_default()
    }

    /// Keeps `looks` (the current groups', under their cells) in place of
    /// whatever was kept.
    fn put(&self, looks: Vec<(Vec<usize>, GroupLook)>) {
        if let Ok(mut kept) = self.looks.lock() {
            *kept = looks.into_iter().collect();
        }
    }

    /// Drops the looks that depend on a cell of `changed` (the bounding box of
    /// the cells a scan changed).
    pub(super) fn forget(&mut self, changed: &Window) {
        if let Ok(looks) = self.looks.get_mut() {
            looks.retain(|_, l| !l.window.meets(changed));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::grid::GridGeometry;

    /// A known corridor (free) with a closed room behind a door in its wall: the
    /// room unknown, the door's cells the border.
    #[test]
    fn the_viewpoint_of_a_door_looks_through_it() {
        let g = GridGeometry::new(120, 100, 0.1, Point::default());
        let mut k = OccupancyGrid::filled(g, CellState::Unknown);
        // Corridor y 10..30, walls at y 9 and y 30 (with a door at x 55..65).
        k.fill_rect(0, 10, 120, 30, CellState::Free);
        k.fill_rect(0, 9, 120, 10, CellState::Occupied);
        k.fill_rect(0, 30, 120, 31, CellState::Occupied);
        k.fill_rect(55, 30, 65, 31, CellState::Free);
        let border: Vec<usize> = (55..65).map(|x| g.index(Cell::new(x, 30))).collect();
        let valid = |i: usize| k.cells()[i] == CellState::Free && g.cell(i).y < 30;
        let vps = viewpoints(&k, &border, 200.0, valid, |_| 0.0);
        assert_eq!(vps.len(), 1);
        let v = vps[0];
        // It sees the whole door, from in front of it (not beside it).
        assert_eq!(v.sees, v.tested);
        assert!((54..=66).contains(&v.cell.x), "{v:?}");
    }

    proptest::proptest! {
        /// On random partial maps (known free rooms in unknown space, with
        /// pillars): every viewpoint stands on a valid cell, sees at least one
        /// of its group's tested border cells and no more than were tested, and
        /// and tests at most `SAMPLED_BORDER` of them.
        #[test]
        fn viewpoints_stand_on_valid_cells_and_see_their_group(
            rooms in proptest::collection::vec((2usize..50, 2usize..40, 5usize..25, 5usize..20), 1..4),
            pillars in proptest::collection::vec((0usize..80, 0usize..60), 0..12),
        ) {
            let g = GridGeometry::new(80, 60, 0.1, Point::default());
            let mut k = OccupancyGrid::filled(g, CellState::Unknown);
            for &(x, y, w, h) in &rooms {
                k.fill_rect(x, y, (x + w).min(79), (y + h).min(59), CellState::Free);
            }
            for &(x, y) in &pillars {
                k.fill_rect(x, y, (x + 2).min(80), (y + 2).min(60), CellState::Occupied);
            }
            let border = super::super::border::border_cells(&k);
            let valid = |i: usize| k.cells()[i] == CellState::Free;
            let vps = viewpoints(&k, &border, 200.0, valid, |_| 0.0);
            for v in &vps {
                proptest::prop_assert!(valid(g.index(v.cell)), "{v:?}");
                proptest::prop_assert!(v.sees >= 1 && v.sees <= v.tested, "{v:?}");
                proptest::prop_assert!(v.tested <= SAMPLED_BORDER, "{v:?}");
            }
        }
    }
}
