//! The valid range of every parameter, and the one check of a whole
//! configuration against them ([`Config::validate`]) and of a grid's size and
//! placement against the limits ([`Config::check_grid`]).
//!
//! Every bound is finite and documented in [`BOUNDS`] (docs/USER-GUIDE.md
//! "Limits" lists them): with every parameter inside its bounds, no quantity the
//! planner derives from them (ranges in cells and their squares, sample and
//! cluster counts, grid sizes) can overflow or exhaust the machine.

use thiserror::Error;

use super::Config;

/// One parameter's valid range, `min ≤ value ≤ max` (both inclusive).
#[derive(Debug, Clone, Copy)]
pub struct Bound {
    /// The parameter's path in the TOML configuration, e.g. `scanner.range`.
    pub key: &'static str,
    /// Least valid value.
    pub min: f64,
    /// Greatest valid value.
    pub max: f64,
    /// Unit, for messages (`m`, `cells`, ...; empty for none).
    pub unit: &'static str,
    /// Whether the parameter is a whole number.
    pub whole: bool,
    /// The parameter's value in a configuration (`None`: an optional one that is
    /// absent).
    pub get: fn(&Config) -> Option<f64>,
    /// Sets the parameter (whole numbers are truncated; used by tests and tools).
    pub set: fn(&mut Config, f64),
}

/// Longest side of any grid, in cells.
pub const MAX_GRID_SIDE: usize = 1 << 20;

/// Most points of one wall column of the registered model
/// (`model.wall_height / model.vertical_step`).
pub const MAX_WALL_SAMPLES: f64 = 10_000.0;

/// Greatest distance of any map coordinate from the world origin, metres: it
/// keeps cell positions exact to a millionth of a cell at the finest resolution.
pub const MAX_COORDINATE_M: f64 = 1e8;

macro_rules! real {
    ($key:literal, $min:expr, $max:expr, $unit:literal, $($field:ident).+) => {
        Bound {
            key: $key,
            min: $min,
            max: $max,
            unit: $unit,
            whole: false,
            get: |c| Some(c.$($field).+),
            set: |c, v| c.$($field).+ = v,
        }
    };
}

macro_rules! optional {
    ($key:literal, $min:expr, $max:expr, $unit:literal, $($field:ident).+) => {
        Bound {
            key: $key,
            min: $min,
            max: $max,
            unit: $unit,
            whole: false,
            get: |c| c.$($field).+,
            set: |c, v| c.$($field).+ = Some(v),
        }
    };
}

macro_rules! count {
    ($key:literal, $min:expr, $max:expr, $unit:literal, $($field:ident).+) => {
        Bound {
            key: $key,
            min: $min,
            max: $max,
            unit: $unit,
            whole: true,
            get: |c| Some(c.$($field).+ as f64),
            set: |c, v| c.$($field).+ = v as usize,
        }
    };
}

/// Every bounded parameter (the seed takes any value).
pub const BOUNDS: &[Bound] = &[
    real!("resolution", 0.001, 10.0, "m", resolution),
    real!("scanner.range", 0.01, 10_000.0, "m", scanner.range),
    real!("robot.radius", 0.0, 10.0, "m", robot.radius),
    real!("parent.alpha", 0.0, 1e6, "", parent.alpha),
    real!("parent.beta", 0.0, 1e6, "", parent.beta),
    real!("parent.gamma", 0.0, 1e6, "", parent.gamma),
    real!("parent.band_width", 0.01, 1_000.0, "m", parent.band_width),
    real!(
        "parent.samples_per_m2",
        0.001,
        10_000.0,
        "per m²",
        parent.samples_per_m2
    ),
    count!("parent.max_samples", 1.0, 1e6, "", parent.max_samples),
    real!("parent.cluster_area", 0.01, 1e8, "m²", parent.cluster_area),
    count!(
        "parent.max_clusters",
        1.0,
        10_000.0,
        "",
        parent.max_clusters
    ),
    count!(
        "parent.kmeans_iterations",
        1.0,
        10_000.0,
        "",
        parent.kmeans_iterations
    ),
    count!(
        "parent.min_gain_cells",
        1.0,
        1e9,
        "cells",
        parent.min_gain_cells
    ),
    real!("parent.min_gain_m2", 0.0, 1e8, "m²", parent.min_gain_m2),
    count!(
        "parent.tour_lookahead",
        1.0,
        1000.0,
        "",
        parent.tour_lookahead
    ),
    real!("parent.refine_step", 0.0, 100.0, "m", parent.refine_step),
    count!(
        "parent.calibration_window",
        0.0,
        1e6,
        "",
        parent.calibration_window
    ),
    real!(
        "parent.calibration_floor",
        1e-3,
        2.0,
        "",
        parent.calibration_floor
    ),
    real!("time.scan_s", 0.0, 1e6, "s", time.scan_s),
    real!("time.measure_s", 0.0, 1e5, "s", time.measure_s),
    real!("time.speed_m_s", 1e-3, 100.0, "m/s", time.speed_m_s),
    real!("parent.min_gain_share", 0.0, 1.0, "", parent.min_gain_share),
    real!("parent.unknown_depth", 0.0, 1e4, "m", parent.unknown_depth),
    real!(
        "parent.frontier_potential_scale",
        0.0,
        1e6,
        "",
        parent.frontier_potential_scale
    ),
    real!(
        "parent.frontier_gain_scale",
        0.0,
        1e6,
        "",
        parent.frontier_gain_scale
    ),
    real!(
        "parent.frontier_min_size",
        0.0,
        1e3,
        "m",
        parent.frontier_min_size
    ),
    real!("parent.gain_scale", 1e-6, 1e6, "", parent.gain_scale),
    real!("parent.travel_jitter", 0.0, 1.0, "", parent.travel_jitter),
    real!("parent.horizon", 0.0, 1.0e6, "m", parent.horizon),
    count!(
        "parent.min_frontier_cells",
        1.0,
        1e9,
        "cells",
        parent.min_frontier_cells
    ),
    count!(
        "parent.error_candidates",
        1.0,
        64.0,
        "",
        parent.error_candidates
    ),
    count!("children.count", 0.0, 8.0, "", children.count),
    real!("children.radius", 0.0, 10.0, "m", children.radius),
    real!("children.alpha_c", 0.0, 1e6, "", children.alpha_c),
    real!("children.beta_c", 0.0, 1e6, "", children.beta_c),
    real!(
        "children.theta_t_deg",
        0.0,
        180.0,
        "°",
        children.theta_t_deg
    ),
    real!("children.d_t", 0.0, 10_000.0, "m", children.d_t),
    real!("children.min_range", 0.0, 10_000.0, "m", children.min_range),
    optional!(
        "children.max_range",
        0.01,
        10_000.0,
        "m",
        children.max_range
    ),
    real!(
        "children.clearance_cap",
        0.01,
        1_000.0,
        "m",
        children.clearance_cap
    ),
    real!(
        "children.sight_clearance",
        0.0,
        10.0,
        "m",
        children.sight_clearance
    ),
    real!(
        "children.marker_radius",
        0.0,
        10.0,
        "m",
        children.marker_radius
    ),
    real!(
        "children.travel_weight",
        0.0,
        1e6,
        "mm² per m",
        children.travel_weight
    ),
    optional!(
        "instrument.distance_sigma_mm",
        0.0,
        10_000.0,
        "mm",
        instrument.distance_sigma_mm
    ),
    optional!(
        "instrument.distance_ppm",
        0.0,
        1e5,
        "ppm",
        instrument.distance_ppm
    ),
    optional!(
        "instrument.angle_sigma_arcsec",
        0.0,
        3_600.0,
        "″",
        instrument.angle_sigma_arcsec
    ),
    optional!(
        "instrument.min_range",
        0.0,
        10_000.0,
        "m",
        instrument.min_range
    ),
    optional!(
        "instrument.max_range",
        0.01,
        10_000.0,
        "m",
        instrument.max_range
    ),
    real!(
        "instrument.instrument_height",
        0.0,
        100.0,
        "m",
        instrument.instrument_height
    ),
    real!(
        "instrument.marker_height",
        0.0,
        100.0,
        "m",
        instrument.marker_height
    ),
    count!(
        "accuracy.monte_carlo_runs",
        0.0,
        100_000.0,
        "",
        accuracy.monte_carlo_runs
    ),
    real!("model.wall_height", 0.01, 1_000.0, "m", model.wall_height),
    real!(
        "model.vertical_step",
        0.001,
        100.0,
        "m",
        model.vertical_step
    ),
    real!(
        "model.scanner_height",
        0.0,
        1_000.0,
        "m",
        model.scanner_height
    ),
    optional!(
        "model.range_sigma_mm",
        0.0,
        1_000.0,
        "mm",
        model.range_sigma_mm
    ),
    count!("mission.max_scans", 1.0, 100_000.0, "", mission.max_scans),
    count!(
        "mission.stop_window",
        0.0,
        100_000.0,
        "",
        mission.stop_window
    ),
    real!("mission.stop_share", 0.0, 1.0, "", mission.stop_share),
    optional!("mission.max_sigma_m", 1e-6, 1e6, "m", mission.max_sigma_m),
    count!("targets.max", 0.0, 200.0, "targets", targets.max),
    count!(
        "limits.max_grid_cells",
        1.0,
        4e9,
        "cells",
        limits.max_grid_cells
    ),
    count!(
        "limits.max_cloud_points",
        1.0,
        1e10,
        "points",
        limits.max_cloud_points
    ),
    real!("limits.max_memory_mb", 0.0, 1e9, "MB", limits.max_memory_mb),
];

/// Why a configuration (or a grid under it) is not valid. Every variant names
/// the parameter.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ConfigError {
    /// A parameter outside its bounds (or not a number).
    #[error("`{key}` must be {} (got {})", range_text(*.min, *.max, .unit, *.whole), number(*.value))]
    OutOfRange {
        /// The parameter.
        key: &'static str,
        /// Its value.
        value: f64,
        /// Least valid value.
        min: f64,
        /// Greatest valid value.
        max: f64,
        /// Unit.
        unit: &'static str,
        /// Whether the parameter is a whole number.
        whole: bool,
    },
    /// Two parameters that contradict each other.
    #[error("`{key}` = {} {rule} `{other}` = {}", number(*.value), number(*.other_value))]
    Conflict {
        /// The parameter reported (the one a user most likely set).
        key: &'static str,
        /// Its value.
        value: f64,
        /// What it must satisfy against the other.
        rule: &'static str,
        /// The other parameter.
        other: &'static str,
        /// Its value.
        other_value: f64,
    },
    /// A target or control point that cannot be used.
    #[error("{what}")]
    Target {
        /// `targets`.
        key: &'static str,
        /// The problem, naming the point.
        what: String,
    },
    /// A grid larger than the limits, or placed too far from the world origin.
    #[error("{what}")]
    Grid {
        /// The parameter that sets the limit (`limits.max_grid_cells`,
        /// `limits.max_memory_mb`, `resolution`).
        key: &'static str,
        /// The problem, with the figures.
        what: String,
    },
}

impl ConfigError {
    /// The parameter the error is about.
    pub fn key(&self) -> &'static str {
        match self {
            ConfigError::OutOfRange { key, .. }
            | ConfigError::Conflict { key, .. }
            | ConfigError::Grid { key, .. }
            | ConfigError::Target { key, .. } => key,
        }
    }
}

/// A number as a person reads it: plain for everyday magnitudes, scientific
/// (`1e300`) for the rest, never three hundred digits.
pub fn number(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || (1e-4..1e9).contains(&a) {
        let s = format!("{v:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    } else if v.is_finite() {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

/// A derived quantity for messages, to four significant digits beyond a
/// million (`1.845e19`), as [`number`] below.
pub fn approx(v: f64) -> String {
    if !v.is_finite() || v.abs() < 1e6 {
        return number(v);
    }
    let s = format!("{v:.3e}");
    match s.split_once('e') {
        Some((mantissa, exp)) if mantissa.contains('.') => {
            let m = mantissa.trim_end_matches('0').trim_end_matches('.');
            format!("{m}e{exp}")
        }
        _ => s,
    }
}

fn range_text(min: f64, max: f64, unit: &str, whole: bool) -> String {
    let kind = if whole { "a whole number" } else { "a number" };
    let unit = if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    };
    format!("{kind} from {} to {}{unit}", number(min), number(max))
}

impl Config {
    /// Checks every parameter against its bounds ([`BOUNDS`]) and the parameters
    /// that depend on each other: the band is wider than the robot, the scanner
    /// reaches past a few cells, and with children the link range (children's
    /// and instrument's minimum, and maximum, which defaults to the scanner's
    /// range) is not empty.
    pub fn validate(&self) -> Result<(), ConfigError> {
        for b in BOUNDS {
            let Some(v) = (b.get)(self) else { continue };
            if !(v.is_finite() && v >= b.min && v <= b.max) {
                return Err(ConfigError::OutOfRange {
                    key: b.key,
                    value: v,
                    min: b.min,
                    max: b.max,
                    unit: b.unit,
                    whole: b.whole,
                });
            }
        }
        let conflict = |key, value, rule, other, other_value| {
            Err(ConfigError::Conflict {
                key,
                value,
                rule,
                other,
                other_value,
            })
        };
        if self.robot.radius >= self.parent.band_width {
            return conflict(
                "robot.radius",
                self.robot.radius,
                "must be less than",
                "parent.band_width",
                self.parent.band_width,
            );
        }
        if self.scanner.range < 3.0 * self.resolution {
            return conflict(
                "scanner.range",
                self.scanner.range,
                "must be at least 3 ×",
                "resolution",
                self.resolution,
            );
        }
        let i = &self.instrument;
        if let (Some(lo), Some(hi)) = (i.min_range, i.max_range) {
            if lo >= hi {
                return conflict(
                    "instrument.min_range",
                    lo,
                    "must be less than",
                    "instrument.max_range",
                    hi,
                );
            }
        }
        let m = &self.model;
        if m.wall_height > MAX_WALL_SAMPLES * m.vertical_step {
            return conflict(
                "model.wall_height",
                m.wall_height,
                "must be at most 10000 ×",
                "model.vertical_step",
                m.vertical_step,
            );
        }
        if self.children.count > 0 {
            self.check_link_range()?;
        }
        self.targets.check()
    }

    /// With children: the shortest link must be shorter than the longest.
    fn check_link_range(&self) -> Result<(), ConfigError> {
        let (imin, imax) = self.instrument.range_m();
        let c = &self.children;
        let (min_key, min) = if c.min_range >= imin {
            ("children.min_range", c.min_range)
        } else {
            ("instrument.min_range", imin)
        };
        let (max_key, max) = match c.max_range {
            Some(m) if m <= imax => ("children.max_range", m),
            None if self.scanner.range <= imax => ("scanner.range", self.scanner.range),
            _ => ("instrument.max_range", imax),
        };
        if min >= max {
            return Err(ConfigError::Conflict {
                key: min_key,
                value: min,
                rule: "(the shortest parent–child link) must be less than",
                other: max_key,
                other_value: max,
            });
        }
        Ok(())
    }

    /// Checks a grid of `width` × `height` cells of `resolution` metres with its
    /// lower-left corner at `origin` (metres) against the limits: at most
    /// `limits.max_grid_cells` cells and [`MAX_GRID_SIDE`] per side, and every
    /// corner within [`MAX_COORDINATE_M`] of the world origin. Call it before
    /// allocating the grid.
    pub fn check_grid(
        &self,
        width: u64,
        height: u64,
        resolution: f64,
        origin: (f64, f64),
    ) -> Result<(), ConfigError> {
        let grid = |key, what| Err(ConfigError::Grid { key, what });
        let cells = width.saturating_mul(height);
        let size = format!(
            "{} × {} cells of {} m ({} m × {} m)",
            approx(width as f64),
            approx(height as f64),
            number(resolution),
            approx(width as f64 * resolution),
            approx(height as f64 * resolution)
        );
        if width == 0 || height == 0 {
            return grid("resolution", format!("the map has no cells: {size}"));
        }
        if cells > self.limits.max_grid_cells as u64 {
            return grid(
                "limits.max_grid_cells",
                format!(
                    "the grid would have {} cells ({size}), more than \
                     `limits.max_grid_cells` = {}; choose a coarser resolution or raise the limit",
                    // The product itself: `cells` saturates at 1.8e19.
                    approx(width as f64 * height as f64),
                    number(self.limits.max_grid_cells as f64)
                ),
            );
        }
        if width.max(height) > MAX_GRID_SIDE as u64 {
            return grid(
                "resolution",
                format!("the grid would be {size}, longer than {MAX_GRID_SIDE} cells on a side"),
            );
        }
        let far = [
            origin.0,
            origin.1,
            origin.0 + width as f64 * resolution,
            origin.1 + height as f64 * resolution,
        ]
        .into_iter()
        .map(f64::abs)
        .fold(0.0, |a, b| if b.is_nan() || b > a { b } else { a });
        if far.is_nan() || far > MAX_COORDINATE_M {
            return grid(
                "origin",
                format!(
                    "the map reaches {} m from the world origin, beyond the {} m at which \
                     cell positions stay exact; shift its origin",
                    approx(far),
                    approx(MAX_COORDINATE_M)
                ),
            );
        }
        Ok(())
    }

    /// Checks a run estimated to need `needed_mb` MB against `limits.max_memory_mb`,
    /// or, when that is 0, against `available`: the megabytes the run may use
    /// and what sets them (the machine's memory, a cgroup or an address-space
    /// limit), where known. Call it before the run allocates its planning
    /// structures.
    pub fn check_memory(
        &self,
        needed_mb: f64,
        available: Option<(f64, &str)>,
    ) -> Result<(), ConfigError> {
        let (limit, what) = if self.limits.max_memory_mb > 0.0 {
            (self.limits.max_memory_mb, "`limits.max_memory_mb`")
        } else {
            match available {
                Some(a) => a,
                None => return Ok(()),
            }
        };
        if needed_mb > limit {
            return Err(ConfigError::Grid {
                key: "limits.max_memory_mb",
                what: format!(
                    "the run is estimated to need {} MB, more than {what} ({} MB); \
                     choose a coarser resolution or a smaller map, or set \
                     `limits.max_memory_mb`",
                    approx(needed_mb.ceil()),
                    approx(limit.floor())
                ),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_default_is_inside_its_bounds_and_every_key_is_unique() {
        let c = Config::default();
        let mut keys: Vec<&str> = BOUNDS.iter().map(|b| b.key).collect();
        keys.sort_unstable();
        let n = keys.len();
        keys.dedup();
        assert_eq!(keys.len(), n, "duplicate key");
        for b in BOUNDS {
            assert!(
                b.min < b.max && b.min.is_finite() && b.max.is_finite(),
                "{}",
                b.key
            );
            if let Some(v) = (b.get)(&c) {
                assert!((b.min..=b.max).contains(&v), "{} = {v}", b.key);
            }
        }
    }

    #[test]
    fn set_and_get_address_the_same_parameter() {
        for b in BOUNDS {
            let mut c = Config::default();
            let v = if b.whole { b.max.floor() } else { b.max };
            (b.set)(&mut c, v);
            assert_eq!((b.get)(&c), Some(v), "{}", b.key);
        }
    }

    #[test]
    fn numbers_print_short() {
        assert_eq!(number(1e300), "1e300");
        assert_eq!(number(20.0), "20");
        assert_eq!(number(0.1), "0.1");
        assert_eq!(number(-2.5e-7), "-2.5e-7");
        assert_eq!(number(f64::NAN), "NaN");
        assert_eq!(number(0.0), "0");
        assert_eq!(approx(18446744073709551615.0), "1.845e19");
        assert_eq!(approx(4e10), "4e10");
        assert_eq!(approx(1234.5), "1234.5");
    }

    #[test]
    fn messages_name_the_key_the_value_and_the_range() {
        let mut c = Config::default();
        c.children.max_range = Some(1e300);
        let e = c.validate().unwrap_err();
        assert_eq!(e.key(), "children.max_range");
        assert_eq!(
            e.to_string(),
            "`children.max_range` must be a number from 0.01 to 10000 m (got 1e300)"
        );
    }

    #[test]
    fn cross_checks_name_both_parameters() {
        let mut c = Config::default();
        c.robot.radius = 5.0;
        c.parent.band_width = 1.5;
        let e = c.validate().unwrap_err();
        assert_eq!(e.key(), "robot.radius");
        assert!(e.to_string().contains("parent.band_width"), "{e}");

        let mut c = Config::default();
        c.children.min_range = 30.0; // scanner range 20 m
        let e = c.validate().unwrap_err();
        assert_eq!(e.key(), "children.min_range");
        assert!(e.to_string().contains("scanner.range"), "{e}");

        c.children.count = 0; // the parent alone needs no link
        c.validate().unwrap();

        let mut c = Config::default();
        c.children.max_range = Some(1.0); // below the 1.3 m minimum
        assert_eq!(c.validate().unwrap_err().key(), "children.min_range");

        let mut c = Config {
            resolution: 50.0,
            ..Config::default()
        };
        assert!(c.validate().is_err());
        c.resolution = 10.0;
        assert_eq!(c.validate().unwrap_err().key(), "scanner.range");
    }

    #[test]
    fn runs_beyond_the_memory_limit_are_refused() {
        let mut c = Config::default();
        let machine = "the memory this machine has available";
        c.check_memory(5_000.0, Some((8_000.0, machine))).unwrap();
        let e = c
            .check_memory(5_000.0, Some((4_000.0, machine)))
            .unwrap_err();
        assert_eq!(e.key(), "limits.max_memory_mb");
        assert!(
            e.to_string()
                .contains("5000 MB, more than the memory this machine has available (4000 MB)"),
            "{e}"
        );
        // Without a limit or a known amount, nothing is refused.
        c.check_memory(1e9, None).unwrap();
        // A set limit takes the place of the machine's memory.
        c.limits.max_memory_mb = 100.0;
        let e = c.check_memory(150.0, Some((1e6, machine))).unwrap_err();
        assert!(
            e.to_string().contains("`limits.max_memory_mb` (100 MB)"),
            "{e}"
        );
        c.check_memory(90.0, None).unwrap();
    }

    #[test]
    fn grids_beyond_the_limits_are_refused_before_allocation() {
        let c = Config::default();
        c.check_grid(10_000, 10_000, 0.1, (0.0, 0.0)).unwrap(); // 1 km × 1 km
        let e = c.check_grid(80_000, 60_000, 0.001, (0.0, 0.0)).unwrap_err();
        assert_eq!(e.key(), "limits.max_grid_cells");
        assert!(e.to_string().contains("4.8e9"), "{e}");
        let e = c
            .check_grid(u64::MAX, u64::MAX, 0.1, (0.0, 0.0))
            .unwrap_err();
        assert_eq!(e.key(), "limits.max_grid_cells");
        let e = c.check_grid(10, 10, 0.1, (1e16, 0.0)).unwrap_err();
        assert_eq!(e.key(), "origin");
        assert!(c.check_grid(10, 10, 0.1, (f64::NAN, 0.0)).is_err());
        assert!(c.check_grid(0, 10, 0.1, (0.0, 0.0)).is_err());
        let mut wide = Config::default();
        wide.limits.max_grid_cells = 4_000_000_000;
        assert_eq!(
            wide.check_grid(2_000_000, 1, 0.1, (0.0, 0.0))
                .unwrap_err()
                .key(),
            "resolution"
        );
    }
}
