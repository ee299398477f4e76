//! Pictures of maps and episodes as PNG (DESIGN.md pipeline stage 9, "Reports").
//!
//! - [`render_episode`]: the final knowledge map of a simulated episode, cropped to
//!   what the episode knows, with world axes, what was missed tinted, the parent's
//!   trajectory, numbered scan positions (labels never overlap: runs of nearby
//!   scans share a range label, omissions are counted in the header), a header
//!   with title, summary and a legend of what is drawn, and a scale bar; with
//!   children, each child's paths and standing places in its own colour, dash
//!   pattern and shape, and the subgoals of every move that needed them.
//! - [`render_episode_large`]: the same at more pixels per cell, for maps whose
//!   normal picture cannot number every scan.
//! - [`render_step`]: one planning step after the paper's Figs. 5–7 (candidates by
//!   score, AND regions, subgoals, every robot's path and the CPS lines of sight),
//!   on a window of the knowledge map the step planned on.
//! - [`render_map`]: a plain preview of an occupancy grid.
//! - [`render_bound`]: the known-map bound's stations on the ground truth.
//!
//! Pictures are drawn in the grid frame (row 0 at the bottom, so north is up for an
//! unrotated map) at an integer number of pixels per cell chosen so that the longer
//! side of the map is about 1600 pixels (at most 2000, and at least one pixel per
//! cell up to 2400 cells); grids longer than 2400 cells are reduced
//! instead, one pixel showing the most salient state of a block of cells (occupied
//! over missed over free over unknown), so thin walls never vanish.

mod axes;
mod bound;
mod canvas;
mod chart;
mod chrome;
mod crop;
mod episode;
mod journey;
mod layout;
mod map;
mod marks;
pub(crate) mod palette;
mod placer;
mod scan_labels;
mod step;
mod targets;
mod team;
pub(crate) mod upright;

pub use self::bound::render_bound;
pub use self::chart::{error_chart, percent, share_percent, Chart, Series, SERIES_COLOURS};
pub use self::episode::{
    pictures_peak_bytes, render_episode, render_episode_large, render_episode_pictures,
};
pub use self::map::render_map;
pub use self::step::{render_step, StepView};

use thiserror::Error;

/// Why a picture could not be drawn.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RenderError {
    /// The grid has no cells.
    #[error("cannot draw an empty map ({width} x {height} cells)")]
    EmptyMap {
        /// Columns.
        width: usize,
        /// Rows.
        height: usize,
    },
    /// The grid's cell width is not a positive finite number.
    #[error("cannot draw a map with resolution {} m: it must be a positive number", cpsplan::config::number(*.0))]
    BadResolution(f64),
    /// The episode's knowledge map and the ground truth differ in size.
    #[error(
        "the knowledge map ({knowledge_width} x {knowledge_height} cells) does not match \
         the ground truth ({truth_width} x {truth_height} cells)"
    )]
    GeometryMismatch {
        /// Ground-truth columns.
        truth_width: usize,
        /// Ground-truth rows.
        truth_height: usize,
        /// Knowledge-map columns.
        knowledge_width: usize,
        /// Knowledge-map rows.
        knowledge_height: usize,
    },
    /// The picture would be too large to allocate.
    #[error("a picture of {width} x {height} pixels is too large to draw")]
    TooLarge {
        /// Picture width in pixels.
        width: u32,
        /// Picture height in pixels.
        height: u32,
    },
    /// PNG encoding failed.
    #[error("PNG encoding failed: {0}")]
    Encode(String),
}

#[cfg(test)]
mod episode_tests;
#[cfg(test)]
mod tests;
