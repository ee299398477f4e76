//! Map and record file formats.

pub mod config;
mod png_chunks;
mod pnm;
pub mod rosmap;
