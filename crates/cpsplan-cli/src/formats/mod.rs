//! Map and record file formats.

pub mod config;
mod pnm;
pub mod rosmap;
