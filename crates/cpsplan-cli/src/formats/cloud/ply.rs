//! PLY files (ascii, binary little and big endian), through `ply-rs-bw`.
//!
//! The points are the `vertex` element's `x`, `y` and `z` (of any scalar
//! type); its other properties are skipped. Vertices are read one at a time
//! into a typed element ([`Vertex`], 24 bytes) rather than the crate's
//! map-based default element, so memory stays that of the points. Elements
//! declared before `vertex` are read and dropped; those after it are not read.

use std::io::{BufRead, BufReader};

use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{ElementDef, Encoding, PropertyAccess, PropertyAccessResult, PropertyType};

use super::collect::{check_claim, Collector};
use super::{one_line, Cloud, CloudFormat, CloudProblem, CloudReadOptions, Source};

/// One vertex's position.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Vertex([f64; 3]);

impl Vertex {
    /// Sets the coordinate `name` names, if it is one.
    fn set(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        let axis = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return PropertyAccessResult::Ignored,
        };
        self.0[axis] = value;
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Self::default()
    }
    fn set_char(&mut self, name: &str, v: i8) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_uchar(&mut self, name: &str, v: u8) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_short(&mut self, name: &str, v: i16) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_ushort(&mut self, name: &str, v: u16) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_int(&mut self, name: &str, v: i32) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_uint(&mut self, name: &str, v: u32) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_float(&mut self, name: &str, v: f32) -> PropertyAccessResult {
        self.set(name, f64::from(v))
    }
    fn set_double(&mut self, name: &str, v: f64) -> PropertyAccessResult {
        self.set(name, v)
    }
}

/// An element that keeps nothing (for elements before `vertex`).
#[derive(Debug, Clone, Copy, Default)]
struct Skipped;

impl PropertyAccess for Skipped {
    fn new() -> Self {
        Self
    }
}

/// Reads the vertices of a PLY file.
pub(crate) fn read<S: Source>(
    source: &S,
    options: &CloudReadOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Cloud, CloudProblem> {
    let file = source.open().map_err(|e| CloudProblem::Io(one_line(e)))?;
    let mut reader = Reader::new(BufReader::new(file));
    let header = Parser::<Vertex>::new()
        .read_header(&mut reader)
        .map_err(malformed)?;
    let Some(vertex) = header.elements.get("vertex") else {
        return Err(unsupported("no `vertex` element"));
    };
    for axis in ["x", "y", "z"] {
        match vertex.properties.get(axis).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(_)) => {}
            Some(PropertyType::List(..)) => {
                return Err(unsupported(format!("vertex property `{axis}` is a list")))
            }
            None => return Err(unsupported(format!("vertices have no `{axis}` property"))),
        }
    }
    let promised = vertex.count as u64;
    if promised == 0 {
        return Err(CloudProblem::Empty);
    }
    check_claim(promised, options)?;
    for (name, element) in &header.elements {
        if name == "vertex" {
            break;
        }
        skip(&mut reader, element, header.encoding, options)?;
    }

    let mut collector = Collector::new(options, progress, promised)?;
    let parser = Parser::<Vertex>::new();
    let axes = axis_tokens(vertex);
    let mut line = String::new();
    for i in 0..promised {
        let truncated = CloudProblem::Truncated { promised, found: i };
        let v = match header.encoding {
            Encoding::Ascii => {
                line.clear();
                match reader.get_mut().read_line(&mut line) {
                    Ok(0) => return Err(truncated),
                    Ok(_) => read_ascii_vertex(&parser, &line, vertex, axes),
                    Err(e) => return Err(malformed(e)),
                }
            }
            Encoding::BinaryLittleEndian => {
                parser.read_little_endian_element(reader.get_mut(), vertex)
            }
            Encoding::BinaryBigEndian => parser.read_big_endian_element(reader.get_mut(), vertex),
        };
        match v {
            Ok(v) => collector.push(v.0)?,
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Err(truncated),
            Err(e) => return Err(malformed(format!("vertex {i}: {e}"))),
        }
    }
    collector.end_scan(None);
    collector.finish(CloudFormat::Ply)
}

/// The token positions of `x`, `y` and `z` in an ascii vertex line, when
/// every property up to them is a scalar (one token each).
fn axis_tokens(vertex: &ElementDef) -> Option<[usize; 3]> {
    let mut axes = [None; 3];
    for (i, (name, p)) in vertex.properties.iter().enumerate() {
        if axes.iter().all(Option::is_some) {
            break;
        }
        if !matches!(p.data_type, PropertyType::Scalar(_)) {
            return None;
        }
        match name.as_str() {
            "x" => axes[0] = Some(i),
            "y" => axes[1] = Some(i),
            "z" => axes[2] = Some(i),
            _ => {}
        }
    }
    Some([axes[0]?, axes[1]?, axes[2]?])
}

/// One ascii vertex. The crate's grammar takes only digits, signs, points
/// and exponents, while writers print non-finite values as `nan`, `inf` and
/// the like: a line the crate refuses is read again with those tokens as 0,
/// and the coordinates they stood for set to their values.
fn read_ascii_vertex(
    parser: &Parser<Vertex>,
    line: &str,
    vertex: &ElementDef,
    axes: Option<[usize; 3]>,
) -> Result<Vertex, ParseError> {
    let refused = match parser.read_ascii_element(line, vertex) {
        Ok(v) => return Ok(v),
        Err(e) => e,
    };
    let Some(axes) = axes else {
        return Err(refused);
    };
    let tokens: Vec<&str> = line.split_whitespace().collect();
    let odd: Vec<(usize, f64)> = tokens
        .iter()
        .enumerate()
        .filter_map(|(i, t)| Some((i, t.parse::<f64>().ok().filter(|v| !v.is_finite())?)))
        .collect();
    if odd.is_empty() {
        return Err(refused);
    }
    let cleaned: Vec<&str> = tokens
        .iter()
        .enumerate()
        .map(|(i, t)| if odd.iter().any(|o| o.0 == i) { "0" } else { t })
        .collect();
    let Ok(mut v) = parser.read_ascii_element(&cleaned.join(" "), vertex) else {
        return Err(refused);
    };
    for (i, value) in odd {
        if let Some(k) = axes.iter().position(|&a| a == i) {
            v.0[k] = value;
        }
    }
    Ok(v)
}

/// Reads and drops the elements of `element`.
fn skip<B: BufRead>(
    reader: &mut Reader<B>,
    element: &ElementDef,
    encoding: Encoding,
    options: &CloudReadOptions,
) -> Result<(), CloudProblem> {
    // Elements without properties take no bytes: a huge count must not spin.
    if element.count as u64 > options.max_points {
        return Err(unsupported(format!(
            "{} `{}` elements before the vertices",
            element.count, element.name
        )));
    }
    let parser = Parser::<Skipped>::new();
    let mut line = String::new();
    for _ in 0..element.count {
        let done = match encoding {
            Encoding::Ascii => {
                line.clear();
                match reader.get_mut().read_line(&mut line) {
                    Ok(0) => {
                        return Err(malformed(format!(
                            "ends inside the `{}` elements",
                            element.name
                        )))
                    }
                    Ok(_) => parser.read_ascii_element(&line, element).map(drop),
                    Err(e) => return Err(malformed(e)),
                }
            }
            Encoding::BinaryLittleEndian => parser
                .read_little_endian_element(reader.get_mut(), element)
                .map(drop),
            Encoding::BinaryBigEndian => parser
                .read_big_endian_element(reader.get_mut(), element)
                .map(drop),
        };
        done.map_err(malformed)?;
    }
    Ok(())
}

/// The crate's complaint, as a malformed-PLY error.
fn malformed(e: impl std::fmt::Display) -> CloudProblem {
    CloudProblem::malformed(CloudFormat::Ply, e)
}

/// A PLY file this reader cannot take.
fn unsupported(message: impl Into<String>) -> CloudProblem {
    CloudProblem::unsupported(CloudFormat::Ply, message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_ascii_coordinates_are_read() {
        let parser = Parser::<Vertex>::new();
        let header = parser
            .read_header(&mut Reader::new(
                &b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float nx\nproperty float x\nproperty float y\nproperty float z\nproperty list uchar int ids\nend_header\n"[..],
            ))
            .unwrap();
        let vertex = &header.elements["vertex"];
        let axes = axis_tokens(vertex);
        assert_eq!(axes, Some([1, 2, 3]));
        let v = read_ascii_vertex(&parser, "nan 1 -inf 3 1 7\n", vertex, axes).unwrap();
        assert_eq!(v.0[0], 1.0);
        assert_eq!(v.0[1], f64::NEG_INFINITY);
        assert_eq!(v.0[2], 3.0);
        let v = read_ascii_vertex(&parser, "0 NaN 2 3 0\n", vertex, axes).unwrap();
        assert!(v.0[0].is_nan());
        assert!(read_ascii_vertex(&parser, "0 x 2 3 0\n", vertex, axes).is_err());
    }

    #[test]
    fn a_vertex_is_three_doubles() {
        assert_eq!(std::mem::size_of::<Vertex>(), 24);
        let mut v = Vertex::new();
        assert_eq!(v.set_float("y", 2.5), PropertyAccessResult::Set);
        assert_eq!(v.set_uchar("red", 255), PropertyAccessResult::Ignored);
        assert_eq!(v.set_int("z", -3), PropertyAccessResult::Set);
        assert_eq!(v, Vertex([0.0, 2.5, -3.0]));
    }
}
