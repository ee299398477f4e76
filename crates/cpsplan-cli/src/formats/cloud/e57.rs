//! E57 files, through the `e57` crate.
//!
//! Each `data3D` point cloud is a scan. Its points are read through the
//! crate's raw reader (its simple reader fails on scans whose first data
//! packet completes no point: it reads one packet where the raw reader reads
//! on until a point is complete) and normalised here as the simple reader
//! would: a point's Cartesian coordinates when `cartesianInvalidState` is 0
//! (or absent), else its spherical ones (range, azimuth, elevation) when
//! `sphericalInvalidState` is 0 (or absent), converted; points with neither
//! (invalid, or a direction without range) are dropped and counted. Every
//! point is then put in the file's common frame by its scan's pose (rotation
//! quaternion, then translation), whose translation is the scan's origin (a
//! scan without a pose is in the file's frame, its scanner at the origin: the
//! E57 standard's identity default).

use e57::{E57Reader, PointCloud, RecordName, RecordValue};

use super::collect::{check_claim, Collector};
use super::{one_line, Cloud, CloudFormat, CloudProblem, CloudReadOptions, Source};

/// Reads every scan of an E57 file.
pub(crate) fn read<S: Source>(
    source: &S,
    options: &CloudReadOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Cloud, CloudProblem> {
    let reader = source.open().map_err(|e| CloudProblem::Io(one_line(e)))?;
    let mut e57 = E57Reader::new(reader).map_err(malformed)?;
    let clouds = e57.pointclouds();
    let claimed = clouds
        .iter()
        .try_fold(0u64, |sum, pc| sum.checked_add(pc.records))
        .unwrap_or(u64::MAX);
    check_claim(claimed, options)?;
    if claimed == 0 {
        return Err(CloudProblem::Empty);
    }
    let mut collector = Collector::new(options, progress, claimed)?;
    for pc in &clouds {
        let layout = Layout::of(pc)?;
        let pose = Pose::of(pc)?;
        for values in e57.pointcloud_raw(pc).map_err(malformed)? {
            match layout.position(&values.map_err(malformed)?, pc)? {
                Some(p) => collector.push(pose.apply(p))?,
                None => collector.push_flagged()?,
            }
        }
        collector.end_scan(Some(pose.translation));
    }
    collector.finish(CloudFormat::E57)
}

/// Where a scan's coordinates are among its records.
struct Layout {
    cartesian: Option<[usize; 3]>,
    cartesian_invalid: Option<usize>,
    spherical: Option<[usize; 3]>,
    spherical_invalid: Option<usize>,
}

impl Layout {
    /// The layout of `pc`'s prototype; an error without any coordinates.
    fn of(pc: &PointCloud) -> Result<Self, CloudProblem> {
        let find = |name: RecordName| pc.prototype.iter().position(|r| r.name == name);
        let three = |a, b, c| Some([find(a)?, find(b)?, find(c)?]);
        let layout = Self {
            cartesian: three(
                RecordName::CartesianX,
                RecordName::CartesianY,
                RecordName::CartesianZ,
            ),
            cartesian_invalid: find(RecordName::CartesianInvalidState),
            spherical: three(
                RecordName::SphericalRange,
                RecordName::SphericalAzimuth,
                RecordName::SphericalElevation,
            ),
            spherical_invalid: find(RecordName::SphericalInvalidState),
        };
        if layout.cartesian.is_none() && layout.spherical.is_none() {
            return Err(CloudProblem::unsupported(
                CloudFormat::E57,
                "a scan has neither Cartesian nor spherical coordinates",
            ));
        }
        Ok(layout)
    }

    /// The point's position in its scan's frame, `None` when it has none.
    fn position(
        &self,
        values: &[RecordValue],
        pc: &PointCloud,
    ) -> Result<Option<[f64; 3]>, CloudProblem> {
        let value = |i: usize| -> Result<f64, CloudProblem> {
            match (values.get(i), pc.prototype.get(i)) {
                (Some(v), Some(r)) => v.to_f64(&r.data_type).map_err(malformed),
                _ => Err(CloudProblem::malformed(
                    CloudFormat::E57,
                    "a point lacks a value",
                )),
            }
        };
        let state = |i: Option<usize>| -> Result<i64, CloudProblem> {
            let Some(i) = i else { return Ok(0) };
            match (values.get(i), pc.prototype.get(i)) {
                (Some(v), Some(r)) => v.to_i64(&r.data_type).map_err(malformed),
                _ => Err(CloudProblem::malformed(
                    CloudFormat::E57,
                    "a point lacks a value",
                )),
            }
        };
        if let Some([x, y, z]) = self.cartesian {
            if state(self.cartesian_invalid)? == 0 {
                return Ok(Some([value(x)?, value(y)?, value(z)?]));
            }
        }
        if let Some([r, a, e]) = self.spherical {
            if state(self.spherical_invalid)? == 0 {
                let (range, azimuth, elevation) = (value(r)?, value(a)?, value(e)?);
                let across = range * elevation.cos();
                return Ok(Some([
                    across * azimuth.cos(),
                    across * azimuth.sin(),
                    range * elevation.sin(),
                ]));
            }
        }
        Ok(None)
    }
}

/// A scan's pose: a rotation matrix (row-major) and a translation.
struct Pose {
    rotation: [[f64; 3]; 3],
    translation: [f64; 3],
}

impl Pose {
    /// `pc`'s pose (the identity without one), its quaternion normalised.
    fn of(pc: &PointCloud) -> Result<Self, CloudProblem> {
        let Some(t) = &pc.transform else {
            return Ok(Self {
                rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                translation: [0.0; 3],
            });
        };
        let q = &t.rotation;
        let norm = (q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z).sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(CloudProblem::malformed(
                CloudFormat::E57,
                "a scan's pose has no rotation (a zero or non-finite quaternion)",
            ));
        }
        let (w, x, y, z) = (q.w / norm, q.x / norm, q.y / norm, q.z / norm);
        Ok(Self {
            rotation: [
                [
                    1.0 - 2.0 * (y * y + z * z),
                    2.0 * (x * y - w * z),
                    2.0 * (x * z + w * y),
                ],
                [
                    2.0 * (x * y + w * z),
                    1.0 - 2.0 * (x * x + z * z),
                    2.0 * (y * z - w * x),
                ],
                [
                    2.0 * (x * z - w * y),
                    2.0 * (y * z + w * x),
                    1.0 - 2.0 * (x * x + y * y),
                ],
            ],
            translation: [t.translation.x, t.translation.y, t.translation.z],
        })
    }

    /// `p` in the file's common frame.
    fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        std::array::from_fn(|i| {
            r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2] + self.translation[i]
        })
    }
}

/// The crate's complaint, as a malformed-E57 error.
fn malformed(e: e57::Error) -> CloudProblem {
    CloudProblem::malformed(CloudFormat::E57, e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poses_rotate_then_translate() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let mut pc = PointCloud::default();
        pc.transform = Some(e57::Transform {
            // Twice a unit quarter turn about z: normalised.
            rotation: e57::Quaternion {
                w: 2.0 * h,
                x: 0.0,
                y: 0.0,
                z: 2.0 * h,
            },
            translation: e57::Translation {
                x: 1.0,
                y: 2.0,
                z: 3.0,
            },
        });
        let pose = Pose::of(&pc).unwrap();
        let p = pose.apply([1.0, 0.0, 0.0]);
        for (got, want) in p.iter().zip([1.0, 3.0, 3.0]) {
            assert!((got - want).abs() < 1e-12, "{p:?}");
        }
        pc.transform.as_mut().unwrap().rotation.w = 0.0;
        pc.transform.as_mut().unwrap().rotation.z = 0.0;
        assert!(Pose::of(&pc).is_err());
        assert_eq!(
            Pose::of(&PointCloud::default())
                .unwrap()
                .apply([1.0, 2.0, 3.0]),
            [1.0, 2.0, 3.0]
        );
    }
}
