//! `tunnel`: a winding tunnel through solid rock, 80 m × 60 m of map.
//!
//! The centre line is a centripetal Catmull-Rom spline through seeded waypoints that
//! sweep the map in a serpentine, either three east–west passes or four north–south
//! passes about 21 m apart, starting at a mouth near the south-west corner. The
//! tunnel is carved as a chain of disks every 0.25 m whose radius varies smoothly
//! between 1.5 and 2.5 m (3–5 m wide), with slight roughness; one stretch widens into
//! a chamber 7.6–9.2 m wide and 14–20 m long, and one or two short dead-end side
//! branches (7–13 m, about 3.2 m wide) leave it at nearly right angles, at least 20 m
//! apart and clear of the chamber. The main tunnel is 180–250 m long.
//!
//! A layout is kept only if every two disks that come within 1.2 m of each other are
//! part of one nearly straight stretch of the tunnel (or of a branch's junction), so
//! rock between neighbouring sections is at least 1.2 m thick, and if the tunnel keeps
//! 1.5 m of rock to the map's edge; otherwise the waypoints are drawn again (after
//! 100 failures, which no tested seed reaches, a jitter-free serpentine without a
//! chamber is used). A branch is kept under the same rule, else redrawn or left out.

use std::f64::consts::PI;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{Canvas, HEIGHT, RESOLUTION, WIDTH};
use crate::geom::Point;

/// Start: the tunnel's mouth, near the south-west corner.
pub(super) const START: Point = Point::new(4.0, 8.0);

/// Least rock between the tunnel and the map's edge, metres.
const MARGIN: f64 = 1.5;
/// Least rock between tunnel sections that do not join, metres.
const ROCK: f64 = 1.2;
/// Spacing of the carved disks along the centre line, metres.
const STEP: f64 = 0.25;
/// Radius range of the ordinary tunnel, metres (3–5 m wide).
const RADIUS: (f64, f64) = (1.5, 2.5);

/// One carved disk: centre and radius (metres), the path it belongs to (0 is the
/// main tunnel, k ≥ 1 the k-th branch) and its arc length along that path.
#[derive(Debug, Clone, Copy)]
struct Disk {
    x: f64,
    y: f64,
    r: f64,
    path: usize,
    s: f64,
}

pub(super) fn generate(seed: u64) -> Canvas {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x7E44_E100_5EED_0003);
    let disks = plan(&mut rng);
    let mut canvas = Canvas::solid();
    for d in &disks {
        canvas.carve_disk(d.x, d.y, d.r);
    }
    canvas
}

/// The disks of the main tunnel and its branches.
fn plan(rng: &mut ChaCha8Rng) -> Vec<Disk> {
    let mut disks = (0..100)
        .map(|_| main_path(rng, 1.0, true))
        .find(|d| valid(d, &[]))
        .unwrap_or_else(|| main_path(rng, 0.0, false));
    let mut junctions: Vec<f64> = Vec::new();
    let length = disks.last().map_or(0.0, |d| d.s);
    for _ in 0..rng.random_range(1..=2) {
        for _ in 0..30 {
            let path = junctions.len() + 1;
            let (junction, branch) = branch(rng, &disks, length, path);
            let mut js = junctions.clone();
            js.push(junction);
            // Junctions stay 20 m apart and 6 m clear of the chamber.
            let apart = junctions.iter().all(|j| (j - junction).abs() >= 20.0);
            let plain = disks
                .iter()
                .filter(|d| d.path == 0 && (d.s - junction).abs() <= 6.0)
                .all(|d| d.r <= RADIUS.1);
            let ok = apart
                && plain
                && branch.iter().all(in_bounds)
                && branch
                    .iter()
                    .all(|b| disks.iter().all(|d| !clash(b, d, &js)));
            if ok {
                junctions = js;
                disks.extend(branch);
                break;
            }
        }
    }
    disks
}

/// The main tunnel: a serpentine of waypoints (cross-track jitter scaled by
/// `jitter`), smoothed, with a radius profile and, if `chamber`, a chamber.
fn main_path(rng: &mut ChaCha8Rng, jitter: f64, chamber: bool) -> Vec<Disk> {
    let centre = resample(&spline(&waypoints(rng, jitter)), STEP);
    let length = (centre.len() - 1) as f64 * STEP;
    let base = Profile::new(rng, length, 8.0, (1.6, 2.4), Some(2.0));
    let rough = Profile::new(rng, length, 1.5, (-0.12, 0.12), None);
    // The chamber: a plateau of radius `r` over `2 * half` metres, with 4 m ramps.
    let bump = chamber.then(|| {
        let at = rng.random_range(0.25 * length..0.75 * length);
        let half = rng.random_range(3.0..6.0);
        let r = rng.random_range(3.8..4.6);
        (at, half, r)
    });
    const RAMP: f64 = 4.0;
    centre
        .iter()
        .enumerate()
        .map(|(i, &(x, y))| {
            let s = i as f64 * STEP;
            let mut r = (base.at(s) + rough.at(s)).clamp(RADIUS.0, RADIUS.1);
            if let Some((at, half, rc)) = bump {
                let out = ((s - at).abs() - half).max(0.0) / RAMP;
                if out < 1.0 {
                    let w = 0.5 + 0.5 * (PI * out).cos();
                    r += (rc - r).max(0.0) * w;
                }
            }
            Disk {
                x,
                y,
                r,
                path: 0,
                s,
            }
        })
        .collect()
}

/// Serpentine waypoints from the mouth: passes along one axis at fixed levels of the
/// other, joined by U-turns; the last pass stops at a random waypoint.
fn waypoints(rng: &mut ChaCha8Rng, jitter: f64) -> Vec<(f64, f64)> {
    let horizontal = rng.random_bool(0.5);
    // Pass levels across the passes, range along them, and where the U-turns are.
    let (levels, along, turns): (&[f64], (f64, f64), (f64, f64)) = if horizontal {
        (&[8.5, 30.0, 51.5], (12.0, 71.0), (5.5, 74.5))
    } else {
        (&[8.5, 29.0, 49.5, 70.0], (13.0, 51.0), (5.0, 55.0))
    };
    let place = |a: f64, c: f64| if horizontal { (a, c) } else { (c, a) };
    let mut pts = vec![(START.x, START.y)];
    let mut level = levels[0];
    for (k, &nominal) in levels.iter().enumerate() {
        if k > 0 {
            level = nominal + jitter * rng.random_range(-1.5..1.5);
        }
        let mut stops = Vec::new();
        let mut a = along.0 + rng.random_range(0.0..4.0);
        while a < along.1 - 6.0 {
            stops.push(a);
            a += rng.random_range(10.0..14.0);
        }
        stops.push(along.1);
        let forward = k % 2 == 0;
        if !forward {
            for a in &mut stops {
                *a = along.0 + along.1 - *a;
            }
        }
        if k + 1 == levels.len() {
            let keep = rng.random_range(2..=stops.len());
            stops.truncate(keep);
        }
        for a in stops {
            let c = level + jitter * rng.random_range(-3.5..3.5);
            pts.push(place(a, c));
        }
        if let Some(&next) = levels.get(k + 1) {
            let a = if forward { turns.1 } else { turns.0 };
            let c = 0.5 * (level + next) + jitter * rng.random_range(-1.5..1.5);
            pts.push(place(a, c));
        }
    }
    pts
}

/// A dense polyline along the centripetal Catmull-Rom spline through `pts`.
fn spline(pts: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let n = pts.len();
    let ext = |a: (f64, f64), b: (f64, f64)| (2.0 * a.0 - b.0, 2.0 * a.1 - b.1);
    let mut all = Vec::with_capacity(n + 2);
    all.push(ext(pts[0], pts[1]));
    all.extend_from_slice(pts);
    all.push(ext(pts[n - 1], pts[n - 2]));
    let mut out = vec![pts[0]];
    for w in all.windows(4) {
        let [p0, p1, p2, p3] = [w[0], w[1], w[2], w[3]];
        let knot = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).hypot(a.1 - b.1).sqrt().max(1e-6);
        let t0 = 0.0;
        let t1 = t0 + knot(p0, p1);
        let t2 = t1 + knot(p1, p2);
        let t3 = t2 + knot(p2, p3);
        let lerp = |a: (f64, f64), b: (f64, f64), ta: f64, tb: f64, t: f64| {
            let u = (t - ta) / (tb - ta);
            (a.0 + (b.0 - a.0) * u, a.1 + (b.1 - a.1) * u)
        };
        const SAMPLES: usize = 64;
        for i in 1..=SAMPLES {
            let t = t1 + (t2 - t1) * i as f64 / SAMPLES as f64;
            let a1 = lerp(p0, p1, t0, t1, t);
            let a2 = lerp(p1, p2, t1, t2, t);
            let a3 = lerp(p2, p3, t2, t3, t);
            let b1 = lerp(a1, a2, t0, t2, t);
            let b2 = lerp(a2, a3, t1, t3, t);
            out.push(lerp(b1, b2, t1, t2, t));
        }
    }
    out
}

/// Points every `step` metres of arc length along a polyline, from its start.
fn resample(line: &[(f64, f64)], step: f64) -> Vec<(f64, f64)> {
    let mut out = vec![line[0]];
    let mut carry = 0.0; // arc length since the last output point
    for w in line.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        let mut t = step - carry;
        while t <= len {
            out.push((a.0 + (b.0 - a.0) * t / len, a.1 + (b.1 - a.1) * t / len));
            t += step;
        }
        carry = len - (t - step);
    }
    out
}

/// A smooth random function of arc length: values drawn at knots every `spacing`
/// metres (the first one fixed if given), blended with a cosine.
struct Profile {
    spacing: f64,
    knots: Vec<f64>,
}

impl Profile {
    fn new(
        rng: &mut ChaCha8Rng,
        length: f64,
        spacing: f64,
        range: (f64, f64),
        first: Option<f64>,
    ) -> Self {
        let n = (length / spacing).ceil() as usize + 2;
        let mut knots: Vec<f64> = (0..n).map(|_| rng.random_range(range.0..range.1)).collect();
        if let Some(v) = first {
            knots[0] = v;
        }
        Self { spacing, knots }
    }

    fn at(&self, s: f64) -> f64 {
        let u = (s / self.spacing).max(0.0);
        let i = (u.floor() as usize).min(self.knots.len() - 2);
        let f = (u - i as f64).min(1.0);
        let w = 0.5 - 0.5 * (PI * f).cos();
        self.knots[i] * (1.0 - w) + self.knots[i + 1] * w
    }
}

/// A dead-end branch, numbered `path`, leaving the main tunnel at a random point away
/// from its ends at nearly a right angle: its junction arc length and its disks.
fn branch(rng: &mut ChaCha8Rng, main: &[Disk], length: f64, path: usize) -> (f64, Vec<Disk>) {
    let i = ((rng.random_range(20.0..length - 20.0) / STEP) as usize).clamp(1, main.len() - 2);
    let (a, b) = (main[i - 1], main[i + 1]);
    let side = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let mut heading =
        (b.y - a.y).atan2(b.x - a.x) + side * PI / 2.0 + rng.random_range(-0.25..0.25);
    let turn = rng.random_range(-0.02..0.02);
    let len = rng.random_range(7.0..13.0);
    let r = rng.random_range(1.55..1.75);
    let (mut x, mut y) = (main[i].x, main[i].y);
    let mut disks = Vec::new();
    let mut s = 0.0;
    while s <= len {
        disks.push(Disk { x, y, r, path, s });
        x += STEP * heading.cos();
        y += STEP * heading.sin();
        heading += turn * STEP;
        s += STEP;
    }
    (main[i].s, disks)
}

/// True when the disk keeps [`MARGIN`] of rock to the map's edge.
fn in_bounds(d: &Disk) -> bool {
    let (w, h) = (WIDTH as f64 * RESOLUTION, HEIGHT as f64 * RESOLUTION);
    d.x - d.r >= MARGIN && d.y - d.r >= MARGIN && d.x + d.r <= w - MARGIN && d.y + d.r <= h - MARGIN
}

/// True when two disks come within [`ROCK`] of each other without being one clean
/// stretch of tunnel: on the same path, the centre line between them must be nearly
/// straight (distance at least 0.85 × arc length); between a branch and another path,
/// they must be near the junction.
fn clash(a: &Disk, b: &Disk, junctions: &[f64]) -> bool {
    let reach = a.r + b.r + ROCK;
    let (dx, dy) = (a.x - b.x, a.y - b.y);
    let d2 = dx * dx + dy * dy;
    if d2 >= reach * reach {
        return false;
    }
    let d = d2.sqrt();
    if a.path == b.path {
        return d < 0.85 * (a.s - b.s).abs();
    }
    let at = |d: &Disk| {
        if d.path == 0 {
            d.s
        } else {
            junctions[d.path - 1]
        }
    };
    let off = |d: &Disk| if d.path == 0 { 0.0 } else { d.s };
    let arc = off(a) + off(b) + (at(a) - at(b)).abs();
    arc > 2.5 * reach
}

/// True when every disk is in bounds and no two clash.
fn valid(disks: &[Disk], junctions: &[f64]) -> bool {
    disks.iter().all(in_bounds)
        && disks
            .iter()
            .enumerate()
            .all(|(i, a)| disks[i + 1..].iter().all(|b| !clash(a, b, junctions)))
}

#[cfg(test)]
mod tests {
    use super::super::checks::{check_determinism, check_map, edt_sq};
    use super::super::{flood4, BuiltinMap};
    use super::*;
    use crate::geom::Cell;
    use crate::grid::CellState;

    #[test]
    fn deterministic_and_seed_dependent() {
        check_determinism(BuiltinMap::Tunnel);
    }

    #[test]
    fn ground_truth_properties() {
        for seed in 0..5 {
            check_map(BuiltinMap::Tunnel, seed, (0.15, 0.30));
        }
    }

    #[test]
    fn long_winding_and_valid() {
        for seed in 0..20 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let disks = plan(&mut rng);
            let main: Vec<&Disk> = disks.iter().filter(|d| d.path == 0).collect();
            let length = main.last().unwrap().s;
            assert!(length > 150.0, "seed {seed}: length {length}");
            assert!(disks.iter().all(in_bounds));
            let widest = main.iter().map(|d| d.r).fold(0.0, f64::max);
            assert!(widest >= 3.7, "seed {seed}: no chamber");
            assert!(disks.iter().any(|d| d.path == 1), "seed {seed}: no branch");
            assert!(main.iter().all(|d| d.r >= RADIUS.0));
        }
    }

    #[test]
    fn fallback_plan_is_valid() {
        for seed in 0..20 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            assert!(valid(&main_path(&mut rng, 0.0, false), &[]), "seed {seed}");
        }
    }

    #[test]
    fn resample_spacing() {
        let pts = resample(&[(0.0, 0.0), (1.0, 0.0), (1.0, 2.0)], 0.25);
        assert_eq!(pts.len(), 13);
        for w in pts.windows(2) {
            let d = (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1);
            assert!(d <= 0.25 + 1e-9 && d > 0.17, "{d}");
        }
    }

    /// No rock wall thinner than about 0.9 m: rock that does not survive an opening
    /// with a 0.5 m disk comes only in small bits (corners at junctions, scallops).
    #[test]
    fn no_thin_rock_walls() {
        for seed in 0..5 {
            let g = BuiltinMap::Tunnel.generate(seed);
            let (w, h) = (g.width(), g.height());
            let free: Vec<bool> = g.cells().iter().map(|&c| c == CellState::Free).collect();
            let d_free = edt_sq(&free, w, h);
            let core: Vec<bool> = (0..w * h).map(|i| d_free[i] >= 25.0).collect();
            let d_core = edt_sq(&core, w, h);
            let mut thin: Vec<bool> = (0..w * h).map(|i| !free[i] && d_core[i] > 25.0).collect();
            let mut largest = 0;
            for i in 0..w * h {
                if thin[i] {
                    let part = flood4(&thin, w, h, Cell::new(i % w, i / w));
                    let n = part.iter().filter(|&&p| p).count();
                    largest = largest.max(n);
                    for (t, p) in thin.iter_mut().zip(part) {
                        *t &= !p;
                    }
                }
            }
            assert!(largest <= 40, "seed {seed}: thin rock of {largest} cells");
        }
    }
}
