//! The `plan_inputs` fuzz target's body.
use cpsplan::config::ChildStrategy;
use cpsplan::{CellState, Config, GridGeometry, OccupancyGrid, Point};

const RESOLUTIONS: [f64; 3] = [0.05, 0.1, 0.2];
const HEADER: usize = 9 + 4 * 3;

/// A world position inside, on the edge of, or outside the grid.
fn position(g: &GridGeometry, mode: u8, a: u8, b: u8) -> Point {
    let (w, h) = (g.width as f64, g.height as f64);
    let r = g.resolution;
    match mode % 6 {
        // A cell centre (wrapping into the grid).
        0 | 1 => g.cell_center(cpsplan::Cell::new(
            usize::from(a) % g.width,
            usize::from(b) % g.height,
        )),
        // A cell corner, including the far edges (x = width · r is outside).
        2 => Point::new(
            f64::from(a % (g.width as u8 + 1)) * r,
            f64::from(b % (g.height as u8 + 1)) * r,
        ),
        // Anywhere from two map sizes left/below to two right/above.
        3 => Point::new(
            (f64::from(a) / 255.0 * 5.0 - 2.0) * w * r,
            (f64::from(b) / 255.0 * 5.0 - 2.0) * h * r,
        ),
        // Just inside / just outside the edges.
        4 => {
            let e = |v: u8, n: f64| match v % 4 {
                0 => -f64::EPSILON,
                1 => 0.0,
                2 => n * r - 1e-12,
                _ => n * r,
            };
            Point::new(e(a, w), e(b, h))
        }
        // Non-finite and huge values.
        _ => {
            let s = |v: u8| match v % 5 {
                0 => f64::NAN,
                1 => f64::INFINITY,
                2 => f64::NEG_INFINITY,
                3 => 1e300,
                _ => -1e300,
            };
            Point::new(s(a), s(b))
        }
    }
}

/// One planning step for a real team (`cpsplan::mission::plan_step`) on a small
/// occupancy grid built from the input, with robots anywhere (cell centres,
/// cell corners, outside the map, non-finite) and a few configuration knobs.
/// Asserts: no panic; errors are fine.
///
/// Input layout (missing bytes read as 0):
/// - 0: width − 1 (`% 64`), 1: height − 1 (`% 64`), 2: resolution (`% 3` of
///   0.05 / 0.1 / 0.2 m), 3: child strategy (`% 5`, `ChildStrategy::ALL`);
/// - 4: scanner.range, 5: children.min_range, 6: children.max_range (0: none),
///   7: robot.radius (see `knob`);
/// - 8: children (`% 4`) in bits 0–1; bit 2: make every robot's cell Free;
/// - 9..: four positions of 3 bytes (parent, then children): a mode byte and
///   two coordinate bytes (see `position`);
/// - then the cells, 2 bits each from the low bits up, row-major from the
///   bottom row: 0 or 1 Free, 2 Occupied, 3 Unknown; cells past the input's
///   end are Free.
pub fn run(data: &[u8]) {
    let byte = |i: usize| data.get(i).copied().unwrap_or(0);
    let width = usize::from(byte(0) % 64) + 1;
    let height = usize::from(byte(1) % 64) + 1;
    let resolution = RESOLUTIONS[usize::from(byte(2)) % RESOLUTIONS.len()];
    let geometry = GridGeometry::new(width, height, resolution, Point::new(0.0, 0.0));

    let mut config = Config {
        resolution,
        ..Config::default()
    };
    config.children.strategy = ChildStrategy::ALL[usize::from(byte(3)) % ChildStrategy::ALL.len()];
    config.scanner.range = 0.05 * f64::from(byte(4)); // 0 – 12.75 m
    config.children.min_range = 0.02 * f64::from(byte(5)); // 0 – 5.1 m
    config.children.max_range = match byte(6) {
        0 => None,
        v => Some(0.05 * f64::from(v)),
    };
    config.robot.radius = 0.01 * f64::from(byte(7)); // 0 – 2.55 m
    let children = usize::from(byte(8) & 3);
    let free_robots = byte(8) & 4 != 0;

    let cells_bytes = data.get(HEADER..).unwrap_or(&[]);
    let cells: Vec<CellState> = (0..width * height)
        .map(
            |i| match cells_bytes.get(i / 4).map(|b| (b >> (2 * (i % 4))) & 3) {
                None | Some(0) | Some(1) => CellState::Free,
                Some(2) => CellState::Occupied,
                Some(_) => CellState::Unknown,
            },
        )
        .collect();
    let mut grid = OccupancyGrid::from_cells(geometry, cells).expect("cell count");

    let at = |k: usize| {
        position(
            &geometry,
            byte(9 + 3 * k),
            byte(10 + 3 * k),
            byte(11 + 3 * k),
        )
    };
    let parent = at(0);
    let kids: Vec<Point> = (1..=children).map(at).collect();
    if free_robots {
        for p in std::iter::once(parent).chain(kids.iter().copied()) {
            if let Some(c) = geometry.world_to_cell(p) {
                grid.set(c, CellState::Free);
            }
        }
    }

    let _ = cpsplan::mission::plan_step(&grid, parent, &kids, &config);
}
