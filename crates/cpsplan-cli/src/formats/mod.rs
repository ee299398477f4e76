//! Map and record file formats.

pub mod rosmap;
