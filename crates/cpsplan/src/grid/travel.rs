//! Shortest travel distances on the grid: Dial's bucket-queue Dijkstra with
//! integer 8-connected step costs (straight 29, diagonal 41; 41/29 ≈ √2 to 0.03 %).
//! Diagonal steps never cut a blocked corner. One sweep gives the travel distance
//! `L` of Eq. (1) to every candidate and the set of reachable cells.
//!
//! The sweep is the dearest step of a planning round (it covers every drivable
//! cell), so it is written for speed: impassable cells carry the cost 0 while it
//! runs (no step improves on them, so entering a cell needs no passability test),
//! each cell's flags say whether all eight neighbours exist (no bounds checks off
//! the grid's border), and the working buffers are kept per thread between sweeps.
//! The costs are exact shortest-path costs, so none of this changes the field.

use std::sync::Mutex;

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

/// Buckets of Dial's queue: one more than the largest step, so that every pending
/// cost lies within one turn of the ring.
const RING: usize = DIAGONAL as usize + 1;

/// The cost impassable cells hold while a sweep runs: no step improves on it, so
/// entering a cell needs no separate passability test.
const BLOCKED: u32 = 0;

/// Cell flag: the cell may be entered.
const OPEN: u8 = 1;
/// Cell flag: the cell is not on the grid's border, so all eight neighbours exist.
const INTERIOR: u8 = 2;

/// Working buffers of a sweep, kept per thread so that repeated sweeps reuse their
/// memory instead of faulting in fresh pages (up to [`KEEP_CELLS`] cells).
#[derive(Default)]
struct Scratch {
    flags: Vec<u8>,
    buckets: Vec<Vec<u32>>,
}

/// The largest grid (cells) whose sweep buffers a thread keeps for the next sweep.
const KEEP_CELLS: usize = 1 << 24;

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::default();
}

/// Dijkstra from `sources` over cells with `passable[i]`, expanding no cell whose
/// cost exceeds `max_cost`. Sources need not be passable themselves.
///
/// Dial's bucket queue. Costs are exact shortest-path costs, so the field does not
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
    let cost = dial(geometry, cells, passable, sources, max_cost, &mut scratch);
    if scratch.flags.capacity() <= KEEP_CELLS {
        SCRATCH.with(|s| *s.borrow_mut() = scratch);
    }
    DistanceField {
        cost,
        resolution: geometry.resolution,
    }
}

/// The costs of [`sweep_cells`].
fn dial<T: Copy>(
    geometry: &GridGeometry,
    cells: &[T],
    passable: impl Fn(T) -> bool,
    sources: &[usize],
    max_cost: u32,
    scratch: &mut Scratch,
) -> Vec<u32> {
    let (w, h) = (geometry.width, geometry.height);
    let n = w * h;
    let cells = &cells[..n];
    if n == 0 {
        return Vec::new();
    }
    // Flags, and costs with impassable cells at BLOCKED.
    let flags = &mut scratch.flags;
    flags.clear();
    flags.extend(cells.iter().map(|&c| {
        if passable(c) {
            OPEN | INTERIOR
        } else {
            INTERIOR
        }
    }));
    let mut cost: Vec<u32> = flags
        .iter()
        .map(|&f| if f & OPEN != 0 { UNREACHED } else { BLOCKED })
        .collect();
    let last = n - w;
    for f in flags[..w].iter_mut() {
        *f &= !INTERIOR;
    }
    for f in flags[last..].iter_mut() {
        *f &= !INTERIOR;
    }
    for row in flags.chunks_exact_mut(w) {
        row[0] &= !INTERIOR;
        row[w - 1] &= !INTERIOR;
    }
    let flags = &scratch.flags;
    let buckets = &mut scratch.buckets;
    buckets.resize_with(RING, Vec::new);
    for b in buckets.iter_mut() {
        b.clear();
    }
    // Sources, each once.
    buckets[0].extend(sources.iter().map(|&i| i as u32));
    buckets[0].sort_unstable();
    buckets[0].dedup();
    for &i in &buckets[0] {
        cost[i as usize] = 0;
    }
    let mut pending = buckets[0].len();
    let mut current: u32 = 0;
    let mut slot = 0usize;
    let wrap = |s: usize| if s >= RING { s - RING } else { s };
    while pending > 0 {
        // Steps cost at least STRAIGHT > 0, so the bucket being drained and the two
        // it feeds are distinct.
        let straight_slot = wrap(slot + STRAIGHT as usize);
        let diagonal_slot = wrap(slot + DIAGONAL as usize);
        let mut bucket = std::mem::take(&mut buckets[slot]);
        let mut to_straight = std::mem::take(&mut buckets[straight_slot]);
        let mut to_diagonal = std::mem::take(&mut buckets[diagonal_slot]);
        pending -= bucket.len();
        let before = to_straight.len() + to_diagonal.len();
        let straight_cost = current.saturating_add(STRAIGHT);
        let diagonal_cost = current.saturating_add(DIAGONAL);
        let straight_ok = straight_cost <= max_cost && straight_cost != UNREACHED;
        let diagonal_ok = diagonal_cost <= max_cost && diagonal_cost != UNREACHED;
        for &p in &bucket {
            let i = p as usize;
            if cost[i] != current || !straight_ok {
                continue; // stale entry, or nothing within max_cost
            }
            if flags[i] & INTERIOR == 0 {
                relax_border(
                    geometry,
                    flags,
                    &mut cost,
                    i,
                    (straight_cost, &mut to_straight),
                    (diagonal_cost, diagonal_ok, &mut to_diagonal),
                );
                continue;
            }
            let mut relax = |j: usize, c: u32, queue: &mut Vec<u32>| {
                if c < cost[j] {
                    cost[j] = c;
                    queue.push(j as u32);
                }
            };
            relax(i + 1, straight_cost, &mut to_straight);
            relax(i - 1, straight_cost, &mut to_straight);
            relax(i + w, straight_cost, &mut to_straight);
            relax(i - w, straight_cost, &mut to_straight);
            if diagonal_ok {
                // A diagonal step never cuts a blocked corner.
                let open = |j: usize| flags[j] & OPEN != 0;
                let (east, west) = (open(i + 1), open(i - 1));
                let (north, south) = (open(i + w), open(i - w));
                if east & north {
                    relax(i + w + 1, diagonal_cost, &mut to_diagonal);
                }
                if west & north {
                    relax(i + w - 1, diagonal_cost, &mut to_diagonal);
                }
                if east & south {
                    relax(i - w + 1, diagonal_cost, &mut to_diagonal);
                }
                if west & south {
                    relax(i - w - 1, diagonal_cost, &mut to_diagonal);
                }
            }
        }
        pending += to_straight.len() + to_diagonal.len() - before;
        bucket.clear();
        buckets[slot] = bucket;
        buckets[straight_slot] = to_straight;
        buckets[diagonal_slot] = to_diagonal;
        slot = wrap(slot + 1);
        current += 1;
    }
    // Impassable cells back to UNREACHED, sources to 0.
    for (c, &f) in cost.iter_mut().zip(flags) {
        *c = if f & OPEN != 0 { *c } else { UNREACHED };
    }
    for &s in sources {
        cost[s] = 0;
    }
    cost
}

/// The costs of a sweep that touches only the cells it reaches, and the cells it
/// touched (their costs are set back to [`UNREACHED`] after each sweep).
#[derive(Default)]
struct Touched {
    cost: Vec<u32>,
    touched: Vec<u32>,
    buckets: Vec<Vec<u32>>,
}

/// The buffers of [`reached_within`], kept for the next sweep: one set for the
/// whole process, until [`release_buffers`].
static TOUCHED: Mutex<Option<Touched>> = Mutex::new(None);

/// Frees the buffers [`reached_within`] keeps between sweeps.
pub(crate) fn release_buffers() {
    if let Ok(mut kept) = TOUCHED.lock() {
        *kept = None;
    }
}

/// The cells [`sweep_cells`] reaches (cost at most `max_cost`, the sources
/// included), in index order, touching only them and their neighbours instead of
/// the whole grid: for a small `max_cost` (the band around the border) a small
/// share of the grid.
pub(crate) fn reached_within<T: Copy>(
    geometry: &GridGeometry,
    cells: &[T],
    passable: impl Fn(T) -> bool,
    sources: &[usize],
    max_cost: u32,
) -> Vec<usize> {
    let n = geometry.len();
    let mut s = TOUCHED
        .lock()
        .ok()
        .and_then(|mut k| k.take())
        .unwrap_or_default();
    if s.cost.len() != n {
        s.cost = vec![UNREACHED; n];
    }
    s.buckets.resize_with(RING, Vec::new);
    let Touched {
        cost,
        touched,
        buckets,
    } = &mut s;
    touched.clear();
    for b in buckets.iter_mut() {
        b.clear();
    }
    let (w, h) = (geometry.width as i64, geometry.height as i64);
    for &i in sources {
        if i < n && cost[i] != 0 {
            cost[i] = 0;
            touched.push(i as u32);
            buckets[0].push(i as u32);
        }
    }
    let open = |j: usize| passable(cells[j]);
    let mut pending = buckets[0].len();
    let (mut current, mut slot) = (0u32, 0usize);
    while pending > 0 {
        let bucket = std::mem::take(&mut buckets[slot]);
        pending -= bucket.len();
        for &p in &bucket {
            let i = p as usize;
            if cost[i] != current {
                continue; // stale entry
            }
            let (x, y) = ((i as i64) % w, (i as i64) / w);
            for (k, &(dx, dy, step)) in STEPS.iter().enumerate() {
                let c = current.saturating_add(step);
                if c > max_cost || c == UNREACHED {
                    continue;
                }
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w || ny >= h {
                    continue;
                }
                let j = (ny * w + nx) as usize;
                // A diagonal step never cuts a blocked corner.
                if !open(j)
                    || (k >= 4 && (!open((y * w + nx) as usize) || !open((ny * w + x) as usize)))
                {
                    continue;
                }
                if c < cost[j] {
                    if cost[j] == UNREACHED {
                        touched.push(j as u32);
                    }
                    cost[j] = c;
                    buckets[(slot + step as usize) % RING].push(j as u32);
                    pending += 1;
                }
            }
        }
        // Steps cost at least STRAIGHT, so nothing was queued into this slot:
        // its buffer goes back for reuse.
        let mut bucket = bucket;
        bucket.clear();
        buckets[slot] = bucket;
        slot = (slot + 1) % RING;
        current += 1;
    }
    let mut out: Vec<usize> = touched.iter().map(|&i| i as usize).collect();
    for &i in touched.iter() {
        cost[i as usize] = UNREACHED;
    }
    out.sort_unstable();
    if let Ok(mut kept) = TOUCHED.lock() {
        *kept = Some(s);
    }
    out
}

/// Relaxes the neighbours of a cell on the grid's border, with bounds checks.
fn relax_border(
    geometry: &GridGeometry,
    flags: &[u8],
    cost: &mut [u32],
    i: usize,
    (straight_cost, to_straight): (u32, &mut Vec<u32>),
    (diagonal_cost, diagonal_ok, to_diagonal): (u32, bool, &mut Vec<u32>),
) {
    let (w, h) = (geometry.width as i64, geometry.height as i64);
    let (x, y) = ((i as i64) % w, (i as i64) / w);
    let open = |j: i64| flags[j as usize] & OPEN != 0;
    for (k, &(dx, dy, _)) in STEPS.iter().enumerate() {
        let (nx, ny) = (x + dx, y + dy);
        if nx < 0 || ny < 0 || nx >= w || ny >= h {
            continue;
        }
        let j = (ny * w + nx) as usize;
        let (c, queue) = if k < 4 {
            (straight_cost, &mut *to_straight)
        } else {
            if !diagonal_ok || !open(y * w + nx) || !open(ny * w + x) {
                continue;
            }
            (diagonal_cost, &mut *to_diagonal)
        };
        if c < cost[j] {
            cost[j] = c;
            queue.push(j as u32);
        }
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

    proptest::proptest! {
        #[test]
        fn sweep_matches_textbook_dijkstra(
            w in 1usize..30,
            h in 1usize..30,
            bits in proptest::collection::vec(0u8..4, 900),
            sources in proptest::collection::vec(0usize..900, 1..4),
            max_cost in proptest::sample::select(vec![0u32, 29, 100, 500, UNREACHED]),
        ) {
            let g = GridGeometry::new(w, h, 0.1, Point::default());
            let passable: Vec<bool> = (0..g.len()).map(|i| bits[i] != 0).collect();
            let sources: Vec<usize> = sources.iter().map(|&s| s % g.len()).collect();
            let f = sweep(&g, &passable, &sources, max_cost);
            proptest::prop_assert_eq!(f.cost, reference(&g, &passable, &sources, max_cost));
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
