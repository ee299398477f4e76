//! Command line, file formats, rendering and reports for cpsplan.

pub mod args;
pub mod cli;
pub mod commands;
pub mod errors;
pub mod experiment;
pub mod formats;
pub mod html;
pub mod interrupt;
pub mod lock;
pub mod memory;
pub mod render;
pub mod report;
