//! The known-map yardstick (beyond the paper): how few scan stations a team that
//! already knew the map would need, to measure an exploring planner against.
//!
//! In: the ground truth, the start, the configuration (scanner range, robot
//! radius). Out: a [`KnownMapBound`]: the stations a greedy set cover picks to
//! see 90 / 95 / 99 / 100 % of the coverable cells, and a lower bound on the
//! fewest stations for each share from the LP relaxation's Lagrangian dual.
//!
//! - Candidate stations: drivable cells reachable from the start on a lattice
//!   (`bound.spacing`, 1 m unless the site is large) and beside the obstacles'
//!   convex corners ([`lattice_stations`], [`corner_stations`]).
//! - Targets: the free cells the exploring planner's coverage counts (reachable
//!   free space, [`crate::world::CoverageTracker`]), on a sub-lattice when there
//!   are very many; *coverable*: seen from at least one candidate.
//! - Visibility: the scanner's own rule ([`crate::sensing::visible_cells`] on the
//!   ground truth, within the range).
//! - [`lazy_greedy`]: the cover. [`lower_bound`]: the lower bound. Both count stations drawn
//!   from the same candidates.

mod dual;
mod stations;

pub use crate::grid::cover::{lazy_greedy, Pick};
pub use dual::lower_bound;
pub use stations::{corner_stations, lattice_stations, StationOrigin};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::config::{Config, ConfigError};
use crate::geom::Point;
use crate::grid::travel::{sweep, UNREACHED};
use crate::grid::{CellState, OccupancyGrid, Traversability};
use crate::mission::{start_cell, MissionError};
use crate::sensing::visible_cells;
use crate::world::CoverageTracker;

/// The coverage shares reported.
pub const BOUND_SHARES: [f64; 4] = [0.90, 0.95, 0.99, 1.0];

/// Targets at most: beyond, they are taken on a coarser sub-lattice.
pub const MAX_TARGETS: usize = 100_000;

/// Lattice stations at most: beyond, the lattice is widened.
pub const MAX_LATTICE_STATIONS: usize = 8_000;

/// Corner stations at most: beyond, every k-th is kept.
pub const MAX_CORNER_STATIONS: usize = 4_000;

/// Subgradient steps of the lower bound per share, at most.
pub const BOUND_ITERATIONS: usize = 150;

/// Work of the lower bound per share: steps times the views' total size, at most
/// (fewer steps on large sites).
pub const BOUND_WORK: usize = 2_000_000_000;

/// Why no bound could be computed.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BoundError {
    /// A parameter is out of range.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The start is off the map or not free.
    #[error(transparent)]
    Start(#[from] MissionError),
    /// A spacing is not within one cell and the map's longer side.
    #[error(
        "--{name} must be from {min} m (one cell) to {max} m (the map's longer side), not {value}"
    )]
    Spacing {
        /// The flag.
        name: &'static str,
        /// The value given.
        value: f64,
        /// One cell, metres.
        min: f64,
        /// The map's longer side, metres.
        max: f64,
    },
    /// The bound would need more memory than the run may use.
    #[error(
        "the bound's {what} {needed_mb:.0} MB, more than {limit_by} ({limit_mb:.0} MB); \
         widen --spacing or --target-spacing, or choose a coarser --resolution"
    )]
    Memory {
        /// What needs it, with its size ("views of 2,560,000 stations are
        /// estimated to need").
        what: String,
        /// The estimate, MB.
        needed_mb: f64,
        /// The limit, MB.
        limit_mb: f64,
        /// What sets the limit.
        limit_by: String,
    },
}

/// Bytes per grid cell of the bound's own maps (the solid copy, the drivable
/// cells, the travel field, the coverage tracker, the target numbers).
pub const BOUND_BYTES_PER_CELL: f64 = 32.0;

/// Stations whose views are counted to estimate the memory of all of them.
const SAMPLED_VIEWS: usize = 64;

/// Bytes in a megabyte (MiB, as the memory limits count).
const MB: f64 = 1024.0 * 1024.0;

/// How the bound is computed: `None` chooses from the map's size.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct BoundParams {
    /// Spacing of the candidate lattice, metres (default 1 m, wider on large sites
    /// so that at most [`MAX_LATTICE_STATIONS`] stations are drawn).
    pub spacing_m: Option<f64>,
    /// Spacing of the target cells, metres (default: every cell, or a sub-lattice
    /// with at most [`MAX_TARGETS`] targets).
    pub target_spacing_m: Option<f64>,
}

/// One coverage share's figures.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BoundLevel {
    /// Share of the coverable targets.
    pub share: f64,
    /// Stations the greedy cover needs for it.
    pub greedy_stations: usize,
    /// The dual's lower bound on the fewest stations (fractional).
    pub lower_bound: f64,
    /// Its ceiling: no cover from the candidates has fewer stations.
    pub lower_bound_stations: usize,
}

/// One station of the greedy cover, in the order chosen.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BoundStation {
    /// Position (cell centre), world frame.
    pub position: Point,
    /// Lattice or corner.
    pub origin: StationOrigin,
    /// Targets it adds.
    pub new_targets: usize,
    /// The area they stand for, m².
    pub new_m2: f64,
    /// Share of the coverable targets seen after it.
    pub coverage: f64,
}

/// The known-map bound of a map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KnownMapBound {
    /// Scanner range, metres.
    pub range_m: f64,
    /// Grid resolution, metres.
    pub resolution_m: f64,
    /// Robot radius, metres.
    pub robot_radius_m: f64,
    /// The start, world frame.
    pub start: Point,
    /// Lattice spacing used, metres.
    pub spacing_m: f64,
    /// Target spacing used, metres.
    pub target_spacing_m: f64,
    /// Candidate stations on the lattice.
    pub lattice_stations: usize,
    /// Candidate stations beside corners.
    pub corner_stations: usize,
    /// Free cells the exploring planner's coverage counts.
    pub reachable_free_cells: usize,
    /// Targets (those cells on the target lattice).
    pub targets: usize,
    /// Targets some candidate sees.
    pub coverable_targets: usize,
    /// Figures for 90, 95, 99 and 100 %.
    pub levels: Vec<BoundLevel>,
    /// The greedy cover to 100 %, in order.
    pub stations: Vec<BoundStation>,
}

impl KnownMapBound {
    /// The figures for `share`, if reported.
    pub fn level(&self, share: f64) -> Option<&BoundLevel> {
        self.levels.iter().find(|l| (l.share - share).abs() < 1e-9)
    }
}

/// The memory limit: `limits.max_memory_mb` when set, else `available`
/// (MB and what sets it), else none.
fn memory_limit(config: &Config, available: Option<(f64, &str)>) -> Option<(f64, String)> {
    if config.limits.max_memory_mb > 0.0 {
        Some((
            config.limits.max_memory_mb,
            "`limits.max_memory_mb`".to_string(),
        ))
    } else {
        available.map(|(mb, source)| (mb, source.to_string()))
    }
}

/// Refuses `needed_mb` for `what` beyond `limit`.
fn check_memory(
    what: String,
    needed_mb: f64,
    limit: &Option<(f64, String)>,
) -> Result<(), BoundError> {
    match limit {
        Some((limit_mb, source)) if needed_mb > *limit_mb => Err(BoundError::Memory {
            what,
            needed_mb: needed_mb.ceil(),
            limit_mb: limit_mb.floor(),
            limit_by: source.clone(),
        }),
        _ => Ok(()),
    }
}

/// Computes the known-map bound of `truth` (planning resolution applied; anything
/// not Free is solid) for a team starting at `start`. Its memory is estimated
/// before each large allocation (the grid's maps; the stations' views, from a
/// sample of them) and refused beyond `limits.max_memory_mb` or, without that
/// limit, `available` (MB and what sets it, for the message).
pub fn known_map_bound(
    truth: &OccupancyGrid,
    start: Point,
    config: &Config,
    params: BoundParams,
    available: Option<(f64, &str)>,
) -> Result<KnownMapBound, BoundError> {
    // The children play no part in the bound: their link range is not checked.
    let mut checked = config.clone();
    checked.children.count = 0;
    checked.validate()?;
    let g = *truth.geometry();
    g.check_limits(config)?;
    let (min, max) = (g.resolution, g.width.max(g.height) as f64 * g.resolution);
    for (name, v) in [
        ("spacing", params.spacing_m),
        ("target-spacing", params.target_spacing_m),
    ] {
        if let Some(value) = v {
            // Within a millionth of a cell of the ends counts as the end.
            let slack = 1e-6 * min;
            if !(value.is_finite() && value >= min - slack && value <= max + slack) {
                return Err(BoundError::Spacing {
                    name,
                    value,
                    min: tidy(min),
                    max: tidy(max),
                });
            }
        }
    }
    let limit = memory_limit(config, available);
    let maps_mb = g.len() as f64 * BOUND_BYTES_PER_CELL / MB;
    check_memory(
        format!("maps of {} cells are estimated to need", g.len()),
        maps_mb,
        &limit,
    )?;
    let truth = truth.solidified();
    let cell = start_cell(&truth, start)?;
    let res = g.resolution;
    let radius = config.robot.radius;
    // Drivable cells reachable from the start, and the free cells coverage counts.
    let trav = Traversability::new(&truth, radius, cell);
    let field = sweep(&g, &trav.passable, &[g.index(cell)], UNREACHED);
    let drivable: Vec<bool> = (0..g.len())
        .map(|i| trav.traversable[i] && field.reached(i))
        .collect();
    let unknown = OccupancyGrid::filled(g, CellState::Unknown);
    let tracker = CoverageTracker::with_field(&truth, cell, radius, &unknown, &field);
    let reachable_free = tracker.free_total();

    // Targets, on a sub-lattice of `stride` cells.
    let stride = match params.target_spacing_m {
        Some(s) => ((s / res).round() as usize).max(1),
        None => ((reachable_free as f64 / MAX_TARGETS as f64).sqrt().ceil() as usize).max(1),
    };
    let mut target_of = vec![u32::MAX; g.len()];
    let mut target_cells: Vec<usize> = Vec::new();
    for (i, t) in target_of.iter_mut().enumerate() {
        if (i % g.width).is_multiple_of(stride)
            && (i / g.width).is_multiple_of(stride)
            && tracker.is_reachable_free(i)
        {
            *t = target_cells.len() as u32;
            target_cells.push(i);
        }
    }

    // Candidate stations.
    let drivable_count = drivable.iter().filter(|&&d| d).count();
    let step = match params.spacing_m {
        Some(s) => ((s / res).round() as usize).max(1),
        None => {
            let one_metre = (1.0 / res).round().max(1.0) as usize;
            let wide = (drivable_count as f64 / MAX_LATTICE_STATIONS as f64)
                .sqrt()
                .ceil() as usize;
            one_metre.max(wide)
        }
    };
    let lattice = lattice_stations(&g, &drivable, step);
    let offset = (radius / res).ceil() as usize + 1;
    let mut corners = corner_stations(&truth, &drivable, offset);
    if corners.len() > MAX_CORNER_STATIONS {
        let k = corners.len().div_ceil(MAX_CORNER_STATIONS);
        corners = corners.into_iter().step_by(k).collect();
    }
    let mut stations: Vec<(usize, StationOrigin)> = lattice
        .iter()
        .map(|&i| (i, StationOrigin::Lattice))
        .chain(corners.iter().map(|&i| (i, StationOrigin::Corner)))
        .collect();
    stations.sort_by_key(|s| s.0);
    stations.dedup_by_key(|s| s.0);

    // Each station's view of the targets, by the scanner's rule.
    let t = truth.cells();
    let range_cells = config.range_cells();
    let view = |i: usize| {
        let mut seen = Vec::new();
        visible_cells(
            &g,
            g.cell(i),
            range_cells,
            |j| t[j] != CellState::Free,
            |j| {
                if target_of[j] != u32::MAX {
                    seen.push(target_of[j]);
                }
                false
            },
        );
        seen.sort_unstable();
        seen.shrink_to_fit();
        seen
    };
    // Their memory, from a sample: the views (4 bytes a target seen) and the
    // lower bound's work on them (about as much again), beside the maps.
    let sample = stations.len().min(SAMPLED_VIEWS);
    let seen_in_sample: usize = (0..sample)
        .into_par_iter()
        .map(|k| view(stations[k * stations.len() / sample].0).len())
        .sum();
    let per_station = seen_in_sample as f64 / sample.max(1) as f64;
    check_memory(
        format!(
            "maps and views of {} stations (about {} targets each) are estimated to need",
            stations.len(),
            per_station.round()
        ),
        maps_mb + stations.len() as f64 * per_station * 2.0 * 4.0 / MB,
        &limit,
    )?;
    let sets: Vec<Vec<u32>> = stations.par_iter().map(|&(i, _)| view(i)).collect();
    let mut coverable: Vec<u32> = Vec::new();
    {
        let mut hit = vec![false; target_cells.len()];
        for s in &sets {
            for &x in s {
                hit[x as usize] = true;
            }
        }
        coverable.extend((0..target_cells.len() as u32).filter(|&x| hit[x as usize]));
    }
    let n = coverable.len();

    let picks = lazy_greedy(&sets, target_cells.len());
    let nnz: usize = sets.iter().map(Vec::len).sum();
    let iterations = (BOUND_WORK / nnz.max(1)).clamp(20, BOUND_ITERATIONS);
    let needed = |share: f64| ((share * n as f64) - 1e-9).ceil().max(0.0) as usize;
    let levels: Vec<BoundLevel> = BOUND_SHARES
        .iter()
        .map(|&share| {
            let m = needed(share);
            let greedy = picks
                .iter()
                .position(|p| p.covered >= m)
                .map_or(picks.len(), |k| k + 1);
            let lb = lower_bound(&sets, target_cells.len(), &coverable, m, greedy, iterations)
                .min(greedy as f64);
            BoundLevel {
                share,
                greedy_stations: greedy,
                lower_bound: lb,
                lower_bound_stations: (lb - 1e-6).ceil().max(0.0) as usize,
            }
        })
        .collect();
    let cell_m2 = (stride as f64 * res).powi(2);
    let chosen = picks
        .iter()
        .map(|p| {
            let (i, origin) = stations[p.station];
            BoundStation {
                position: g.cell_center(g.cell(i)),
                origin,
                new_targets: p.gain,
                new_m2: p.gain as f64 * cell_m2,
                coverage: if n == 0 {
                    1.0
                } else {
                    p.covered as f64 / n as f64
                },
            }
        })
        .collect();
    Ok(KnownMapBound {
        range_m: config.scanner.range,
        resolution_m: res,
        robot_radius_m: radius,
        start: g.cell_center(cell),
        spacing_m: tidy(step as f64 * res),
        target_spacing_m: tidy(stride as f64 * res),
        lattice_stations: lattice.len(),
        corner_stations: corners.len(),
        reachable_free_cells: reachable_free,
        targets: target_cells.len(),
        coverable_targets: n,
        levels,
        stations: chosen,
    })
}

/// `v` rounded to a nanometre (3 × 0.1 m is 0.30000000000000004).
fn tidy(v: f64) -> f64 {
    (v * 1e9).round() / 1e9
}
