//! Shortest travel distances on the grid with integer 8-connected step costs
//! (straight 29, diagonal 41; 41/29 ≈ √2 to 0.03 %). Diagonal steps never cut a
//! blocked corner. One sweep gives the travel distance `L` of Eq. (1) to every
//! candidate and the set of reachable cells.
//!
//! The sweep is the dearest step of a planning round (it covers every drivable
//! cell), so it is written for speed: canonical Dijkstra (module `canonical`) writes
//! the costs along straight and diagonal rays and queues only the jump points
//! where a ray passes the end of a wall, and its working buffers are kept per
//! thread between sweeps (the cost buffer of a dropped field too, for the next
//! sweep on any thread). Its costs are the exact shortest-path costs, so the
//! field equals a plain Dijkstra's. `reached_within` is Dial's bucket-queue
//! Dijkstra that touches only what it reaches, for short sweeps.

mod canonical;
mod reach;

pub(crate) use reach::{reached_within, release_buffers};

use crate::geom::Cell;
use crate::grid::GridGeometry;

/// Cost of a straight step.
pub const STRAIGHT: u32 = 29;
/// Cost of a diagonal step.
pub const DIAGONAL: u32 = 41;
/// Distance of a cell that no source reaches.
pub const UNREACHED: u32 = u32::MAX;

/// Travel distances from a set of source cells.
#[derive(Debug, Clone)]
pub struct DistanceField {
    /// Per cell: the cost of the cheapest path from a source, or [`UNREACHED`].
    pub cost: Vec<u32>,
    resolution: f64,
}

impl DistanceField {
    /// Whether a cell was reached.
    #[inline]
    pub fn reached(&self, index: usize) -> bool {
        self.cost[index] != UNREACHED
    }

    /// Travel distance in metres to a cell, or `None` if it was not reached.
    pub fn metres(&self, index: usize) -> Option<f64> {
        self.reached(index)
            .then(|| self.cost[index] as f64 / STRAIGHT as f64 * self.resolution)
    }

    /// Converts a distance in metres into the field's integer cost units.
    pub fn cost_of(metres: f64, resolution: f64) -> u32 {
        (metres / resolution * STRAIGHT as f64)
            .round()
            .clamp(0.0, (UNREACHED - 1) as f64) as u32
    }
}

/// Neighbour offsets: (dx, dy, cost); the first four are straight.
const STEPS: [(i64, i64, u32); 8] = [
    (1, 0, STRAIGHT),
    (-1, 0, STRAIGHT),
    (0, 1, STRAIGHT),
    (0, -1, STRAIGHT),
    (1, 1, DIAGONAL),
    (-1, 1, DIAGONAL),
    (1, -1, DIAGONAL),
    (-1, -1, DIAGONAL),
];

/// The largest grid (cells) whose sweep buffers a thread keeps for the next sweep.
const KEEP_CELLS: usize = 1 << 24;

thread_local! {
    static SCRATCH: std::cell::RefCell<canonical::Scratch> = std::cell::RefCell::default();
}

/// A dropped field's cost buffer, for the next sweep (on any thread: a field
/// is often dropped on another thread than the one that swept it): a fresh
/// buffer of a large grid costs a page fault per 4 KiB.
static SPARE_COST: std::sync::Mutex<Vec<u32>> = std::sync::Mutex::new(Vec::new());

impl Drop for DistanceField {
    fn drop(&mut self) {
        let cost = std::mem::take(&mut self.cost);
        if cost.capacity() > 0 && cost.capacity() <= KEEP_CELLS {
            if let Ok(mut spare) = SPARE_COST.lock() {
                if spare.capacity() < cost.capacity() {
                    *spare = cost;
                }
            }
        }
    }
}

/// `n` cells of [`UNREACHED`], in the spare buffer if there is one.
fn unreached_costs(n: usize) -> Vec<u32> {
    let mut cost = SPARE_COST
        .lock()
        .map(|mut s| std::mem::take(&mut *s))
        .unwrap_or_default();
    cost.clear();
    cost.resize(n, UNREACHED);
    cost
}

/// Dijkstra from `sources` over cells with `passable[i]`, expanding no cell whose
/// cost exceeds `max_cost`. Sources need not be passable themselves.
///
/// Canonical Dijkstra. Costs are exact shortest-path costs, so the field does not
/// depend on the order in which equal costs are settled.
pub fn sweep(
    geometry: &GridGeometry,
    passable: &[bool],
    sources: &[usize],
    max_cost: u32,
) -> DistanceField {
    sweep_cells(geometry, passable, |p| p, sources, max_cost)
}

/// [`sweep`] over the cells `i` with `passable(cells[i])`.
pub(crate) fn sweep_cells<T: Copy>(
    geometry: &GridGeometry,
    cells: &[T],
    passable: impl Fn(T) -> bool,
    sources: &[usize],
    max_cost: u32,
) -> DistanceField {
    let mut scratch = SCRATCH.with(|s| std::mem::take(&mut *s.borrow_mut()));
    let cost = canonical::canonical(geometry, cells, passable, sources, max_cost, &mut scratch);
    if scratch.capacity() <= KEEP_CELLS {
        SCRATCH.with(|s| *s.borrow_mut() = scratch);
    }
    DistanceField {
        cost,
        resolution: geometry.resolution,
    }
}

/// The cells of a cheapest path from a source of `field` to `target`, source first,
/// found by descending the field; `None` if `target` was not reached.
pub fn descend(
    geometry: &GridGeometry,
    field: &DistanceField,
    passable: &[bool],
    target: Cell,
) -> Option<Vec<Cell>> {
    let (w, h) = (geometry.width as i64, geometry.height as i64);
    let mut i = geometry.index(target);
    if !field.reached(i) {
        return None;
    }
    let mut path = vec![target];
    while field.cost[i] != 0 {
        let (x, y) = ((i as i64) % w, (i as i64) / w);
        let mut next = None;
        for (k, &(dx, dy, step)) in STEPS.iter().enumerate() {
            let (nx, ny) = (x + dx, y + dy);
            if nx < 0 || ny < 0 || nx >= w || ny >= h {
                continue;
            }
            let j = (ny * w + nx) as usize;
            if !field.reached(j) || field.cost[j] + step != field.cost[i] {
                continue;
            }
            if k >= 4 {
                let a = (y * w + nx) as usize;
                let b = (ny * w + x) as usize;
                if !passable[a] || !passable[b] {
                    continue;
                }
            }
            next = Some(j);
            break;
        }
        i = next?;
        path.push(geometry.cell(i));
    }
    path.reverse();
    Some(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;

    #[test]
    fn open_grid_distances_are_octile() {
        let g = GridGeometry::new(20, 20, 0.1, Point::default());
        let passable = vec![true; g.len()];
        let f = sweep(&g, &passable, &[g.index(Cell::new(0, 0))], UNREACHED);
        assert_eq!(f.cost[g.index(Cell::new(5, 0))], 5 * STRAIGHT);
        assert_eq!(f.cost[g.index(Cell::new(5, 5))], 5 * DIAGONAL);
        assert_eq!(
            f.cost[g.index(Cell::new(7, 3))],
            3 * DIAGONAL + 4 * STRAIGHT
        );
        let m = f.metres(g.index(Cell::new(10, 0))).unwrap();
        assert!((m - 1.0).abs() < 1e-9);
    }

    #[test]
    fn walls_detour_and_corners_are_not_cut() {
        let g = GridGeometry::new(3, 3, 1.0, Point::default());
        // Blocks (1,0) and (0,1): (1,1) is reachable from (0,0) only by cutting a corner.
        let mut passable = vec![true; 9];
        passable[g.index(Cell::new(1, 0))] = false;
        passable[g.index(Cell::new(0, 1))] = false;
        let f = sweep(&g, &passable, &[0], UNREACHED);
        assert!(!f.reached(g.index(Cell::new(1, 1))));
    }

    #[test]
    fn descend_gives_a_connected_path_of_the_field_cost() {
        let g = GridGeometry::new(30, 30, 0.1, Point::default());
        let mut passable = vec![true; g.len()];
        for y in 0..25 {
            passable[g.index(Cell::new(15, y))] = false;
        }
        let src = g.index(Cell::new(2, 2));
        let f = sweep(&g, &passable, &[src], UNREACHED);
        let p = descend(&g, &f, &passable, Cell::new(28, 2)).unwrap();
        assert_eq!(p[0], Cell::new(2, 2));
        assert_eq!(*p.last().unwrap(), Cell::new(28, 2));
        let mut total = 0;
        for w2 in p.windows(2) {
            let dx = w2[0].x.abs_diff(w2[1].x);
            let dy = w2[0].y.abs_diff(w2[1].y);
            assert!(dx <= 1 && dy <= 1 && dx + dy > 0);
            assert!(passable[g.index(w2[1])]);
            total += if dx + dy == 2 { DIAGONAL } else { STRAIGHT };
        }
        assert_eq!(total, f.cost[g.index(Cell::new(28, 2))]);
    }

    #[test]
    fn max_cost_limits_the_sweep() {
        let g = GridGeometry::new(50, 1, 1.0, Point::default());
        let f = sweep(&g, &[true; 50], &[0], 10 * STRAIGHT);
        assert!(f.reached(10));
        assert!(!f.reached(11));
    }

    /// Textbook Dijkstra with a binary heap and bounds checks, for comparison.
    fn reference(
        g: &GridGeometry,
        passable: &[bool],
        sources: &[usize],
        max_cost: u32,
    ) -> Vec<u32> {
        use std::cmp::Reverse;
        use std::collections::BinaryHeap;
        let (w, h) = (g.width as i64, g.height as i64);
        let mut cost = vec![UNREACHED; g.len()];
        let mut heap = BinaryHeap::new();
        for &s in sources {
            cost[s] = 0;
            heap.push(Reverse((0u32, s)));
        }
        while let Some(Reverse((c, i))) = heap.pop() {
            if c != cost[i] {
                continue;
            }
            let (x, y) = ((i as i64) % w, (i as i64) / w);
            for (k, &(dx, dy, step)) in STEPS.iter().enumerate() {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w || ny >= h {
                    continue;
                }
                let j = (ny * w + nx) as usize;
                let corners =
                    k < 4 || (passable[(y * w + nx) as usize] && passable[(ny * w + x) as usize]);
                let nc = c + step;
                if passable[j] && corners && nc <= max_cost && nc < cost[j] {
                    cost[j] = nc;
                    heap.push(Reverse((nc, j)));
                }
            }
        }
        cost
    }

    /// Every map of 4 × 4 and 5 × 3 cells from every source: the corner cases of
    /// jump points (walls ending beside a ray, rays stopped by cheaper costs) all
    /// occur on maps this small.
    #[test]
    fn sweep_matches_textbook_dijkstra_on_every_small_map() {
        for (w, h) in [(4usize, 4usize), (5, 3)] {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            let n = w * h;
            for map in 0u32..1 << n {
                let passable: Vec<bool> = (0..n).map(|i| map >> i & 1 == 1).collect();
                for s in 0..n {
                    let f = sweep(&g, &passable, &[s], UNREACHED);
                    assert_eq!(
                        f.cost,
                        reference(&g, &passable, &[s], UNREACHED),
                        "{w} x {h} map {map:b}, source {s}"
                    );
                }
            }
        }
    }

    proptest::proptest! {
        #[test]
        fn sweep_matches_textbook_dijkstra(
            w in 1usize..30,
            h in 1usize..30,
            bits in proptest::collection::vec(0u8..8, 900),
            walls in 1u8..8,
            sources in proptest::collection::vec(0usize..900, 1..4),
            max_cost in proptest::sample::select(vec![0u32, 29, 100, 500, UNREACHED]),
        ) {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            // From one wall cell in eight (open rooms, where rays run far) to seven
            // in eight (mazes of jump points).
            let passable: Vec<bool> = (0..g.len()).map(|i| bits[i] >= walls).collect();
            let sources: Vec<usize> = sources.iter().map(|&s| s % g.len()).collect();
            let f = sweep(&g, &passable, &sources, max_cost);
            proptest::prop_assert_eq!(&f.cost, &reference(&g, &passable, &sources, max_cost));
        }

        /// The sweep that touches only what it reaches finds exactly the cells the
        /// whole-grid sweep reaches, also when run again on another grid.
        #[test]
        fn reached_within_is_the_reached_set(
            w in 1usize..30,
            h in 1usize..30,
            bits in proptest::collection::vec(0u8..4, 900),
            sources in proptest::collection::vec(0usize..900, 1..6),
            max_cost in proptest::sample::select(vec![0u32, 29, 41, 100, 500, UNREACHED]),
        ) {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            let passable: Vec<bool> = (0..g.len()).map(|i| bits[i] != 0).collect();
            let sources: Vec<usize> = sources.iter().map(|&s| s % g.len()).collect();
            let f = sweep(&g, &passable, &sources, max_cost);
            let want: Vec<usize> = (0..g.len()).filter(|&i| f.reached(i)).collect();
            for _ in 0..2 {
                let got = reached_within(&g, &passable, |p| p, &sources, max_cost);
                proptest::prop_assert_eq!(&got, &want);
            }
        }
    }
}
