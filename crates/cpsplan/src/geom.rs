//! Small geometric value types shared by every stage: world points and grid cells.

use serde::{Deserialize, Serialize};

/// A point in the world frame (metres; x right, y up).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Point {
    /// x coordinate in metres.
    pub x: f64,
    /// y coordinate in metres.
    pub y: f64,
}

impl Point {
    /// A point from its coordinates.
    pub const fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }

    /// Euclidean distance to `other`.
    pub fn distance(self, other: Point) -> f64 {
        (self.x - other.x).hypot(self.y - other.y)
    }
}

/// A grid cell by its column `x` and row `y` (row 0 is the bottom of the map).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Cell {
    /// Column, growing with world x.
    pub x: usize,
    /// Row, growing with world y.
    pub y: usize,
}

impl Cell {
    /// A cell from its column and row.
    pub const fn new(x: usize, y: usize) -> Self {
        Self { x, y }
    }
}

/// Length of a polyline in metres.
pub fn polyline_length(points: &[Point]) -> f64 {
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}
