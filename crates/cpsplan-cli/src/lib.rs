//! Command line, file formats, rendering and reports for cpsplan.

pub mod formats;
pub mod render;
