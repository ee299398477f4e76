//! Map and record file formats.

pub mod cloud;
pub mod config;
pub mod mcap_out;
mod png_chunks;
mod pnm;
pub mod readings;
pub mod ros2;
pub mod ros2_in;
pub mod ros_out;
pub mod rosmap;
pub mod targets;
pub mod tidy;
