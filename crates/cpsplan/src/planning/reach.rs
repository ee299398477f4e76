//! Shortest travel distances on the grid: Dial's bucket-queue Dijkstra with
//! integer 8-connected step costs (straight 29, diagonal 41; 41/29 ≈ √2 to 0.03 %).
//! Diagonal steps never cut a blocked corner. One sweep gives the travel distance
//! `L` of Eq. (1) to every candidate and the set of reachable cells.

use crate::geom::Cell;
use crate::world::GridGeometry;

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

/// Dijkstra from `sources` over cells with `passable[i]`, expanding no cell whose
/// cost exceeds `max_cost`. Sources need not be passable themselves.
pub fn sweep(
    geometry: &GridGeometry,
    passable: &[bool],
    sources: &[usize],
    max_cost: u32,
) -> DistanceField {
    let (w, h) = (geometry.width as i64, geometry.height as i64);
    let mut cost = vec![UNREACHED; geometry.len()];
    let ring = DIAGONAL as usize + 1;
    let mut buckets: Vec<Vec<usize>> = vec![Vec::new(); ring];
    let mut pending = 0usize;
    for &s in sources {
        if cost[s] != 0 {
            cost[s] = 0;
            buckets[0].push(s);
            pending += 1;
        }
    }
    let wu = geometry.width;
    // Index offsets of the straight and diagonal steps, with the two straight cells
    // a diagonal step passes between.
    let wi = wu as isize;
    let straight = [1isize, -1, wi, -wi];
    let diagonal = [
        (wi + 1, 1, wi),
        (wi - 1, -1, wi),
        (-wi + 1, 1, -wi),
        (-wi - 1, -1, -wi),
    ];
    let mut current: u32 = 0;
    while pending > 0 {
        let slot = current as usize % ring;
        while let Some(i) = buckets[slot].pop() {
            pending -= 1;
            if cost[i] != current {
                continue; // stale entry
            }
            let (x, y) = ((i % wu) as i64, (i / wu) as i64);
            let mut relax = |j: usize, step: u32, buckets: &mut [Vec<usize>]| {
                let c = current + step;
                if c < cost[j] && c <= max_cost {
                    cost[j] = c;
                    buckets[c as usize % ring].push(j);
                    pending += 1;
                }
            };
            if x > 0 && y > 0 && x + 1 < w && y + 1 < h {
                // Interior cell: every neighbour exists.
                let ii = i as isize;
                for d in straight {
                    let j = (ii + d) as usize;
                    if passable[j] {
                        relax(j, STRAIGHT, &mut buckets);
                    }
                }
                for (d, a, b) in diagonal {
                    let j = (ii + d) as usize;
                    if passable[j] && passable[(ii + a) as usize] && passable[(ii + b) as usize] {
                        relax(j, DIAGONAL, &mut buckets);
                    }
                }
                continue;
            }
            for (k, &(dx, dy, step)) in STEPS.iter().enumerate() {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w || ny >= h {
                    continue;
                }
                let j = (ny * w + nx) as usize;
                if !passable[j] {
                    continue;
                }
                if k >= 4 {
                    let a = (y * w + nx) as usize;
                    let b = (ny * w + x) as usize;
                    if !passable[a] || !passable[b] {
                        continue;
                    }
                }
                relax(j, step, &mut buckets);
            }
        }
        current += 1;
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
        let f = sweep(&g, &vec![true; 50], &[0], 10 * STRAIGHT);
        assert!(f.reached(10));
        assert!(!f.reached(11));
    }
}
