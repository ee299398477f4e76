//! The whole-grid sweep as canonical Dijkstra (Sturtevant & Rabin, "Canonical
//! orderings on grids", IJCAI 2016), for 8-connected grids whose diagonal steps
//! never cut a blocked corner.
//!
//! Among the cheapest paths to a cell there is one in canonical order: from a
//! source or a jump point, diagonal steps in one direction, then straight steps
//! along one of the diagonal's two components. So a cell reached by a diagonal step
//! passes the search on along the diagonal and its two component rays, a cell
//! reached by a straight step only along its ray, and the ray writes its costs
//! without the queue. Only where a straight ray passes the end of a wall beside it
//! (the side cell behind is blocked, the side cell here is open: the cells behind
//! the wall are reached from here, not from the row before) does a cell become a
//! jump point and enter the queue, to be expanded in all eight directions like a
//! source. With corners never cut a diagonal step has no such cells.
//!
//! Rays write costs ahead of the queue, so a cell may first get a dearer cost and
//! later a cheaper one: a ray stops at a cell that already holds a cheaper cost
//! (whatever reaches that cell cheaper carries on from it), continues over an equal
//! one, and a jump point is expanded only at its final cost, once. The queue holds
//! jump points in cost order, so a cost popped from it is final. The field equals
//! the plain Dijkstra's cell for cell (property tests against a textbook Dijkstra).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::{DIAGONAL, STRAIGHT, UNREACHED};
use crate::grid::GridGeometry;

/// Cell flag: the cell may be entered.
const OPEN: u8 = 1;
/// Cell flag: the cell was expanded as a source or jump point.
const EXPANDED: u8 = 2;

/// Working buffers of a sweep, kept between sweeps.
#[derive(Default)]
pub(super) struct Scratch {
    /// The flags of the grid with a border of one blocked cell all round, so that
    /// every cell of the grid has eight neighbours.
    flags: Vec<u8>,
    /// Jump points and sources by cost: `cost << 32 | cell` (a grid's cells
    /// number fewer than 2³²: the memory estimate refuses grids long before).
    queue: BinaryHeap<Reverse<u64>>,
}

impl Scratch {
    /// The cells the buffers are sized for.
    pub(super) fn capacity(&self) -> usize {
        self.flags.capacity()
    }
}

/// A step of the sweep: its offsets in the grid and in the bordered flags.
#[derive(Clone, Copy)]
struct Step {
    cell: isize,
    flag: isize,
}

impl Step {
    const fn plus(self, other: Step) -> Step {
        Step {
            cell: self.cell + other.cell,
            flag: self.flag + other.flag,
        }
    }
}

/// The grid being swept: its flags, its costs, and the queue.
struct Sweep<'a> {
    flags: &'a mut [u8],
    cost: Vec<u32>,
    queue: &'a mut BinaryHeap<Reverse<u64>>,
    /// The largest cost written.
    limit: u32,
}

/// The costs of a sweep from `sources` over the cells `i` with
/// `passable(cells[i])`, no cost above `max_cost`.
pub(super) fn canonical<T: Copy>(
    geometry: &GridGeometry,
    cells: &[T],
    passable: impl Fn(T) -> bool,
    sources: &[usize],
    max_cost: u32,
    scratch: &mut Scratch,
) -> Vec<u32> {
    let (w, h) = (geometry.width, geometry.height);
    let n = w * h;
    if n == 0 {
        return Vec::new();
    }
    let padded = w + 2;
    let flags = &mut scratch.flags;
    flags.clear();
    flags.resize(padded, 0);
    for row in cells[..n].chunks_exact(w) {
        flags.push(0);
        flags.extend(row.iter().map(|&c| if passable(c) { OPEN } else { 0 }));
        flags.push(0);
    }
    flags.resize(flags.len() + padded, 0);
    scratch.queue.clear();
    let mut sweep = Sweep {
        flags,
        cost: super::unreached_costs(n),
        queue: &mut scratch.queue,
        limit: max_cost.min(UNREACHED - 1),
    };
    for &s in sources {
        sweep.cost[s] = 0;
        sweep.jump(s, 0);
    }
    let east = Step { cell: 1, flag: 1 };
    let north = Step {
        cell: w as isize,
        flag: padded as isize,
    };
    let flag_of = |i: usize| i + 2 * (i / w) + padded + 1;
    while let Some(Reverse(key)) = sweep.queue.pop() {
        let (c, i) = ((key >> 32) as u32, (key & u64::from(u32::MAX)) as usize);
        let f = flag_of(i);
        if sweep.cost[i] != c || sweep.flags[f] & EXPANDED != 0 {
            continue; // a stale entry, or expanded already
        }
        sweep.flags[f] |= EXPANDED;
        for (along, side) in [(east, north), (north, east)] {
            for ray in [along, neg(along)] {
                sweep.ray(i, f, c, ray, side);
            }
        }
        for dx in [east, neg(east)] {
            for dy in [north, neg(north)] {
                sweep.diagonal(i, f, c, dx, dy);
            }
        }
    }
    sweep.cost
}

/// The opposite step.
const fn neg(s: Step) -> Step {
    Step {
        cell: -s.cell,
        flag: -s.flag,
    }
}

/// `i + d` for an offset that stays on the grid.
#[inline(always)]
fn at(i: usize, d: isize) -> usize {
    i.wrapping_add_signed(d)
}

impl Sweep<'_> {
    #[inline(always)]
    fn open(&self, f: usize) -> bool {
        self.flags[f] & OPEN != 0
    }

    /// Queues a jump point (or a source) at cost `c`.
    fn jump(&mut self, i: usize, c: u32) {
        self.queue.push(Reverse(u64::from(c) << 32 | i as u64));
    }

    /// The straight ray from cell `i` (flag `f`, cost `c`) along `step`; `side`
    /// is the perpendicular step, for the walls beside the ray.
    #[inline(always)]
    fn ray(&mut self, mut i: usize, mut f: usize, mut c: u32, step: Step, side: Step) {
        let mut left = self.open(at(f, side.flag));
        let mut right = self.open(at(f, -side.flag));
        loop {
            let next = c.saturating_add(STRAIGHT);
            let (ni, nf) = (at(i, step.cell), at(f, step.flag));
            if next > self.limit || !self.open(nf) {
                return;
            }
            let held = self.cost[ni];
            if next > held {
                return; // reached cheaper: that path carries on from here
            }
            self.cost[ni] = next;
            let (l, r) = (self.open(at(nf, side.flag)), self.open(at(nf, -side.flag)));
            if (l && !left) || (r && !right) {
                self.jump(ni, next);
            }
            (i, f, c, left, right) = (ni, nf, next, l, r);
        }
    }

    /// The diagonal from cell `i` (flag `f`, cost `c`) along `dx + dy`, with the
    /// rays along `dx` and `dy` from every cell it reaches.
    #[inline(always)]
    fn diagonal(&mut self, mut i: usize, mut f: usize, mut c: u32, dx: Step, dy: Step) {
        let step = dx.plus(dy);
        loop {
            let next = c.saturating_add(DIAGONAL);
            let nf = at(f, step.flag);
            if next > self.limit
                || !self.open(at(f, dx.flag))
                || !self.open(at(f, dy.flag))
                || !self.open(nf)
            {
                return;
            }
            let ni = at(i, step.cell);
            if next > self.cost[ni] {
                return;
            }
            self.cost[ni] = next;
            self.ray(ni, nf, next, dx, dy);
            self.ray(ni, nf, next, dy, dx);
            (i, f, c) = (ni, nf, next);
        }
    }
}
