//! ROS `map_server` maps: a YAML metadata file next to a PGM or PNG image.
//!
//! Conventions (DESIGN.md "Frames", ROS `map_server`):
//! - the image's first row is the *top* of the map; grid row 0 is the bottom, so
//!   rows are flipped on load and save;
//! - `origin: [x, y, yaw]` is the pose of the lower-left pixel; `yaw` becomes
//!   [`GridGeometry::yaw`];
//! - a pixel value `v` (RGB channels averaged, alpha ignored) gives the occupancy
//!   `p = (255 − v) / 255`, or `p = v / 255` with `negate`;
//! - in `trinary` and `scale` modes a cell is Occupied if `p > occupied_thresh`,
//!   Free if `p < free_thresh`, Unknown otherwise (`scale`'s intermediate
//!   probabilities have no place in a three-state grid);
//! - in `raw` mode the value is the occupancy in percent: `v == 0` is Free,
//!   `v == 100` is Occupied, and every other value (255 = ROS "unknown", and the
//!   intermediate probabilities 1–99) is Unknown — the conservative reading, since
//!   Unknown is solid in a ground truth. `negate` and the thresholds do not apply.
//!
//! Only `image`, `resolution` and `origin` are required; `negate` defaults to
//! false, `occupied_thresh` to 0.65, `free_thresh` to 0.196 and `mode` to
//! `trinary` (the ROS defaults). Unknown keys are ignored.

use std::fs;
use std::io::{self, Cursor, Read};
use std::path::{Path, PathBuf};

use cpsplan::config::number;
use cpsplan::{CellState, Config, GridGeometry, OccupancyGrid, Point};
use image::{DynamicImage, ImageFormat, ImageReader};

use super::{png_chunks, pnm};

mod save;
pub use save::{encode_map, save_map, save_map_with_notes, EncodedMap};
use serde::Deserialize;

/// Default `occupied_thresh` (ROS `map_server`).
pub const DEFAULT_OCCUPIED_THRESH: f64 = 0.65;
/// Default `free_thresh` (ROS `map_server`).
pub const DEFAULT_FREE_THRESH: f64 = 0.196;

/// Pixel value written for a Free cell.
const PIXEL_FREE: u8 = 254;
/// Pixel value written for an Occupied cell.
const PIXEL_OCCUPIED: u8 = 0;
/// Pixel value written for an Unknown cell.
const PIXEL_UNKNOWN: u8 = 205;

/// Why a map file could not be read or written. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    /// The file could not be read, written or renamed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: io::Error,
    },
    /// The YAML could not be parsed.
    #[error("{}: bad YAML: {message}", path.display())]
    Yaml {
        /// The YAML file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A required key is absent from the YAML.
    #[error("{}: missing required key `{key}`", path.display())]
    MissingKey {
        /// The YAML file.
        path: PathBuf,
        /// The missing key.
        key: &'static str,
    },
    /// A key (or argument) has an unusable value.
    #[error("{}: bad value for `{key}`: {message}", path.display())]
    BadValue {
        /// The file concerned.
        path: PathBuf,
        /// The key or argument.
        key: &'static str,
        /// What is wrong with it.
        message: String,
    },
    /// The image is of a kind that cannot be read as a map.
    #[error("{}: unsupported image: {message}", path.display())]
    UnsupportedImage {
        /// The image file.
        path: PathBuf,
        /// What is unsupported.
        message: String,
    },
    /// The path is not a regular file (a directory, a FIFO, a device).
    #[error("{}: not a regular file", path.display())]
    NotAFile {
        /// The path.
        path: PathBuf,
    },
    /// The file is larger than the limit for its kind.
    #[error("{}: file of {} bytes, more than the limit of {}", path.display(), number(*size as f64), number(*limit as f64))]
    FileTooLarge {
        /// The file.
        path: PathBuf,
        /// Its size, bytes.
        size: u64,
        /// The limit, bytes.
        limit: u64,
    },
    /// The image has more pixels than the grid-cell limit.
    #[error(
        "{}: image of {width} × {height} pixels, more than `limits.max_grid_cells` = {}",
        path.display(),
        number(*limit as f64)
    )]
    TooManyPixels {
        /// The image file.
        path: PathBuf,
        /// Pixels per row.
        width: u32,
        /// Rows.
        height: u32,
        /// The limit, pixels.
        limit: u64,
    },
    /// The image could not be decoded.
    #[error("{}: cannot decode image: {source}", path.display())]
    ImageDecode {
        /// The image file.
        path: PathBuf,
        /// The decoder's error.
        #[source]
        source: image::ImageError,
    },
}

impl FormatError {
    fn io(path: &Path, source: io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    fn bad(path: &Path, key: &'static str, message: impl Into<String>) -> Self {
        Self::BadValue {
            path: path.to_path_buf(),
            key,
            message: message.into(),
        }
    }
}

/// How pixel values become occupancy (ROS `map_server` `mode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MapMode {
    /// Thresholded into free / occupied / unknown (the default).
    #[default]
    Trinary,
    /// Thresholded like `Trinary` here (a three-state grid has no intermediate values).
    Scale,
    /// Pixel values are occupancy percentages: 0 free, 100 occupied, else unknown.
    Raw,
}

/// The contents of a ROS `map_server` YAML file, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct MapMetadata {
    /// The image file, resolved against the YAML file's directory.
    pub image: PathBuf,
    /// Cell width in metres (finite, > 0).
    pub resolution: f64,
    /// Pose `[x, y, yaw]` of the lower-left pixel (metres, radians).
    pub origin: [f64; 3],
    /// Whether white means occupied.
    pub negate: bool,
    /// Occupancy above which a cell is Occupied (in `[0, 1]`).
    pub occupied_thresh: f64,
    /// Occupancy below which a cell is Free (in `[0, 1]`, below `occupied_thresh`).
    pub free_thresh: f64,
    /// How pixel values are interpreted.
    pub mode: MapMode,
}

/// `negate` as ROS files write it: `0`/`1` or `true`/`false`.
#[derive(Deserialize)]
#[serde(untagged)]
enum Flag {
    Bool(bool),
    Int(i64),
    Float(f64),
    Text(String),
    Other(serde::de::IgnoredAny),
}

/// The YAML as written, before validation.
#[derive(Deserialize)]
struct RawMetadata {
    image: Option<String>,
    resolution: Option<f64>,
    origin: Option<Vec<f64>>,
    negate: Option<Flag>,
    occupied_thresh: Option<f64>,
    free_thresh: Option<f64>,
    mode: Option<String>,
}

impl MapMetadata {
    /// Read and validate a YAML file.
    pub fn read(yaml: &Path) -> Result<Self, FormatError> {
        Self::read_with(yaml, &ReadLimits::default())
    }

    /// Read and validate a YAML file of at most `limits.max_text_bytes`.
    pub fn read_with(yaml: &Path, limits: &ReadLimits) -> Result<Self, FormatError> {
        Self::parse(&read_text(yaml, limits.max_text_bytes)?, yaml)
    }

    /// Parse and validate YAML text; `yaml` is the file it came from (for messages
    /// and to resolve a relative `image:`).
    pub fn parse(text: &str, yaml: &Path) -> Result<Self, FormatError> {
        let mut options = serde_saphyr::Options::default();
        options.with_snippet = false; // one-line messages; the snippet says `<input>`
        let raw: RawMetadata =
            serde_saphyr::from_str_with_options(text, options).map_err(|e| FormatError::Yaml {
                path: yaml.to_path_buf(),
                message: e.to_string(),
            })?;
        let missing = |key| FormatError::MissingKey {
            path: yaml.to_path_buf(),
            key,
        };
        let image = raw.image.ok_or_else(|| missing("image"))?;
        if image.trim().is_empty() {
            return Err(FormatError::bad(yaml, "image", "empty path"));
        }
        let image = PathBuf::from(image);
        let image = if image.is_absolute() {
            image
        } else {
            yaml.parent().unwrap_or(Path::new("")).join(image)
        };

        let resolution = raw.resolution.ok_or_else(|| missing("resolution"))?;
        check_resolution(resolution, yaml, "resolution")?;

        let origin = raw.origin.ok_or_else(|| missing("origin"))?;
        let origin: [f64; 3] = match origin.as_slice() {
            [x, y, yaw] => [*x, *y, *yaw],
            [x, y] => [*x, *y, 0.0],
            other => {
                return Err(FormatError::bad(
                    yaml,
                    "origin",
                    format!("expected [x, y, yaw], got {} numbers", other.len()),
                ))
            }
        };
        if origin.iter().any(|v| !v.is_finite()) {
            return Err(FormatError::bad(yaml, "origin", "not finite"));
        }

        let negate = match raw.negate {
            None | Some(Flag::Bool(false)) | Some(Flag::Int(0)) => false,
            Some(Flag::Bool(true)) | Some(Flag::Int(1)) => true,
            Some(other) => {
                let got = match other {
                    Flag::Int(n) => n.to_string(),
                    Flag::Float(x) => format!("{x:?}"),
                    Flag::Text(t) => format!("{t:?}"),
                    Flag::Bool(b) => b.to_string(),
                    Flag::Other(_) => "a list or mapping".to_string(),
                };
                return Err(FormatError::bad(
                    yaml,
                    "negate",
                    format!("expected 0, 1, true or false, got {got}"),
                ));
            }
        };

        let occupied_thresh = raw.occupied_thresh.unwrap_or(DEFAULT_OCCUPIED_THRESH);
        let free_thresh = raw.free_thresh.unwrap_or(DEFAULT_FREE_THRESH);
        for (key, v) in [
            ("occupied_thresh", occupied_thresh),
            ("free_thresh", free_thresh),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(FormatError::bad(
                    yaml,
                    key,
                    format!("{v} is outside [0, 1]"),
                ));
            }
        }
        if free_thresh >= occupied_thresh {
            return Err(FormatError::bad(
                yaml,
                "free_thresh",
                format!("{free_thresh} is not below occupied_thresh {occupied_thresh}"),
            ));
        }

        let mode = match raw.mode.as_deref().map(str::trim) {
            None => MapMode::Trinary,
            Some(m) if m.eq_ignore_ascii_case("trinary") => MapMode::Trinary,
            Some(m) if m.eq_ignore_ascii_case("scale") => MapMode::Scale,
            Some(m) if m.eq_ignore_ascii_case("raw") => MapMode::Raw,
            Some(m) => {
                return Err(FormatError::bad(
                    yaml,
                    "mode",
                    format!("expected trinary, scale or raw, got {m:?}"),
                ))
            }
        };

        Ok(Self {
            image,
            resolution,
            origin,
            negate,
            occupied_thresh,
            free_thresh,
            mode,
        })
    }

    /// Metadata for a plain image without YAML: default thresholds, origin (0, 0, 0).
    pub fn for_image(image: &Path, resolution: f64) -> Self {
        Self {
            image: image.to_path_buf(),
            resolution,
            origin: [0.0; 3],
            negate: false,
            occupied_thresh: DEFAULT_OCCUPIED_THRESH,
            free_thresh: DEFAULT_FREE_THRESH,
            mode: MapMode::Trinary,
        }
    }

    /// The grid's placement: size from the image, the rest from this metadata.
    pub fn geometry(&self, width: usize, height: usize) -> GridGeometry {
        GridGeometry {
            width,
            height,
            resolution: self.resolution,
            origin: Point::new(self.origin[0], self.origin[1]),
            yaw: self.origin[2],
        }
    }

    /// Read the image this metadata refers to into a grid, within the default
    /// [`ReadLimits`].
    pub fn load_grid(&self) -> Result<OccupancyGrid, FormatError> {
        self.load_grid_with(&ReadLimits::default())
    }

    /// Read the image this metadata refers to into a grid, within `limits`.
    pub fn load_grid_with(&self, limits: &ReadLimits) -> Result<OccupancyGrid, FormatError> {
        let bytes = read_file(&self.image, limits.max_image_bytes)?;
        self.grid_from_image(&bytes, limits)
    }

    /// Decode image bytes (PNG or PGM/PPM/PAM, told apart by content) into a grid
    /// placed by this metadata; `self.image` names the image in messages. The
    /// image's size is checked against `limits` before its pixels are decoded.
    pub fn grid_from_image(
        &self,
        bytes: &[u8],
        limits: &ReadLimits,
    ) -> Result<OccupancyGrid, FormatError> {
        check_resolution(self.resolution, &self.image, "resolution")?;
        let path = &self.image;
        let unsupported = |message: String| FormatError::UnsupportedImage {
            path: path.clone(),
            message,
        };
        let format = image::guess_format(bytes)
            .ok()
            .filter(|f| matches!(f, ImageFormat::Png | ImageFormat::Pnm))
            .ok_or_else(|| unsupported("not a PNG or PGM/PNM image".into()))?;
        let raster = match format {
            ImageFormat::Pnm => match pnm::read_raw(bytes, limits.max_pixels) {
                Ok(Some(raw)) => Raster::Raw(raw),
                Ok(None) => Raster::Decoded(decode(bytes, format, path, limits)?),
                Err(message) => return Err(unsupported(message)),
            },
            _ => {
                png_chunks::check(bytes).map_err(unsupported)?;
                Raster::Decoded(decode(bytes, format, path, limits)?)
            }
        };
        let (w, h) = raster.size();
        if w == 0 || h == 0 {
            return Err(unsupported("image has no pixels".into()));
        }
        let cells = raster.classify(path, self.classifier())?;
        OccupancyGrid::from_cells(self.geometry(w, h), cells)
            .ok_or_else(|| unsupported("pixel count does not match the image size".into()))
    }

    /// The rule turning a pixel's sample value (channels averaged) out of the
    /// image's greatest value `max` into a cell state.
    fn classifier(&self) -> impl Fn(f64, f64) -> CellState {
        let (mode, negate) = (self.mode, self.negate);
        let (occ, free) = (self.occupied_thresh, self.free_thresh);
        move |v: f64, max: f64| match mode {
            MapMode::Raw => match v.round() as i64 {
                0 => CellState::Free,
                100 => CellState::Occupied,
                _ => CellState::Unknown,
            },
            MapMode::Trinary | MapMode::Scale => {
                let p = if negate { v / max } else { (max - v) / max };
                if p > occ {
                    CellState::Occupied
                } else if p < free {
                    CellState::Free
                } else {
                    CellState::Unknown
                }
            }
        }
    }
}

/// What a map file may make cpsplan read and allocate. Every size is checked
/// before the memory it implies is taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadLimits {
    /// Most pixels an image may have (`limits.max_grid_cells` of the
    /// configuration).
    pub max_pixels: u64,
    /// Largest image file, bytes.
    pub max_image_bytes: u64,
    /// Largest YAML or TOML file, bytes.
    pub max_text_bytes: u64,
}

impl Default for ReadLimits {
    fn default() -> Self {
        Self::for_config(&Config::default())
    }
}

impl ReadLimits {
    /// The limits for a configuration: images up to its grid-cell cap, image
    /// files up to 2 GiB, text files up to 16 MiB.
    pub fn for_config(config: &Config) -> Self {
        Self {
            max_pixels: config.limits.max_grid_cells as u64,
            max_image_bytes: 2 << 30,
            max_text_bytes: 16 << 20,
        }
    }
}

/// Reads a whole regular file of at most `max_bytes` bytes. Anything else (a
/// directory, a FIFO, a device, a larger file) is refused before reading, so a
/// path can never block or exhaust memory.
pub fn read_file(path: &Path, max_bytes: u64) -> Result<Vec<u8>, FormatError> {
    let meta = fs::metadata(path).map_err(|e| FormatError::io(path, e))?;
    if !meta.is_file() {
        return Err(FormatError::NotAFile {
            path: path.to_path_buf(),
        });
    }
    if meta.len() > max_bytes {
        return Err(FormatError::FileTooLarge {
            path: path.to_path_buf(),
            size: meta.len(),
            limit: max_bytes,
        });
    }
    let file = fs::File::open(path).map_err(|e| FormatError::io(path, e))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| FormatError::io(path, e))?;
    if bytes.len() as u64 > max_bytes {
        return Err(FormatError::FileTooLarge {
            path: path.to_path_buf(),
            size: bytes.len() as u64,
            limit: max_bytes,
        });
    }
    Ok(bytes)
}

/// Reads a UTF-8 text file of at most `max_bytes` bytes with [`read_file`].
pub fn read_text(path: &Path, max_bytes: u64) -> Result<String, FormatError> {
    String::from_utf8(read_file(path, max_bytes)?).map_err(|_| FormatError::BadValue {
        path: path.to_path_buf(),
        key: "file",
        message: "not UTF-8 text".into(),
    })
}

fn check_resolution(resolution: f64, path: &Path, key: &'static str) -> Result<(), FormatError> {
    if resolution.is_finite() && resolution > 0.0 {
        Ok(())
    } else {
        Err(FormatError::bad(
            path,
            key,
            format!(
                "{} is not a finite positive number of metres",
                number(resolution)
            ),
        ))
    }
}

/// Decode a PNG or a bitmap PNM with the `image` crate, its size checked against
/// `limits` from the header first.
fn decode(
    bytes: &[u8],
    format: ImageFormat,
    path: &Path,
    limits: &ReadLimits,
) -> Result<DynamicImage, FormatError> {
    let decode_error = |source| FormatError::ImageDecode {
        path: path.to_path_buf(),
        source,
    };
    let (w, h) = ImageReader::with_format(Cursor::new(bytes), format)
        .into_dimensions()
        .map_err(decode_error)?;
    let pixels = u64::from(w) * u64::from(h);
    if pixels > limits.max_pixels {
        return Err(FormatError::TooManyPixels {
            path: path.to_path_buf(),
            width: w,
            height: h,
            limit: limits.max_pixels,
        });
    }
    let mut image_limits = image::Limits::default();
    image_limits.max_image_width = Some(w);
    image_limits.max_image_height = Some(h);
    // The largest pixel type (RGBA, 16 bits) and the decoder's own buffers.
    image_limits.max_alloc = Some(pixels.saturating_mul(16).saturating_add(64 << 20));
    let mut reader = ImageReader::with_format(Cursor::new(bytes), format);
    reader.limits(image_limits);
    reader.decode().map_err(decode_error)
}

/// Decoded pixels: raw anymap samples, or an image from the `image` crate.
enum Raster {
    Raw(pnm::RawSamples),
    Decoded(DynamicImage),
}

impl Raster {
    fn size(&self) -> (usize, usize) {
        match self {
            Raster::Raw(r) => (r.width as usize, r.height as usize),
            Raster::Decoded(img) => (img.width() as usize, img.height() as usize),
        }
    }

    /// Cell states of the pixels, row-major from the *bottom* row (the image's
    /// first row is the top of the map). Each pixel is reduced to one sample
    /// value (gray as is, colour channels averaged, alpha ignored) and passed to
    /// `classify` with the image's greatest value (anymap maxval, 255 or 65535).
    fn classify(
        &self,
        path: &Path,
        classify: impl Fn(f64, f64) -> CellState,
    ) -> Result<Vec<CellState>, FormatError> {
        const M8: f64 = 255.0;
        const M16: f64 = 65535.0;
        let (w, _) = self.size();
        let c = &classify;
        let img = match self {
            Raster::Raw(r) => {
                let max = f64::from(r.maxval);
                let value: fn(&[u16]) -> f64 = if r.channels >= 3 { rgb } else { gray };
                return Ok(flipped(&r.samples, w, r.channels, |v| c(v, max), value));
            }
            Raster::Decoded(img) => img,
        };
        let cells = match img {
            DynamicImage::ImageLuma8(b) => flipped(b.as_raw(), w, 1, |v| c(v, M8), gray),
            DynamicImage::ImageLumaA8(b) => flipped(b.as_raw(), w, 2, |v| c(v, M8), gray),
            DynamicImage::ImageRgb8(b) => flipped(b.as_raw(), w, 3, |v| c(v, M8), rgb),
            DynamicImage::ImageRgba8(b) => flipped(b.as_raw(), w, 4, |v| c(v, M8), rgb),
            DynamicImage::ImageLuma16(b) => flipped(b.as_raw(), w, 1, |v| c(v, M16), gray),
            DynamicImage::ImageLumaA16(b) => flipped(b.as_raw(), w, 2, |v| c(v, M16), gray),
            DynamicImage::ImageRgb16(b) => flipped(b.as_raw(), w, 3, |v| c(v, M16), rgb),
            DynamicImage::ImageRgba16(b) => flipped(b.as_raw(), w, 4, |v| c(v, M16), rgb),
            other => {
                return Err(FormatError::UnsupportedImage {
                    path: path.to_path_buf(),
                    message: format!("pixel type {:?}", other.color()),
                })
            }
        };
        Ok(cells)
    }
}

/// The first channel of a pixel.
fn gray<T: Copy + Into<f64>>(p: &[T]) -> f64 {
    p[0].into()
}

/// The mean of a pixel's first three channels.
fn rgb<T: Copy + Into<f64>>(p: &[T]) -> f64 {
    (p[0].into() + p[1].into() + p[2].into()) / 3.0
}

/// Classify interleaved samples (`channels` per pixel, rows of `width` pixels
/// from the top) into cells ordered from the bottom row.
fn flipped<T>(
    samples: &[T],
    width: usize,
    channels: usize,
    classify: impl Fn(f64) -> CellState,
    value: impl Fn(&[T]) -> f64,
) -> Vec<CellState> {
    let mut cells = Vec::with_capacity(samples.len() / channels);
    for row in samples.chunks_exact(width * channels).rev() {
        cells.extend(row.chunks_exact(channels).map(|p| classify(value(p))));
    }
    cells
}

/// Load a ROS `map_server` map from its YAML file (default [`ReadLimits`]).
pub fn load_map(yaml: &Path) -> Result<OccupancyGrid, FormatError> {
    load_map_with(yaml, &ReadLimits::default())
}

/// Load a ROS `map_server` map from its YAML file within `limits`.
pub fn load_map_with(yaml: &Path, limits: &ReadLimits) -> Result<OccupancyGrid, FormatError> {
    MapMetadata::read_with(yaml, limits)?.load_grid_with(limits)
}

/// Load a plain PNG/PGM image as a map without YAML: cells `resolution` m wide,
/// origin (0, 0), yaw 0, default thresholds (0.65 / 0.196), trinary.
pub fn load_image_map(path: &Path, resolution: f64) -> Result<OccupancyGrid, FormatError> {
    check_resolution(resolution, path, "resolution")?;
    MapMetadata::for_image(path, resolution).load_grid()
}

/// The map_server YAML beside the image `image` that names it (`NAME.yaml` or
/// `NAME.yml` for `NAME.pgm`), with what it says, if there is one: an image
/// read alone loses its resolution and origin.
pub fn yaml_beside(image: &Path) -> Option<(PathBuf, MapMetadata)> {
    let same = |a: &Path, b: &Path| match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    ["yaml", "yml"].into_iter().find_map(|ext| {
        let yaml = image.with_extension(ext);
        if yaml == image || !yaml.is_file() {
            return None;
        }
        let meta = MapMetadata::read(&yaml).ok()?;
        same(&meta.image, image).then_some((yaml, meta))
    })
}

/// Load a map from a `.yaml`/`.yml` file (with [`load_map`]) or from any other
/// file as a plain image (with [`load_image_map`] at `default_resolution`).
pub fn load_any(path: &Path, default_resolution: f64) -> Result<OccupancyGrid, FormatError> {
    load_any_with(path, default_resolution, &ReadLimits::default())
}

/// Whether `path` names a map_server YAML (`.yaml` or `.yml`, any case).
pub fn is_yaml_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"))
}

/// [`load_any`] within `limits`.
pub fn load_any_with(
    path: &Path,
    default_resolution: f64,
    limits: &ReadLimits,
) -> Result<OccupancyGrid, FormatError> {
    if is_yaml_path(path) {
        load_map_with(path, limits)
    } else {
        check_resolution(default_resolution, path, "resolution")?;
        MapMetadata::for_image(path, default_resolution).load_grid_with(limits)
    }
}
