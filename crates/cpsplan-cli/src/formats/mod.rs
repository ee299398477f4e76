//! Map and record file formats.

pub mod cloud;
pub mod config;
mod png_chunks;
mod pnm;
pub mod readings;
pub mod rosmap;
pub mod targets;
