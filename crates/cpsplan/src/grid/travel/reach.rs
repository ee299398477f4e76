//! Dial's bucket-queue Dijkstra over the cells it reaches only.

use std::sync::Mutex;

use super::{DIAGONAL, STEPS, UNREACHED};
use crate::grid::GridGeometry;

/// Buckets of Dial's queue: one more than the largest step, so that every pending
/// cost lies within one turn of the ring.
const RING: usize = DIAGONAL as usize + 1;

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
