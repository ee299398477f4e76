//! Built-in procedural ground-truth maps at the paper's simulation scale (section V-A:
//! 800 × 600 cells of 0.1 m, i.e. 80 m × 60 m, origin at the world origin).
//!
//! Every map is generated from a seed, deterministically: the same seed always gives
//! the same cells. Each map is binary ground truth (only [`CellState::Free`] and
//! [`CellState::Occupied`]), has a solid border at least 0.2 m thick, and all of its
//! free space is one 4-connected region. Every passage meant for robots (doors,
//! corridor necks, gaps between buildings, tunnel sections) is at least 1.2 m wide,
//! and there are no free slivers narrower than 0.8 m, so a robot of radius 0.3 m
//! reaches every part of the map.
//!
//! [`BuiltinMap::default_start`] is a fixed world point that is free, with at least
//! 1 m of clearance, for every seed: the generators keep that spot open by design.

mod office;
mod site;
mod tunnel;

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::geom::{Cell, Point};
use crate::grid::{CellState, GridGeometry, OccupancyGrid};

/// Columns of every built-in map (80 m at [`RESOLUTION`]).
pub const WIDTH: usize = 800;
/// Rows of every built-in map (60 m at [`RESOLUTION`]).
pub const HEIGHT: usize = 600;
/// Cell width of every built-in map, metres.
pub const RESOLUTION: f64 = 0.1;

/// The grid placement shared by all built-in maps: [`WIDTH`] × [`HEIGHT`] cells of
/// [`RESOLUTION`] m, lower-left corner at the world origin.
pub fn geometry() -> GridGeometry {
    GridGeometry::new(WIDTH, HEIGHT, RESOLUTION, Point::new(0.0, 0.0))
}

/// One of the procedural ground-truth maps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BuiltinMap {
    /// An office floor: two long corridors, rooms of 4–12 m with doors, cross
    /// corridors, an open-plan hall with pillars and desks.
    Office,
    /// An outdoor construction site inside a fence: 4–7 solid buildings (rectangles
    /// and L-shapes) with containers, trees and material piles between them.
    Site,
    /// A winding 3–5 m wide tunnel through solid rock, over 100 m long, with a
    /// wider chamber and short dead-end side branches.
    Tunnel,
}

/// The valid names of [`BuiltinMap`], comma-separated, for messages.
pub const VALID_NAMES: &str = "office, site, tunnel";

/// A name that is not one of the built-in maps.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown built-in map `{name}` (valid names: {VALID_NAMES})")]
pub struct UnknownMapError {
    /// The name that was given.
    pub name: String,
}

impl BuiltinMap {
    /// Every built-in map, in a fixed order.
    pub const ALL: [BuiltinMap; 3] = [BuiltinMap::Office, BuiltinMap::Site, BuiltinMap::Tunnel];

    /// The map used when none is named.
    pub const DEFAULT: BuiltinMap = BuiltinMap::Site;

    /// The map's name, as accepted by [`FromStr`] and used by serde.
    pub fn name(self) -> &'static str {
        match self {
            BuiltinMap::Office => "office",
            BuiltinMap::Site => "site",
            BuiltinMap::Tunnel => "tunnel",
        }
    }

    /// A one-line description of the map.
    pub fn description(self) -> &'static str {
        match self {
            BuiltinMap::Office => {
                "office floor: two long corridors, cross corridors, rooms of 4-12 m with \
                 doors, an open-plan hall with pillars and desks"
            }
            BuiltinMap::Site => {
                "fenced outdoor construction site: 4-7 solid buildings (rectangles and \
                 L-shapes), containers, trees and material piles"
            }
            BuiltinMap::Tunnel => {
                "winding 3-5 m wide tunnel through rock, over 100 m long, with a wider \
                 chamber and dead-end side branches"
            }
        }
    }

    /// Generate the ground truth for `seed`: [`WIDTH`] × [`HEIGHT`] cells of
    /// [`RESOLUTION`] m with origin (0, 0), only `Free` and `Occupied` cells. The same
    /// seed always gives the same map; generation takes a few milliseconds.
    ///
    /// ```
    /// use cpsplan::world::builtin::BuiltinMap;
    /// use cpsplan::world::CellState;
    ///
    /// let map = BuiltinMap::Tunnel;
    /// let grid = map.generate(7);
    /// assert_eq!((grid.width(), grid.height()), (800, 600));
    /// assert_eq!(grid, map.generate(7));
    /// assert_eq!(grid.count(CellState::Unknown), 0);
    /// let start = grid.geometry().world_to_cell(map.default_start()).unwrap();
    /// assert_eq!(grid.get(start), CellState::Free);
    /// ```
    pub fn generate(self, seed: u64) -> OccupancyGrid {
        let canvas = match self {
            BuiltinMap::Office => office::generate(seed),
            BuiltinMap::Site => site::generate(seed),
            BuiltinMap::Tunnel => tunnel::generate(seed),
        };
        canvas.finish(self.default_start())
    }

    /// A world-frame start position for the robots. It is the same for every seed
    /// and is free with at least 1 m clearance in every generated map: the west end
    /// of the office's main corridor, the south-west corner of the site, the tunnel's
    /// west mouth.
    pub fn default_start(self) -> Point {
        match self {
            BuiltinMap::Office => office::START,
            BuiltinMap::Site => site::START,
            BuiltinMap::Tunnel => tunnel::START,
        }
    }
}

impl Default for BuiltinMap {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl fmt::Display for BuiltinMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for BuiltinMap {
    type Err = UnknownMapError;

    /// Parse a map name, ignoring ASCII case and surrounding whitespace.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        Self::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(t))
            .ok_or_else(|| UnknownMapError { name: s.to_owned() })
    }
}

/// An axis-aligned rectangle of cells `[x0, x1) × [y0, y1)`, signed so that
/// inflated rectangles may reach past the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Rect {
    x0: i64,
    y0: i64,
    x1: i64,
    y1: i64,
}

impl Rect {
    fn new(x0: i64, y0: i64, x1: i64, y1: i64) -> Self {
        Self { x0, y0, x1, y1 }
    }

    fn width(&self) -> i64 {
        self.x1 - self.x0
    }

    fn height(&self) -> i64 {
        self.y1 - self.y0
    }

    /// The rectangle grown by `d` cells on every side (shrunk for negative `d`).
    fn inflate(&self, d: i64) -> Self {
        Self::new(self.x0 - d, self.y0 - d, self.x1 + d, self.y1 + d)
    }

    /// True when `other` lies inside this rectangle.
    fn contains(&self, other: &Rect) -> bool {
        other.x0 >= self.x0 && other.y0 >= self.y0 && other.x1 <= self.x1 && other.y1 <= self.y1
    }

    /// Euclidean width, in cells, of the free gap between two rectangles: 0 when
    /// they touch or overlap; for rectangles side by side, the number of cells
    /// between them.
    fn gap(&self, other: &Rect) -> f64 {
        let dx = (other.x0 - self.x1).max(self.x0 - other.x1).max(0) as f64;
        let dy = (other.y0 - self.y1).max(self.y0 - other.y1).max(0) as f64;
        dx.hypot(dy)
    }
}

/// A binary drawing surface of the built-in map size: `true` is free. Starts solid.
struct Canvas {
    free: Vec<bool>,
}

impl Canvas {
    /// All rock.
    fn solid() -> Self {
        Self {
            free: vec![false; WIDTH * HEIGHT],
        }
    }

    /// Set every cell of `r` (clipped to the grid) to `free`.
    fn fill(&mut self, r: Rect, free: bool) {
        let x0 = r.x0.clamp(0, WIDTH as i64) as usize;
        let x1 = r.x1.clamp(0, WIDTH as i64) as usize;
        let y0 = r.y0.clamp(0, HEIGHT as i64) as usize;
        let y1 = r.y1.clamp(0, HEIGHT as i64) as usize;
        if x0 >= x1 {
            return;
        }
        for y in y0..y1 {
            self.free[y * WIDTH + x0..y * WIDTH + x1].fill(free);
        }
    }

    /// Make free every cell whose centre lies within `r` metres of `(x, y)` metres.
    fn carve_disk(&mut self, x: f64, y: f64, r: f64) {
        let (cx, cy, cr) = (x / RESOLUTION, y / RESOLUTION, r / RESOLUTION);
        let y0 = ((cy - cr - 0.5).floor().max(0.0)) as usize;
        let y1 = ((cy + cr + 0.5).ceil().max(0.0) as usize).min(HEIGHT);
        for iy in y0..y1 {
            let dy = iy as f64 + 0.5 - cy;
            let h2 = cr * cr - dy * dy;
            if h2 < 0.0 {
                continue;
            }
            let h = h2.sqrt();
            let x0 = ((cx - h - 0.5).ceil().max(0.0)) as usize;
            let x1 = (((cx + h - 0.5).floor() + 1.0).max(0.0) as usize).min(WIDTH);
            if x0 < x1 {
                self.free[iy * WIDTH + x0..iy * WIDTH + x1].fill(true);
            }
        }
    }

    /// Solidify the border ring, keep only the free region 4-connected to `start`
    /// (a safety net: the generators already produce one region) and convert.
    fn finish(mut self, start: Point) -> OccupancyGrid {
        const RING: usize = 2;
        for y in 0..HEIGHT {
            for x in 0..WIDTH {
                if x < RING || y < RING || x >= WIDTH - RING || y >= HEIGHT - RING {
                    self.free[y * WIDTH + x] = false;
                }
            }
        }
        let geometry = geometry();
        let keep = match geometry.world_to_cell(start) {
            Some(c) if self.free[geometry.index(c)] => flood4(&self.free, WIDTH, HEIGHT, c),
            _ => vec![false; WIDTH * HEIGHT],
        };
        let cells = keep
            .iter()
            .map(|&f| {
                if f {
                    CellState::Free
                } else {
                    CellState::Occupied
                }
            })
            .collect();
        OccupancyGrid::from_cells(geometry, cells).expect("canvas has the grid's size")
    }
}

/// The cells of `mask` 4-connected to `seed` (which must be in `mask`).
fn flood4(mask: &[bool], w: usize, h: usize, seed: Cell) -> Vec<bool> {
    crate::grid::region::flood4(w, h, seed.y * w + seed.x, |i| mask[i])
}

/// Split `[start, end)` into spans of length `min..=max` separated by `gap` cells,
/// with random lengths. Requires `end - start >= min` and `max >= 2 * min + gap`.
fn partition<R: rand::Rng>(
    rng: &mut R,
    start: i64,
    end: i64,
    min: i64,
    max: i64,
    gap: i64,
) -> Vec<(i64, i64)> {
    use rand::RngExt;
    let mut spans = Vec::new();
    let mut a = start;
    while end - a > max {
        let hi = max.min(end - a - gap - min);
        let len = rng.random_range(min..=hi);
        spans.push((a, a + len));
        a += len + gap;
    }
    spans.push((a, end));
    spans
}

/// Shared checks of the generated maps, used by each map's tests.
#[cfg(test)]
mod checks {
    use super::*;

    /// Squared Euclidean distance, in cells², from every cell centre to the nearest
    /// cell centre where `source` is true (about 1e12 when there is none).
    /// Felzenszwalb & Huttenlocher's exact separable transform.
    pub(super) fn edt_sq(source: &[bool], w: usize, h: usize) -> Vec<f64> {
        const INF: f64 = 1e12;
        let mut d: Vec<f64> = source.iter().map(|&s| if s { 0.0 } else { INF }).collect();
        let n = w.max(h);
        let (mut f, mut out) = (vec![0.0; n], vec![0.0; n]);
        let (mut v, mut z) = (vec![0usize; n], vec![0.0; n + 1]);
        let mut dt = |f: &[f64], out: &mut [f64]| {
            let n = f.len();
            let mut k = 0;
            v[0] = 0;
            z[0] = f64::NEG_INFINITY;
            z[1] = f64::INFINITY;
            let sect = |q: usize, p: usize| {
                ((f[q] + (q * q) as f64) - (f[p] + (p * p) as f64)) / (2.0 * (q as f64 - p as f64))
            };
            for q in 1..n {
                let mut s = sect(q, v[k]);
                while s <= z[k] {
                    k -= 1;
                    s = sect(q, v[k]);
                }
                k += 1;
                v[k] = q;
                z[k] = s;
                z[k + 1] = f64::INFINITY;
            }
            k = 0;
            for (q, o) in out.iter_mut().enumerate().take(n) {
                while z[k + 1] < q as f64 {
                    k += 1;
                }
                let dq = q as f64 - v[k] as f64;
                *o = dq * dq + f[v[k]];
            }
        };
        for x in 0..w {
            for y in 0..h {
                f[y] = d[y * w + x];
            }
            dt(&f[..h], &mut out[..h]);
            for y in 0..h {
                d[y * w + x] = out[y];
            }
        }
        for y in 0..h {
            f[..w].copy_from_slice(&d[y * w..(y + 1) * w]);
            dt(&f[..w], &mut out[..w]);
            d[y * w..(y + 1) * w].copy_from_slice(&out[..w]);
        }
        d
    }

    /// True when the cells of `mask` form exactly one non-empty 4-connected region.
    pub(super) fn one_region(mask: &[bool], w: usize, h: usize) -> bool {
        let Some(first) = mask.iter().position(|&m| m) else {
            return false;
        };
        let reached = flood4(mask, w, h, Cell::new(first % w, first / w));
        reached.iter().filter(|&&r| r).count() == mask.iter().filter(|&&m| m).count()
    }

    /// Assert every ground-truth property of `map` generated with `seed`, with the
    /// free fraction inside `free_range`.
    pub(super) fn check_map(map: BuiltinMap, seed: u64, free_range: (f64, f64)) {
        let g = map.generate(seed);
        let ctx = format!("{map} seed {seed}");
        assert_eq!(*g.geometry(), geometry(), "{ctx}: geometry");
        assert_eq!(g.count(CellState::Unknown), 0, "{ctx}: unknown cells");
        let (w, h) = (g.width(), g.height());
        let free: Vec<bool> = g.cells().iter().map(|&c| c == CellState::Free).collect();

        for y in 0..h {
            for x in 0..w {
                if x < 2 || y < 2 || x >= w - 2 || y >= h - 2 {
                    assert!(!free[y * w + x], "{ctx}: border cell ({x}, {y}) is free");
                }
            }
        }

        let frac = free.iter().filter(|&&f| f).count() as f64 / free.len() as f64;
        assert!(
            (free_range.0..=free_range.1).contains(&frac),
            "{ctx}: free fraction {frac:.3} outside {free_range:?}"
        );

        assert!(
            one_region(&free, w, h),
            "{ctx}: free space is not one 4-connected region"
        );

        // The start and every cell within 1 m of it are free.
        let start = map.default_start();
        let res = g.resolution();
        for y in 0..h {
            for x in 0..w {
                let (cx0, cy0) = (x as f64 * res, y as f64 * res);
                let dx = (start.x - start.x.clamp(cx0, cx0 + res)).abs();
                let dy = (start.y - start.y.clamp(cy0, cy0 + res)).abs();
                if dx.hypot(dy) < 1.0 {
                    assert!(
                        free[y * w + x],
                        "{ctx}: cell ({x}, {y}) within 1 m of the start is not free"
                    );
                }
            }
        }

        // Distances (cells, centre to centre) to the nearest occupied cell. A free cell
        // at centre distance d has clearance about (d - 0.5) cells to the obstacle's edge.
        let occupied: Vec<bool> = free.iter().map(|&f| !f).collect();
        let d_obst = edt_sq(&occupied, w, h);

        // Robot centres (clearance >= 0.35 m): one region, reaching every free cell
        // within 0.6 m (no free pocket too narrow for the robot).
        let robot: Vec<bool> = (0..w * h).map(|i| free[i] && d_obst[i] >= 16.0).collect();
        assert!(
            one_region(&robot, w, h),
            "{ctx}: robot-reachable cells are not one region"
        );
        let d_robot = edt_sq(&robot, w, h);
        for i in 0..w * h {
            assert!(
                !free[i] || d_robot[i] <= 36.0,
                "{ctx}: free cell ({}, {}) is more than 0.6 m from any robot position",
                i % w,
                i / w
            );
        }

        // Passages at least 1.2 m wide: the cells with clearance >= 0.55 m (the middle
        // two cells of a 12-cell gap) form one region that comes within 1 m of every
        // free cell.
        let wide: Vec<bool> = (0..w * h).map(|i| free[i] && d_obst[i] >= 36.0).collect();
        assert!(
            one_region(&wide, w, h),
            "{ctx}: 1.2 m passages do not connect the map"
        );
        let d_wide = edt_sq(&wide, w, h);
        for i in 0..w * h {
            assert!(
                !free[i] || d_wide[i] <= 100.0,
                "{ctx}: free cell ({}, {}) lies in a pocket narrower than 1.2 m",
                i % w,
                i / w
            );
        }
    }

    /// Assert that `map` is deterministic in its seed and varies with it.
    pub(super) fn check_determinism(map: BuiltinMap) {
        for seed in [0, 1, 42] {
            assert_eq!(map.generate(seed), map.generate(seed), "{map} seed {seed}");
        }
        assert_ne!(
            map.generate(0),
            map.generate(1),
            "{map}: seeds 0 and 1 agree"
        );
        assert_ne!(
            map.generate(1),
            map.generate(2),
            "{map}: seeds 1 and 2 agree"
        );
    }
}

#[cfg(test)]
mod tests {
    use super::checks::{edt_sq, one_region};
    use super::*;

    #[test]
    fn names_round_trip() {
        for m in BuiltinMap::ALL {
            assert_eq!(m.name().parse::<BuiltinMap>(), Ok(m));
            assert_eq!(m.to_string(), m.name());
            assert!(!m.description().is_empty());
            assert!(VALID_NAMES.contains(m.name()));
        }
        assert_eq!(" Tunnel ".parse::<BuiltinMap>(), Ok(BuiltinMap::Tunnel));
        let names: Vec<&str> = BuiltinMap::ALL.iter().map(|m| m.name()).collect();
        assert_eq!(names.join(", "), VALID_NAMES);
        assert_eq!(BuiltinMap::default(), BuiltinMap::DEFAULT);
        assert_eq!(BuiltinMap::DEFAULT, BuiltinMap::Site);
    }

    #[test]
    fn unknown_name_lists_valid_names() {
        let err = "warehouse".parse::<BuiltinMap>().unwrap_err();
        assert_eq!(err.name, "warehouse");
        let msg = err.to_string();
        assert!(msg.contains("warehouse"), "{msg}");
        for m in BuiltinMap::ALL {
            assert!(msg.contains(m.name()), "{msg}");
        }
    }

    #[test]
    fn serde_uses_lowercase_names() {
        for m in BuiltinMap::ALL {
            let json = serde_json::to_string(&m).unwrap();
            assert_eq!(json, format!("\"{}\"", m.name()));
            assert_eq!(serde_json::from_str::<BuiltinMap>(&json).unwrap(), m);
        }
        assert!(serde_json::from_str::<BuiltinMap>("\"Office\"").is_err());
    }

    #[test]
    fn default_starts_are_inside_the_maps() {
        let g = geometry();
        for m in BuiltinMap::ALL {
            assert!(g.world_to_cell(m.default_start()).is_some(), "{m}");
        }
    }

    #[test]
    fn partition_respects_bounds() {
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for len in [40, 41, 119, 120, 121, 200, 794] {
            let spans = partition(&mut rng, 3, 3 + len, 40, 120, 2);
            assert_eq!(spans.first().unwrap().0, 3);
            assert_eq!(spans.last().unwrap().1, 3 + len);
            for (a, b) in &spans {
                assert!((40..=120).contains(&(b - a)), "{spans:?}");
            }
            for p in spans.windows(2) {
                assert_eq!(p[1].0 - p[0].1, 2);
            }
        }
    }

    #[test]
    fn rect_gap_counts_cells_between() {
        let a = Rect::new(0, 0, 10, 10);
        assert_eq!(a.gap(&Rect::new(22, 0, 30, 10)), 12.0);
        assert_eq!(a.gap(&Rect::new(5, 5, 30, 30)), 0.0);
        assert_eq!(a.gap(&Rect::new(13, 14, 20, 20)), 5.0);
        assert!(a.inflate(2).contains(&a));
        assert_eq!((a.width(), a.height()), (10, 10));
    }

    #[test]
    fn carve_disk_is_round() {
        let mut c = Canvas::solid();
        c.carve_disk(10.0, 10.0, 1.0);
        let n = c.free.iter().filter(|&&f| f).count() as f64;
        assert!((n - std::f64::consts::PI * 100.0).abs() < 20.0, "{n}");
        assert!(c.free[100 * WIDTH + 100] && c.free[100 * WIDTH + 109]);
        assert!(!c.free[100 * WIDTH + 111]);
    }

    #[test]
    fn edt_matches_brute_force() {
        let (w, h) = (23, 17);
        let src: Vec<bool> = (0..w * h).map(|i| (i * 7919) % 13 == 0).collect();
        let d = edt_sq(&src, w, h);
        for (i, &di) in d.iter().enumerate() {
            let best = (0..w * h)
                .filter(|&j| src[j])
                .map(|j| {
                    let dx = (i % w) as f64 - (j % w) as f64;
                    let dy = (i / w) as f64 - (j / w) as f64;
                    dx * dx + dy * dy
                })
                .fold(f64::INFINITY, f64::min);
            assert_eq!(di, best);
        }
        assert!(one_region(&[true, true, false, false], 2, 2));
        assert!(!one_region(&[true, false, false, true], 2, 2));
    }
}
