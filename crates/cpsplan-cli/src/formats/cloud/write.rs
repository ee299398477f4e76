//! Writers for the registered model: its points as LAS/LAZ or PLY, its scan
//! stations as PLY.
//!
//! Every point carries its scan's number (from 1, [`scan_number`]), and a colour and an intensity that
//! tell scans apart in any viewer: hues a golden angle apart ([`scan_colour`]),
//! intensities a golden ratio apart.

use std::io::Cursor;

use cpsplan::model::{ModelPoint, ModelStation};
use las::point::Format;
use las::{Builder, Color, Point, Transform, Vector, Version, Writer};
use ply_rs_bw::ply::{
    Addable, ElementDef, Encoding, Header, PropertyAccess, PropertyDef, PropertyType, ScalarType,
};

use super::frame::SourceCrs;
use super::{CloudError, CloudProblem};

/// LAS coordinate resolution, metres.
const LAS_SCALE: f64 = 1e-4;

/// The number a file gives scan index `scan` (from 0 in memory): from 1, as
/// the steps of `episode.json`, `metrics.csv` and `model.csv` number them.
pub fn scan_number(scan: u32) -> u32 {
    scan.saturating_add(1)
}

/// The golden ratio's fractional part: successive multiples are well spread
/// over [0, 1).
const GOLDEN_FRACTION: f64 = 0.618_033_988_749_894_9;

/// The colour of scan `scan`: hues a golden angle (137.5°) apart, so that
/// neighbouring scans differ clearly and no two of the first dozens coincide.
pub fn scan_colour(scan: u32) -> [u8; 3] {
    let hue = (f64::from(scan) * (1.0 - GOLDEN_FRACTION)).fract();
    hsv_to_rgb(hue, 0.75, 0.95)
}

/// The intensity of scan `scan`'s points: spread over the range by the golden
/// ratio, so that an intensity ramp tells scans apart too.
fn scan_intensity(scan: u32) -> u16 {
    let t = (f64::from(scan) * GOLDEN_FRACTION).fract();
    (4096.0 + t * 61439.0).round() as u16
}

/// HSV (hue in turns) to 8-bit RGB.
fn hsv_to_rgb(hue: f64, saturation: f64, value: f64) -> [u8; 3] {
    let h = hue * 6.0;
    let sector = h.floor();
    let f = h - sector;
    let p = value * (1.0 - saturation);
    let q = value * (1.0 - saturation * f);
    let t = value * (1.0 - saturation * (1.0 - f));
    let (r, g, b) = match sector as u8 % 6 {
        0 => (value, t, p),
        1 => (q, value, p),
        2 => (p, value, t),
        3 => (p, q, value),
        4 => (t, p, value),
        _ => (value, p, q),
    };
    [r, g, b].map(|c| (c * 255.0).round() as u8)
}

/// An encoding problem for the output named `what`.
fn encode_error(what: &str, message: impl Into<String>) -> CloudError {
    CloudError {
        file: what.to_string(),
        problem: CloudProblem::Encode(message.into()),
    }
}

/// Checks that every position is finite.
fn check_finite(what: &str, positions: impl Iterator<Item = [f64; 3]>) -> Result<(), CloudError> {
    for (i, p) in positions.enumerate() {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(encode_error(
                what,
                format!("point {i} has a non-finite coordinate"),
            ));
        }
    }
    Ok(())
}

/// The model's points as LAS 1.2, point format 3 (RGB and GPS time), LAZ
/// when `compressed`: 0.1 mm resolution from an offset at the rounded
/// minimum; each point's scan number as its point source id (saturating at
/// 65535) and its GPS time, its colour and intensity from the scan number.
pub fn encode_las(points: &[ModelPoint], compressed: bool) -> Result<Vec<u8>, CloudError> {
    encode_las_in(points, compressed, None)
}

/// [`encode_las`] with a source cloud's coordinate reference system: its
/// `LASF_Projection` records copied, and a WKT one flagged as LAS 1.4 requires
/// (the file is then LAS 1.4, point format 3).
pub fn encode_las_in(
    points: &[ModelPoint],
    compressed: bool,
    crs: Option<&SourceCrs>,
) -> Result<Vec<u8>, CloudError> {
    let what = if compressed {
        "LAZ output"
    } else {
        "LAS output"
    };
    check_finite(what, points.iter().map(|p| p.position))?;
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            min[k] = min[k].min(p.position[k]);
            max[k] = max[k].max(p.position[k]);
        }
    }
    let offset = if points.is_empty() {
        [0.0; 3]
    } else {
        min.map(f64::round)
    };
    for k in 0..3 {
        if !points.is_empty() && (max[k] - offset[k]) / LAS_SCALE >= f64::from(i32::MAX) {
            return Err(encode_error(
                what,
                format!(
                    "the points span {:.0} m, more than LAS holds at 0.1 mm",
                    max[k] - min[k]
                ),
            ));
        }
    }
    let axis = |k: usize| Transform {
        scale: LAS_SCALE,
        offset: offset[k],
    };
    let mut builder = Builder::default();
    builder.version = Version::new(1, 2);
    builder.point_format = Format::new(3).map_err(|e| encode_error(what, e.to_string()))?;
    builder.point_format.is_compressed = compressed;
    builder.transforms = Vector {
        x: axis(0),
        y: axis(1),
        z: axis(2),
    };
    if let Some(crs) = crs {
        builder.vlrs = crs.vlrs().map_err(|e| encode_error(what, e.to_string()))?;
        if crs.wkt {
            builder.version = Version::new(1, 4);
            builder.has_wkt_crs = true;
        }
    }
    builder.generating_software = "cpsplan".to_string();
    builder.system_identifier = "cpsplan registered model".to_string();
    let header = builder
        .into_header()
        .map_err(|e| encode_error(what, e.to_string()))?;
    let mut writer = Writer::new(Cursor::new(Vec::new()), header)
        .map_err(|e| encode_error(what, e.to_string()))?;
    for p in points {
        let n = scan_number(p.scan);
        let [r, g, b] = scan_colour(n).map(|c| u16::from(c) * 257);
        let point = Point {
            x: p.position[0],
            y: p.position[1],
            z: p.position[2],
            intensity: scan_intensity(n),
            point_source_id: u16::try_from(n).unwrap_or(u16::MAX),
            gps_time: Some(f64::from(n)),
            color: Some(Color::new(r, g, b)),
            ..Point::default()
        };
        writer
            .write_point(point)
            .map_err(|e| encode_error(what, e.to_string()))?;
    }
    let bytes = writer
        .into_inner()
        .map_err(|e| encode_error(what, e.to_string()))?;
    Ok(bytes.into_inner())
}

/// A PLY element to declare: its name, its count and its scalar properties.
type ElementSpec<'a> = (&'a str, usize, &'a [(&'a str, ScalarType)]);

/// A PLY header of one binary little-endian file with `elements`.
fn ply_header(elements: &[ElementSpec]) -> Header {
    let mut header = Header::new();
    header.encoding = Encoding::BinaryLittleEndian;
    header.comments.push("written by cpsplan".to_string());
    for &(name, count, properties) in elements {
        let mut element = ElementDef::new(name.to_string());
        element.count = count;
        for (property, scalar) in properties {
            element.properties.add(PropertyDef::new(
                property.to_string(),
                PropertyType::Scalar(scalar.clone()),
            ));
        }
        header.elements.add(element);
    }
    header
}

/// Appends `elements` to `out` as the binary little-endian records of `def`.
fn write_elements<E: PropertyAccess>(
    out: &mut Vec<u8>,
    def: &ElementDef,
    elements: impl Iterator<Item = E>,
) -> std::io::Result<()> {
    let writer = ply_rs_bw::writer::Writer::<E>::new();
    for e in elements {
        writer.write_little_endian_element(out, &e, def)?;
    }
    Ok(())
}

/// Writes a PLY file: `header`, then the elements `fill` appends.
fn write_ply(
    what: &str,
    header: &Header,
    fill: impl FnOnce(&mut Vec<u8>, &Header) -> std::io::Result<()>,
) -> Result<Vec<u8>, CloudError> {
    let mut out = Vec::new();
    let fail = |e: std::io::Error| encode_error(what, e.to_string());
    ply_rs_bw::writer::Writer::<PointVertex>::new()
        .write_header(&mut out, header)
        .map_err(fail)?;
    fill(&mut out, header).map_err(fail)?;
    Ok(out)
}

/// The element definition `name` of `header` (always there: the writers
/// build the headers).
fn element<'h>(header: &'h Header, name: &str) -> std::io::Result<&'h ElementDef> {
    header
        .elements
        .get(name)
        .ok_or_else(|| std::io::Error::other(format!("no `{name}` element")))
}

/// A model point as a PLY vertex.
struct PointVertex(ModelPoint);

impl PropertyAccess for PointVertex {
    fn new() -> Self {
        Self(ModelPoint {
            position: [0.0; 3],
            scan: 0,
        })
    }
    fn get_double(&self, name: &str) -> Option<f64> {
        let p = self.0.position;
        match name {
            "x" => Some(p[0]),
            "y" => Some(p[1]),
            "z" => Some(p[2]),
            _ => None,
        }
    }
    fn get_uint(&self, name: &str) -> Option<u32> {
        (name == "scan").then_some(scan_number(self.0.scan))
    }
    fn get_uchar(&self, name: &str) -> Option<u8> {
        let [r, g, b] = scan_colour(scan_number(self.0.scan));
        match name {
            "red" => Some(r),
            "green" => Some(g),
            "blue" => Some(b),
            _ => None,
        }
    }
    fn get_ushort(&self, name: &str) -> Option<u16> {
        (name == "intensity").then(|| scan_intensity(scan_number(self.0.scan)))
    }
}

/// A station as a PLY vertex.
struct StationVertex(ModelStation);

impl PropertyAccess for StationVertex {
    fn new() -> Self {
        Self(ModelStation {
            scan: 0,
            truth: [0.0; 3],
            estimate: [0.0; 3],
            heading_error_rad: 0.0,
            position_sigma_m: None,
        })
    }
    fn get_double(&self, name: &str) -> Option<f64> {
        let s = &self.0;
        match name {
            "x" => Some(s.estimate[0]),
            "y" => Some(s.estimate[1]),
            "z" => Some(s.estimate[2]),
            "true_x" => Some(s.truth[0]),
            "true_y" => Some(s.truth[1]),
            "true_z" => Some(s.truth[2]),
            "heading_error" => Some(s.heading_error_rad),
            "sigma" => Some(s.position_sigma_m.unwrap_or(f64::NAN)),
            _ => None,
        }
    }
    fn get_uint(&self, name: &str) -> Option<u32> {
        (name == "scan").then_some(scan_number(self.0.scan))
    }
}

/// A PLY edge between two vertices.
struct Edge([i32; 2]);

impl PropertyAccess for Edge {
    fn new() -> Self {
        Self([0; 2])
    }
    fn get_int(&self, name: &str) -> Option<i32> {
        match name {
            "vertex1" => Some(self.0[0]),
            "vertex2" => Some(self.0[1]),
            _ => None,
        }
    }
}

/// The model's points as binary little-endian PLY: `vertex` with `double x,
/// y, z`, `uint scan`, `uchar red, green, blue` and `ushort intensity` (the
/// colour and intensity from the scan number).
pub fn encode_ply(points: &[ModelPoint]) -> Result<Vec<u8>, CloudError> {
    let what = "PLY output";
    check_finite(what, points.iter().map(|p| p.position))?;
    let header = ply_header(&[(
        "vertex",
        points.len(),
        &[
            ("x", ScalarType::Double),
            ("y", ScalarType::Double),
            ("z", ScalarType::Double),
            ("scan", ScalarType::UInt),
            ("red", ScalarType::UChar),
            ("green", ScalarType::UChar),
            ("blue", ScalarType::UChar),
            ("intensity", ScalarType::UShort),
        ],
    )]);
    write_ply(what, &header, |out, header| {
        write_elements(
            out,
            element(header, "vertex")?,
            points.iter().map(|&p| PointVertex(p)),
        )
    })
}

/// The scan stations as binary little-endian PLY: `vertex` with `double x, y,
/// z` (the estimate), `uint scan`, `double true_x, true_y, true_z`, `double
/// heading_error` (radians) and `double sigma` (metres, NaN when unknown); and
/// `edge` (`int vertex1, vertex2`) joining consecutive scans, so that viewers
/// draw the route.
pub fn encode_stations_ply(stations: &[ModelStation]) -> Result<Vec<u8>, CloudError> {
    let what = "stations PLY output";
    check_finite(what, stations.iter().map(|s| s.estimate))?;
    let Ok(count) = i32::try_from(stations.len()) else {
        return Err(encode_error(what, "too many stations for PLY edges"));
    };
    let edges = count.saturating_sub(1).max(0);
    let header = ply_header(&[
        (
            "vertex",
            stations.len(),
            &[
                ("x", ScalarType::Double),
                ("y", ScalarType::Double),
                ("z", ScalarType::Double),
                ("scan", ScalarType::UInt),
                ("true_x", ScalarType::Double),
                ("true_y", ScalarType::Double),
                ("true_z", ScalarType::Double),
                ("heading_error", ScalarType::Double),
                ("sigma", ScalarType::Double),
            ],
        ),
        (
            "edge",
            edges as usize,
            &[("vertex1", ScalarType::Int), ("vertex2", ScalarType::Int)],
        ),
    ]);
    write_ply(what, &header, |out, header| {
        write_elements(
            out,
            element(header, "vertex")?,
            stations.iter().map(|&s| StationVertex(s)),
        )?;
        write_elements(
            out,
            element(header, "edge")?,
            (0..edges).map(|i| Edge([i, i + 1])),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_colours_are_well_separated() {
        let colours: Vec<[u8; 3]> = (0..24).map(scan_colour).collect();
        for (i, a) in colours.iter().enumerate() {
            for b in &colours[i + 1..] {
                let d: i32 = a
                    .iter()
                    .zip(b)
                    .map(|(&x, &y)| (i32::from(x) - i32::from(y)).abs())
                    .sum();
                assert!(d >= 12, "{a:?} and {b:?} are too close");
            }
        }
        for w in colours.windows(2) {
            let d: i32 = w[0]
                .iter()
                .zip(&w[1])
                .map(|(&x, &y)| (i32::from(x) - i32::from(y)).abs())
                .sum();
            assert!(
                d >= 150,
                "consecutive scans {:?} and {:?} look alike",
                w[0],
                w[1]
            );
        }
        assert_eq!(scan_colour(7), scan_colour(7));
    }

    #[test]
    fn hsv_primaries() {
        assert_eq!(hsv_to_rgb(0.0, 1.0, 1.0), [255, 0, 0]);
        assert_eq!(hsv_to_rgb(1.0 / 3.0, 1.0, 1.0), [0, 255, 0]);
        assert_eq!(hsv_to_rgb(2.0 / 3.0, 1.0, 1.0), [0, 0, 255]);
    }

    #[test]
    fn intensities_differ_between_neighbouring_scans() {
        for s in 0..100 {
            let d = i32::from(scan_intensity(s)) - i32::from(scan_intensity(s + 1));
            assert!(d.abs() > 10_000, "scans {s} and {}", s + 1);
        }
    }

    #[test]
    fn huge_spans_and_non_finite_points_are_refused() {
        let p = |x: f64| ModelPoint {
            position: [x, 0.0, 0.0],
            scan: 0,
        };
        let e = encode_las(&[p(0.0), p(1e6)], false).unwrap_err();
        assert!(e.to_string().contains("LAS output: cannot encode"), "{e}");
        assert!(encode_ply(&[p(f64::NAN)]).is_err());
        assert!(encode_las(&[p(f64::INFINITY)], true).is_err());
    }

    #[test]
    fn empty_models_encode() {
        assert!(!encode_las(&[], true).unwrap().is_empty());
        assert!(!encode_ply(&[]).unwrap().is_empty());
        assert!(!encode_stations_ply(&[]).unwrap().is_empty());
    }
}
