//! The memory a simulated episode needs, estimated before it allocates anything
//! of the map's size (docs/PERFORMANCE.md "Memory").
//!
//! In: the planning grid's size and the configuration. Out: a [`MemoryEstimate`]
//! of the process's peak resident memory, for any number of scans.
//!
//! The planning structures of a step (knowledge, traversability, travel field,
//! gain field, border and band; with children also their terrain, the GVD and the
//! sight fields) are a fixed number of bytes per cell; the records grow by a
//! roughly fixed amount per scan (the band samples, the candidates, the paths and
//! the 3D model's per-point distances). The pictures are drawn after the run,
//! when the planning structures are gone. The constants come from measured peaks
//! of the resident memory (`VmHWM`, which also counts what the allocator
//! keeps): the per-cell ones from the campus map (6.07 million cells, 307
//! scans) and one team step on a 10⁸-cell site (1 km × 1 km at 0.1 m,
//! everything known: 3.84 GB against 3.84 GB for a step's structures). An
//! episode with children also keeps the GVD's obstacle side over the whole
//! grid across scans, counted from its buffers' sizes
//! ([`KEPT_TEAM_BYTES_PER_CELL`]), and every episode the gain views' cell
//! classes ([`VIEW_CLASS_BYTES_PER_CELL`]). docs/PERFORMANCE.md lists the estimate
//! against the measured peak on every map tried: within about 15 % on the
//! large maps, up to half high on small ones, and short with children on open
//! ground, where the Visibility-Graph search's lists and queue (not counted
//! here) grow with the corners in view. The pictures' size is the caller's to
//! give ([`MemoryEstimate::with_pictures`]): it depends
//! on how they are drawn.

use crate::config::Config;
use crate::sensing::{MAX_KEPT_CELLS, MAX_KEPT_VIEWS};

/// Resident memory of the program whatever the map: code, libraries, thread
/// stacks, the allocator's arenas and the view caches of a step.
pub const FIXED_BYTES: u64 = 24 << 20;
/// Bytes per planning cell when the parent plans alone.
pub const PARENT_BYTES_PER_CELL: u64 = 32;
/// Bytes per planning cell with children (their terrain, GVD and sight fields).
pub const TEAM_BYTES_PER_CELL: u64 = 40;
/// Bytes per planning cell an episode with children keeps across scans besides
/// a step's structures: the GVD's obstacle side over the whole grid
/// (`motion::VoronoiField`: the obstacle flags, the nearest obstacle cell and
/// its squared distance, its clearance, the column pass's nearest row, the
/// component labels and the two straddling-pair flags: 1 + 8 + 4 + 4 + 4 + 4 +
/// 2 bytes).
pub const KEPT_TEAM_BYTES_PER_CELL: u64 = 27;
/// Bytes per planning cell the gain estimate keeps across scans for its views'
/// sweep by runs: each cell's class in rows and in columns (1 + 1 bytes,
/// `sensing::NearField`).
pub const VIEW_CLASS_BYTES_PER_CELL: u64 = 2;
/// Bytes the gain views kept across scans take at most, whatever the map: 4
/// a near cell, and about 128 a view for its entry and counts
/// (`sensing::GainEstimate`'s kept views).
pub const KEPT_VIEWS_BYTES: u64 = 4 * MAX_KEPT_CELLS as u64 + 128 * MAX_KEPT_VIEWS as u64;
/// Bytes of records per scan at the paper's 20 m scanner range; they grow with
/// the range (a scan sees more border and more wall).
pub const SCAN_BYTES_AT_20_M: u64 = 150_000;
/// Bytes per cell kept while the pictures are drawn: the ground truth, the
/// knowledge and the coverage class of every cell.
pub const PICTURE_BYTES_PER_CELL: u64 = 3;

/// An estimate of a simulated episode's peak resident memory: the planning
/// structures while it runs, or the pictures drawn after it (with the knowledge,
/// the ground truth and the coverage classes), whichever is larger, plus the
/// records of its scans.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryEstimate {
    /// Planning cells.
    pub cells: u64,
    /// Bytes the planning structures take, independent of the scans.
    pub planning_bytes: u64,
    /// Bytes the pictures drawn after the run take at their largest (0 unless
    /// set with [`Self::with_pictures`]).
    pub pictures_bytes: u64,
    /// Bytes the records add per scan.
    pub per_scan_bytes: u64,
}

impl MemoryEstimate {
    /// The estimate for an episode on a planning grid of `width` × `height`
    /// cells under `config` (with children when `config.children.count > 0`,
    /// and then with what the episode keeps across scans).
    pub fn for_grid(width: usize, height: usize, config: &Config) -> Self {
        let cells = (width as u64).saturating_mul(height as u64);
        let per_cell = VIEW_CLASS_BYTES_PER_CELL
            + if config.children.count > 0 {
                TEAM_BYTES_PER_CELL + KEPT_TEAM_BYTES_PER_CELL
            } else {
                PARENT_BYTES_PER_CELL
            };
        let range = (config.scanner.range / 20.0).clamp(0.05, 1e6);
        Self {
            cells,
            planning_bytes: cells
                .saturating_mul(per_cell)
                .saturating_add(KEPT_VIEWS_BYTES),
            pictures_bytes: 0,
            per_scan_bytes: (SCAN_BYTES_AT_20_M as f64 * range) as u64,
        }
    }

    /// The estimate with pictures of `bytes` at their largest.
    pub fn with_pictures(self, bytes: u64) -> Self {
        Self {
            pictures_bytes: bytes,
            ..self
        }
    }

    /// Estimated peak bytes of an episode of `scans` scans.
    pub fn bytes(&self, scans: usize) -> u64 {
        let pictures = self
            .pictures_bytes
            .saturating_add(self.cells.saturating_mul(PICTURE_BYTES_PER_CELL));
        FIXED_BYTES
            .saturating_add(self.planning_bytes.max(pictures))
            .saturating_add(self.per_scan_bytes.saturating_mul(scans as u64))
    }

    /// [`Self::bytes`] in MB (2²⁰ bytes).
    pub fn mb(&self, scans: usize) -> f64 {
        self.bytes(scans) as f64 / (1u64 << 20) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_team_costs_more_and_scans_add_up() {
        let mut config = Config::default();
        let team = MemoryEstimate::for_grid(800, 600, &config);
        config.children.count = 0;
        let alone = MemoryEstimate::for_grid(800, 600, &config);
        assert_eq!(team.cells, 480_000);
        assert!(team.bytes(0) > alone.bytes(0));
        assert_eq!(
            alone.bytes(0),
            FIXED_BYTES
                + 480_000 * (PARENT_BYTES_PER_CELL + VIEW_CLASS_BYTES_PER_CELL)
                + KEPT_VIEWS_BYTES
        );
        // Pictures count only where they outweigh the planning.
        assert_eq!(alone.with_pictures(1_000).bytes(0), alone.bytes(0));
        let big = alone.with_pictures(80 << 20);
        assert_eq!(big.bytes(0), FIXED_BYTES + (80 << 20) + 3 * 480_000);
        assert_eq!(alone.bytes(10) - alone.bytes(0), 10 * alone.per_scan_bytes);
        config.scanner.range = 40.0;
        assert_eq!(
            MemoryEstimate::for_grid(800, 600, &config).per_scan_bytes,
            2 * SCAN_BYTES_AT_20_M
        );
    }

    #[test]
    fn a_square_kilometre_at_a_decimetre_needs_gigabytes() {
        let config = Config::default();
        let e = MemoryEstimate::for_grid(10_000, 10_000, &config);
        assert!((6_000.0..7_000.0).contains(&e.mb(0)), "{}", e.mb(0));
        // Sizes beyond any machine saturate instead of wrapping.
        let huge = MemoryEstimate::for_grid(usize::MAX, usize::MAX, &config);
        assert_eq!(huge.bytes(usize::MAX), u64::MAX);
    }
}
