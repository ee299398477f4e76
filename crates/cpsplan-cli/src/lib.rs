//! Command line, file formats, rendering and reports for cpsplan.

pub mod cli;
pub mod commands;
pub mod experiment;
pub mod formats;
pub mod html;
pub mod render;
pub mod report;
