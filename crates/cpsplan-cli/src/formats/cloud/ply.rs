//! PLY files (ascii, binary little and big endian), through `ply-rs-bw`.
//!
//! The points are the `vertex` element's `x`, `y` and `z` (of any scalar
//! type); its other properties are skipped. Vertices are read one at a time
//! into a typed element ([`Vertex`], 24 bytes) rather than the crate's
//! map-based default element, so memory stays that of the points. Elements
//! declared before `vertex` are read and dropped; those after it are not read.

use std::io::{BufRead, BufReader};

use ply_rs_bw::parser::{Parser, Reader};
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
    let mut line = String::new();
    for i in 0..promised {
        let truncated = CloudProblem::Truncated { promised, found: i };
        let v = match header.encoding {
            Encoding::Ascii => {
                line.clear();
                match reader.get_mut().read_line(&mut line) {
                    Ok(0) => return Err(truncated),
                    Ok(_) => parser.read_ascii_element(&line, vertex),
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
    fn a_vertex_is_three_doubles() {
        assert_eq!(std::mem::size_of::<Vertex>(), 24);
        let mut v = Vertex::new();
        assert_eq!(v.set_float("y", 2.5), PropertyAccessResult::Set);
        assert_eq!(v.set_uchar("red", 255), PropertyAccessResult::Ignored);
        assert_eq!(v.set_int("z", -3), PropertyAccessResult::Set);
        assert_eq!(v, Vertex([0.0, 2.5, -3.0]));
    }
}
