//! E57 files, through the `e57` crate.
//!
//! Each `data3D` point cloud is a scan. The crate's simple reader puts every
//! point in the file's common frame by its scan's pose (rotation quaternion,
//! then translation) and converts spherical coordinates (range, azimuth,
//! elevation) to Cartesian where a scan has no valid Cartesian ones. Points it
//! reports without a valid position (`cartesianInvalidState` 1 or 2, or a
//! direction without range) are dropped and counted. A scan's origin is its
//! pose's translation, when it has a pose.

use e57::{CartesianCoordinate, E57Reader};

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
        let origin = pc
            .transform
            .as_ref()
            .map(|t| [t.translation.x, t.translation.y, t.translation.z]);
        let mut points = e57.pointcloud_simple(pc).map_err(malformed)?;
        points.spherical_to_cartesian(true);
        points.apply_pose(true);
        points.intensity_to_color(false);
        points.normalize_color(false);
        points.normalize_intensity(false);
        for point in points {
            match point.map_err(malformed)?.cartesian {
                CartesianCoordinate::Valid { x, y, z } => collector.push([x, y, z])?,
                CartesianCoordinate::Direction { .. } | CartesianCoordinate::Invalid => {
                    collector.push_flagged()?;
                }
            }
        }
        collector.end_scan(origin);
    }
    collector.finish(CloudFormat::E57)
}

/// The crate's complaint, as a malformed-E57 error.
fn malformed(e: e57::Error) -> CloudProblem {
    CloudProblem::malformed(CloudFormat::E57, e)
}
