//! Map and record file formats.

mod pnm;
pub mod rosmap;
