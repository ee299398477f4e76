//! Point-cloud files: LAS and LAZ, E57, PLY and PCD in, LAS/LAZ and PLY out.
//!
//! [`read_cloud`] reads any of the five formats (told apart by the file's
//! extension) into one [`Cloud`]: the points in metres, one [`CloudScan`] per
//! scan the file holds with the scanner's origin when the file records it, and
//! one-line notes for the user (unit conversions, dropped points).
//! [`parse_cloud`] does the same from memory and never panics, whatever the
//! bytes. Every problem is a [`CloudError`] whose message is one line naming
//! the file and what is wrong with it.
//!
//! What each format contributes:
//! - LAS/LAZ (`las`): coordinates converted to metres from the units of the
//!   GeoTIFF keys or the WKT of the file's coordinate system; no origin.
//! - E57 (`e57`): every `data3D` is a scan, its points put in the file's common
//!   frame by its pose, whose translation is the scan's origin; points flagged
//!   invalid are dropped and counted; spherical-only scans are converted.
//! - PLY (`ply`): the `vertex` element's `x`, `y`, `z`; no origin.
//! - PCD (`pcd`): `x`, `y`, `z` as stored; the origin is the `VIEWPOINT`
//!   translation (PCL's sensor origin).
//!
//! The writers ([`encode_las`], [`encode_ply`], [`encode_stations_ply`]) save
//! the registered model of a simulated campaign; [`SourceFrame`] (`frame`)
//! carries a cloud-derived map's metres back to its source cloud's frame and
//! CRS for them.

mod collect;
mod e57;
mod frame;
mod las;
mod las_units;
mod laz_check;
mod pcd;
mod ply;
mod write;

use std::fmt;
use std::fs::File;
use std::io::{self, BufReader, Cursor};
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

pub use frame::{CrsRecord, FrameGround, SourceCrs, SourceFrame, CRS_USER_ID, FRAME_FORMAT};
pub use write::{
    encode_las, encode_las_in, encode_ply, encode_stations_ply, scan_colour, scan_number,
};

/// A point cloud read from a file, coordinates in metres.
#[derive(Debug, Clone, PartialEq)]
pub struct Cloud {
    /// The points, `[x, y, z]`, in the order the file holds them.
    pub points: Vec<[f64; 3]>,
    /// Contiguous ranges of `points`, one per scan in the file (one for
    /// single-scan formats), each with the scanner's origin when the file
    /// records it.
    pub scans: Vec<CloudScan>,
    /// The format the file was read as.
    pub format: CloudFormat,
    /// Points the file holds (before invalid ones were dropped).
    pub points_in_file: u64,
    /// Points dropped: E57 points flagged invalid (`cartesianInvalidState`),
    /// and with `drop_invalid` the non-finite ones.
    pub points_dropped: u64,
    /// One-line notes for the user, e.g. "LAS coordinates in international
    /// feet: converted to metres (× 0.3048)".
    pub notes: Vec<String>,
    /// Metres per unit of the file's x and y, and of its heights (LAS/LAZ in
    /// feet: 0.3048; otherwise 1).
    pub metres_per_unit: [f64; 2],
    /// The file's coordinate reference system (LAS/LAZ `LASF_Projection`
    /// records), when it has one.
    pub crs: Option<SourceCrs>,
}

/// One scan of a [`Cloud`].
#[derive(Debug, Clone, PartialEq)]
pub struct CloudScan {
    /// The scan's points, a range of [`Cloud::points`].
    pub points: Range<usize>,
    /// Where the scanner stood, metres, when the file records it.
    pub origin: Option<[f64; 3]>,
}

/// A point-cloud file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CloudFormat {
    /// ASPRS LAS.
    Las,
    /// LAS compressed by LASzip.
    Laz,
    /// ASTM E57.
    E57,
    /// Stanford PLY (ascii or binary).
    Ply,
    /// PCL's PCD (ascii, binary or binary_compressed).
    Pcd,
}

impl CloudFormat {
    /// The format's usual name, as in messages: "LAS", "LAZ", "E57", "PLY", "PCD".
    pub fn name(self) -> &'static str {
        match self {
            Self::Las => "LAS",
            Self::Laz => "LAZ",
            Self::E57 => "E57",
            Self::Ply => "PLY",
            Self::Pcd => "PCD",
        }
    }

    /// The format a path's extension names (case-insensitive: `las`, `laz`,
    /// `e57`, `ply`, `pcd`), if any.
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "las" => Some(Self::Las),
            "laz" => Some(Self::Laz),
            "e57" => Some(Self::E57),
            "ply" => Some(Self::Ply),
            "pcd" => Some(Self::Pcd),
            _ => None,
        }
    }
}

impl fmt::Display for CloudFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A unit of length coordinates can be stored in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    /// The metre.
    Metre,
    /// The international foot, 0.3048 m exactly.
    Foot,
    /// The US survey foot, 1200/3937 m.
    UsSurveyFoot,
}

impl LengthUnit {
    /// Metres per unit.
    pub fn factor(self) -> f64 {
        match self {
            Self::Metre => 1.0,
            Self::Foot => 0.3048,
            Self::UsSurveyFoot => 1200.0 / 3937.0,
        }
    }

    /// The unit a command-line word names: `m`, `ft` or `us-ft`.
    pub fn parse(word: &str) -> Option<Self> {
        match word {
            "m" => Some(Self::Metre),
            "ft" => Some(Self::Foot),
            "us-ft" => Some(Self::UsSurveyFoot),
            _ => None,
        }
    }

    /// The unit's name in notes: "metres", "international feet", "US survey feet".
    pub fn plural(self) -> &'static str {
        match self {
            Self::Metre => "metres",
            Self::Foot => "international feet",
            Self::UsSurveyFoot => "US survey feet",
        }
    }
}

/// How [`read_cloud`] and [`parse_cloud`] read a file.
#[derive(Debug, Clone, PartialEq)]
pub struct CloudReadOptions {
    /// Most points a file may hold (`limits.max_cloud_points`).
    pub max_points: u64,
    /// Largest file read, bytes (64 GiB by default).
    pub max_bytes: u64,
    /// Skip points with a non-finite coordinate instead of refusing the file.
    pub drop_invalid: bool,
    /// The unit the coordinates are in, overriding what the file says.
    pub units: Option<LengthUnit>,
}

impl Default for CloudReadOptions {
    fn default() -> Self {
        Self {
            max_points: 200_000_000,
            max_bytes: 64 << 30,
            drop_invalid: false,
            units: None,
        }
    }
}

/// Why a point cloud could not be read or written: the file and the problem,
/// on one line.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {problem}")]
pub struct CloudError {
    /// The file as the user named it (or "LAS data" and the like from memory).
    pub file: String,
    /// What is wrong.
    pub problem: CloudProblem,
}

/// What is wrong with a point-cloud file.
#[derive(Debug, thiserror::Error)]
pub enum CloudProblem {
    /// The file could not be opened or read.
    #[error("cannot read: {0}")]
    Io(String),
    /// A directory, a FIFO, a device.
    #[error("not a regular file")]
    NotAFile,
    /// The file is larger than the largest a cloud may be.
    #[error("file of {size} bytes, more than the {limit} bytes a cloud file may have")]
    FileTooLarge {
        /// Its size, bytes.
        size: u64,
        /// The limit, bytes.
        limit: u64,
    },
    /// The extension names no known format.
    #[error("unknown point-cloud format (the name must end in .las, .laz, .e57, .ply or .pcd)")]
    UnknownFormat,
    /// The file holds more points than `limits.max_cloud_points`.
    #[error("holds {points} points, more than `limits.max_cloud_points` = {limit}")]
    TooManyPoints {
        /// Points the file holds or claims.
        points: u64,
        /// The limit.
        limit: u64,
    },
    /// The file ends before the points its header promises.
    #[error("truncated: the header promises {promised} points, the file ends after {found}")]
    Truncated {
        /// Points the header promises.
        promised: u64,
        /// Whole points the file holds.
        found: u64,
    },
    /// The file ends inside a block of bytes its header promises.
    #[error("truncated: {what} needs {needed} bytes, the file has {available}")]
    TruncatedBytes {
        /// The block (e.g. "the compressed point data").
        what: &'static str,
        /// Bytes the header promises.
        needed: u64,
        /// Bytes there are.
        available: u64,
    },
    /// A point has a NaN or infinite coordinate.
    #[error("point {index} has a {kind} coordinate (pass --drop-invalid to skip such points)")]
    NonFinite {
        /// The point's index in the file, from 0.
        index: u64,
        /// "NaN" or "infinite".
        kind: &'static str,
    },
    /// The file holds no points.
    #[error("holds no points")]
    Empty,
    /// Every point of the file was dropped as invalid.
    #[error("holds no valid points (all {0} were invalid)")]
    NoValidPoints(u64),
    /// The file is not what its extension says, or is damaged.
    #[error("not a valid {format} file: {message}")]
    Malformed {
        /// The format expected.
        format: CloudFormat,
        /// What the decoder said, on one line.
        message: String,
    },
    /// A valid file of a kind this reader does not take.
    #[error("unsupported {format} file: {message}")]
    Unsupported {
        /// The format.
        format: CloudFormat,
        /// What is unsupported.
        message: String,
    },
    /// The points cannot be written in the format.
    #[error("cannot encode: {0}")]
    Encode(String),
}

impl CloudProblem {
    /// A decoder's complaint about a `format` file, flattened to one line.
    pub(crate) fn malformed(format: CloudFormat, message: impl fmt::Display) -> Self {
        Self::Malformed {
            format,
            message: one_line(message),
        }
    }

    /// Something valid but not supported in a `format` file.
    pub(crate) fn unsupported(format: CloudFormat, message: impl Into<String>) -> Self {
        Self::Unsupported {
            format,
            message: message.into(),
        }
    }

    fn named(self, file: impl Into<String>) -> CloudError {
        CloudError {
            file: file.into(),
            problem: self,
        }
    }
}

/// `message` with every run of whitespace (line breaks and tabs included)
/// made one space.
pub(crate) fn one_line(message: impl fmt::Display) -> String {
    message
        .to_string()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// A seekable byte source a reader can open again from the start (LAZ
/// needs a second pass to count the points of a truncated file).
pub(crate) trait Source {
    /// The reader type.
    type Reader: io::Read + io::Seek + Send + Sync + 'static;
    /// A reader at the start of the data.
    fn open(&self) -> io::Result<Self::Reader>;
    /// The data's length, bytes.
    fn len(&self) -> u64;
}

/// A file on disk.
struct FileSource<'a> {
    path: &'a Path,
    len: u64,
}

impl Source for FileSource<'_> {
    type Reader = BufReader<File>;
    fn open(&self) -> io::Result<Self::Reader> {
        Ok(BufReader::with_capacity(1 << 16, File::open(self.path)?))
    }
    fn len(&self) -> u64 {
        self.len
    }
}

/// Bytes in memory.
struct MemorySource(Arc<[u8]>);

impl Source for MemorySource {
    type Reader = Cursor<Arc<[u8]>>;
    fn open(&self) -> io::Result<Self::Reader> {
        Ok(Cursor::new(Arc::clone(&self.0)))
    }
    fn len(&self) -> u64 {
        self.0.len() as u64
    }
}

/// Reads the point cloud at `path`, its format told by the extension.
///
/// Only regular files of at most `options.max_bytes` are read. `progress` is
/// called with (points read, points in the file) about every 64k points.
pub fn read_cloud(
    path: &Path,
    options: &CloudReadOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Cloud, CloudError> {
    let file = path.display().to_string();
    let format =
        CloudFormat::from_path(path).ok_or_else(|| CloudProblem::UnknownFormat.named(&file))?;
    let meta = std::fs::metadata(path).map_err(|e| CloudProblem::Io(one_line(e)).named(&file))?;
    if !meta.is_file() {
        return Err(CloudProblem::NotAFile.named(&file));
    }
    if meta.len() > options.max_bytes {
        return Err(CloudProblem::FileTooLarge {
            size: meta.len(),
            limit: options.max_bytes,
        }
        .named(&file));
    }
    let source = FileSource {
        path,
        len: meta.len(),
    };
    read_source(&source, format, options, progress).map_err(|p| p.named(file))
}

/// Reads a point cloud of `format` from `bytes`, as [`read_cloud`] does a
/// file; never panics, whatever the bytes.
pub fn parse_cloud(
    bytes: &[u8],
    format: CloudFormat,
    options: &CloudReadOptions,
) -> Result<Cloud, CloudError> {
    let name = format!("{format} data");
    if bytes.len() as u64 > options.max_bytes {
        return Err(CloudProblem::FileTooLarge {
            size: bytes.len() as u64,
            limit: options.max_bytes,
        }
        .named(name));
    }
    let source = MemorySource(Arc::from(bytes));
    read_source(&source, format, options, &mut |_, _| {}).map_err(|p| p.named(name))
}

/// Reads `source` as `format`, then converts units where the format has not.
fn read_source<S: Source>(
    source: &S,
    format: CloudFormat,
    options: &CloudReadOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Cloud, CloudProblem> {
    if source.len() == 0 {
        return Err(CloudProblem::Empty);
    }
    let mut cloud = match format {
        CloudFormat::Las | CloudFormat::Laz => las::read(source, format, options, progress)?,
        CloudFormat::E57 => e57::read(source, options, progress)?,
        CloudFormat::Ply => ply::read(source, options, progress)?,
        CloudFormat::Pcd => pcd::read(source, options, progress)?,
    };
    if !matches!(format, CloudFormat::Las | CloudFormat::Laz) {
        if let Some(unit) = options.units.filter(|&u| u != LengthUnit::Metre) {
            scale(&mut cloud, unit.factor());
            cloud.notes.push(format!(
                "coordinates taken as {} (--units): converted to metres (× {})",
                unit.plural(),
                unit.factor()
            ));
        }
    }
    Ok(cloud)
}

/// Multiplies every point and origin of `cloud` by `factor`.
fn scale(cloud: &mut Cloud, factor: f64) {
    for p in &mut cloud.points {
        *p = p.map(|c| c * factor);
    }
    for s in &mut cloud.scans {
        s.origin = s.origin.map(|o| o.map(|c| c * factor));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_come_from_extensions_in_any_case() {
        let f = |p: &str| CloudFormat::from_path(Path::new(p));
        assert_eq!(f("a/scan.LAZ"), Some(CloudFormat::Laz));
        assert_eq!(f("scan.las"), Some(CloudFormat::Las));
        assert_eq!(f("x.E57"), Some(CloudFormat::E57));
        assert_eq!(f("x.Ply"), Some(CloudFormat::Ply));
        assert_eq!(f("x.pcd"), Some(CloudFormat::Pcd));
        assert_eq!(f("x.xyz"), None);
        assert_eq!(f("pcd"), None);
    }

    #[test]
    fn units_parse_and_convert() {
        assert_eq!(LengthUnit::parse("m"), Some(LengthUnit::Metre));
        assert_eq!(LengthUnit::parse("ft"), Some(LengthUnit::Foot));
        assert_eq!(LengthUnit::parse("us-ft"), Some(LengthUnit::UsSurveyFoot));
        assert_eq!(LengthUnit::parse("feet"), None);
        assert_eq!(LengthUnit::Foot.factor(), 0.3048);
        assert!((LengthUnit::UsSurveyFoot.factor() - 0.304_800_609_6).abs() < 1e-10);
    }

    #[test]
    fn decoder_messages_become_one_line() {
        assert_eq!(one_line("a\n\tb  c\r\n"), "a b c");
        let e = CloudProblem::malformed(CloudFormat::Ply, "Line 3:\n\tbad").named("x.ply");
        assert_eq!(e.to_string(), "x.ply: not a valid PLY file: Line 3: bad");
    }

    #[test]
    fn empty_input_holds_no_points() {
        for format in [
            CloudFormat::Las,
            CloudFormat::Laz,
            CloudFormat::E57,
            CloudFormat::Ply,
            CloudFormat::Pcd,
        ] {
            let e = parse_cloud(&[], format, &CloudReadOptions::default()).unwrap_err();
            assert_eq!(e.to_string(), format!("{format} data: holds no points"));
        }
    }
}
