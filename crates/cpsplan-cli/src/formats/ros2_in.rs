//! The ROS 2 messages a live campaign takes in (`cpsplan ros`,
//! docs/USER-GUIDE.md "Robot software"): a scan as `sensor_msgs/PointCloud2`,
//! as any ROS 2 driver publishes it, decoded to points whatever its layout.

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// `builtin_interfaces/Time`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds within the second.
    pub nanosec: u32,
}

/// `std_msgs/Header`.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Header {
    /// When the data was taken.
    pub stamp: Time,
    /// The frame the data is in.
    pub frame_id: String,
}

/// `sensor_msgs/PointField`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct PointField {
    /// The field's name (`x`, `y`, `z`, `intensity`, …).
    pub name: String,
    /// Its offset in a point, bytes.
    pub offset: u32,
    /// Its type: 1–6 integers, 7 float32, 8 float64.
    pub datatype: u8,
    /// Elements in the field.
    pub count: u32,
}

/// `sensor_msgs/PointCloud2`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointCloud2 {
    /// Stamp and frame.
    pub header: Header,
    /// Rows (1 for an unordered cloud).
    pub height: u32,
    /// Points in a row.
    pub width: u32,
    /// The layout of a point.
    pub fields: Vec<PointField>,
    /// Whether the numbers are big-endian.
    pub is_bigendian: bool,
    /// Bytes in a point.
    pub point_step: u32,
    /// Bytes in a row.
    pub row_step: u32,
    /// The points.
    pub data: Vec<u8>,
    /// Whether every point is finite.
    pub is_dense: bool,
}

/// A `PointCloud2` that cannot be read as points.
#[derive(Debug, Error, PartialEq, Eq)]
#[error("PointCloud2: {0}")]
pub struct BadCloud(String);

/// `sensor_msgs/PointField` FLOAT32.
const FLOAT32: u8 = 7;
/// `sensor_msgs/PointField` FLOAT64.
const FLOAT64: u8 = 8;

impl PointCloud2 {
    /// The finite points `(x, y, z)` (float32 or float64 fields, either byte
    /// order), at most `max_points` of them.
    pub fn points(&self, max_points: usize) -> Result<Vec<[f64; 3]>, BadCloud> {
        let bad = |m: String| BadCloud(m);
        let step = self.point_step as usize;
        let field = |name: &str| -> Result<(usize, u8), BadCloud> {
            let f = self
                .fields
                .iter()
                .find(|f| f.name == name)
                .ok_or_else(|| bad(format!("no `{name}` field")))?;
            let size = match f.datatype {
                FLOAT32 => 4,
                FLOAT64 => 8,
                t => {
                    return Err(bad(format!(
                        "field `{name}` has type {t}; float32 (7) or float64 (8) is needed"
                    )))
                }
            };
            if f.offset as usize + size > step {
                return Err(bad(format!(
                    "field `{name}` ends past the point ({} bytes)",
                    self.point_step
                )));
            }
            Ok((f.offset as usize, f.datatype))
        };
        let xyz = [field("x")?, field("y")?, field("z")?];
        let count = (self.width as usize)
            .checked_mul(self.height as usize)
            .filter(|&n| n <= max_points)
            .ok_or_else(|| {
                bad(format!(
                    "{} × {} points, more than the limit of {max_points}",
                    self.width, self.height
                ))
            })?;
        let row = (self.width as usize)
            .checked_mul(step)
            .filter(|&r| r <= self.row_step as usize)
            .ok_or_else(|| bad(format!("row_step {} is short of its points", self.row_step)))?;
        let needed = (self.row_step as usize)
            .checked_mul(self.height as usize)
            .ok_or_else(|| bad("the cloud's size overflows".into()))?;
        if self.data.len() < needed {
            return Err(bad(format!(
                "{} bytes of data for {} rows of {} bytes",
                self.data.len(),
                self.height,
                self.row_step
            )));
        }
        let read = |bytes: &[u8], (offset, kind): (usize, u8)| -> f64 {
            let big = self.is_bigendian;
            if kind == FLOAT32 {
                let b: [u8; 4] = [0, 1, 2, 3].map(|i| bytes[offset + i]);
                f64::from(if big {
                    f32::from_be_bytes(b)
                } else {
                    f32::from_le_bytes(b)
                })
            } else {
                let b: [u8; 8] = [0, 1, 2, 3, 4, 5, 6, 7].map(|i| bytes[offset + i]);
                if big {
                    f64::from_be_bytes(b)
                } else {
                    f64::from_le_bytes(b)
                }
            }
        };
        let mut points = Vec::with_capacity(count);
        for r in 0..self.height as usize {
            let start = r * self.row_step as usize;
            for point in self.data[start..start + row].chunks_exact(step.max(1)) {
                let p = xyz.map(|f| read(point, f));
                if p.iter().all(|v| v.is_finite()) {
                    points.push(p);
                }
            }
        }
        Ok(points)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(name: &str, offset: u32, datatype: u8) -> PointField {
        PointField {
            name: name.into(),
            offset,
            datatype,
            count: 1,
        }
    }

    /// An organised cloud of float64 big-endian points with an intensity
    /// between and padding at each row's end.
    fn organised(points: &[[f64; 3]], width: u32) -> PointCloud2 {
        let step = 8 * 3 + 4;
        let row_step = width * step + 6;
        let height = points.len() as u32 / width;
        let mut data = Vec::new();
        for row in points.chunks(width as usize) {
            for p in row {
                data.extend_from_slice(&p[0].to_be_bytes());
                data.extend_from_slice(&7.5f32.to_be_bytes());
                data.extend_from_slice(&p[1].to_be_bytes());
                data.extend_from_slice(&p[2].to_be_bytes());
            }
            data.extend_from_slice(&[0xAA; 6]);
        }
        PointCloud2 {
            header: Header::default(),
            height,
            width,
            fields: vec![
                field("x", 0, FLOAT64),
                field("intensity", 8, FLOAT32),
                field("y", 12, FLOAT64),
                field("z", 20, FLOAT64),
            ],
            is_bigendian: true,
            point_step: step,
            row_step,
            data,
            is_dense: false,
        }
    }

    #[test]
    fn any_layout_gives_the_points_and_drops_non_finite_ones() {
        let pts = [
            [1.0, 2.0, 3.0],
            [f64::NAN, 0.0, 0.0],
            [-4.25, 5.5, 0.125],
            [1e3, -2e3, 7.0],
        ];
        let cloud = organised(&pts, 2);
        assert_eq!(
            cloud.points(10),
            Ok(vec![pts[0], pts[2], pts[3]]),
            "float64 big-endian, organised, padded rows"
        );
    }

    #[test]
    fn float32_little_endian_is_read() {
        let mut data = Vec::new();
        for v in [1.5f32, -2.0, 0.25, 3.0, 4.0, 5.0] {
            data.extend_from_slice(&v.to_le_bytes());
        }
        let cloud = PointCloud2 {
            header: Header::default(),
            height: 1,
            width: 2,
            fields: vec![
                field("x", 0, FLOAT32),
                field("y", 4, FLOAT32),
                field("z", 8, FLOAT32),
            ],
            is_bigendian: false,
            point_step: 12,
            row_step: 24,
            data,
            is_dense: true,
        };
        assert_eq!(
            cloud.points(2),
            Ok(vec![[1.5, -2.0, 0.25], [3.0, 4.0, 5.0]])
        );
        assert!(cloud.points(1).is_err(), "over the point limit");
    }

    #[test]
    fn inconsistent_layouts_are_refused() {
        let good = organised(&[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], 2);
        let mut short = good.clone();
        short.data.truncate(10);
        let mut no_z = good.clone();
        no_z.fields.retain(|f| f.name != "z");
        let mut ints = good.clone();
        ints.fields[0].datatype = 5;
        let mut past = good.clone();
        past.fields[3].offset = 24;
        let mut narrow = good.clone();
        narrow.row_step = 10;
        let mut huge = good.clone();
        huge.width = u32::MAX;
        huge.height = u32::MAX;
        for (what, c) in [
            ("short data", short),
            ("no z", no_z),
            ("integer x", ints),
            ("z past the point", past),
            ("row_step short", narrow),
            ("overflowing size", huge),
        ] {
            assert!(c.points(1_000_000).is_err(), "{what}");
        }
    }

    proptest::proptest! {
        /// Whatever the layout claims, reading never panics, and what it
        /// gives is finite and within the limit.
        #[test]
        fn any_message_is_read_or_refused_without_panic(
            offsets in proptest::collection::vec(0u32..40, 3),
            kinds in proptest::collection::vec(0u8..10, 3),
            width in 0u32..20,
            height in 0u32..4,
            point_step in 0u32..48,
            row_step in 0u32..400,
            big in proptest::bool::ANY,
            data in proptest::collection::vec(proptest::num::u8::ANY, 0..600),
        ) {
            let fields = ["x", "y", "z"]
                .iter()
                .zip(offsets.iter().zip(&kinds))
                .map(|(n, (&o, &k))| field(n, o, k))
                .collect();
            let cloud = PointCloud2 {
                header: Header::default(),
                height,
                width,
                fields,
                is_bigendian: big,
                point_step,
                row_step,
                data,
                is_dense: false,
            };
            if let Ok(points) = cloud.points(50) {
                proptest::prop_assert!(points.len() <= 50);
                proptest::prop_assert!(points.iter().flatten().all(|v| v.is_finite()));
            }
        }
    }
}
