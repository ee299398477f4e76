//! PCD files (ascii, binary and binary_compressed), through `pcd-rs`.
//!
//! The points are the `x`, `y` and `z` fields as stored (of any type; the
//! first value when a field has a count above one). The scan's origin is the
//! `VIEWPOINT` translation, PCL's sensor origin (0 0 0 when the line is
//! absent); its rotation is the sensor's orientation and is not applied.
//!
//! Before the crate reads the data, the header (parsed by the crate alone)
//! is checked for what the crate takes on trust: record sizes that overflow,
//! binary data shorter than the points promised, and compressed sizes beyond
//! the file or unequal to the points promised (the crate allocates both sizes
//! before reading, and indexes out of bounds on a short decompressed block).

use std::io::{BufReader, Read, Seek, SeekFrom};

use pcd_rs::{DataKind, DynReader, DynRecord, Field, PcdMeta};

use super::collect::{check_claim, Collector};
use super::{one_line, Cloud, CloudFormat, CloudProblem, CloudReadOptions, Source};

/// Largest record accepted, bytes (or values, in ascii).
const MAX_RECORD: u64 = 1 << 20;

/// Reads the points of a PCD file.
pub(crate) fn read<S: Source>(
    source: &S,
    options: &CloudReadOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Cloud, CloudProblem> {
    let len = source.len();
    let mut reader = BufReader::new(source.open().map_err(io)?);
    let meta = PcdMeta::from_reader(&mut reader).map_err(malformed)?;
    let data_start = reader.stream_position().map_err(io)?;
    let axes = axes(&meta)?;
    let promised = meta.num_points;
    if promised == 0 {
        return Err(CloudProblem::Empty);
    }
    check_claim(promised, options)?;
    let record = record_size(&meta)?;
    match meta.data {
        DataKind::Ascii => {}
        DataKind::Binary => {
            let available = len - data_start;
            let needed = promised
                .checked_mul(record)
                .ok_or_else(|| malformed("the point data's size overflows"))?;
            if needed > available {
                return Err(CloudProblem::Truncated {
                    promised,
                    found: available / record,
                });
            }
        }
        DataKind::BinaryCompressed => {
            check_compressed(&mut reader, promised, record, data_start, len)?
        }
    }
    let vp = &meta.viewpoint;
    let origin = [vp.tx, vp.ty, vp.tz];

    reader.seek(SeekFrom::Start(0)).map_err(io)?;
    let records = DynReader::from_reader(&mut reader).map_err(malformed)?;
    let mut collector = Collector::new(options, progress, promised)?;
    for (i, record) in records.enumerate() {
        let record = match record {
            Ok(r) => r,
            Err(e) => {
                let i = i as u64;
                let cut = matches!(&e, pcd_rs::Error::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof)
                    || matches!(&e, pcd_rs::Error::TextTokenMismatchError { found: 0, .. });
                if cut {
                    return Err(CloudProblem::Truncated { promised, found: i });
                }
                return Err(malformed(format!("point {i}: {e}")));
            }
        };
        collector.push(
            position(&record, axes).ok_or_else(|| malformed("a point lacks a coordinate"))?,
        )?;
    }
    collector.end_scan(Some(origin));
    collector.finish(CloudFormat::Pcd)
}

/// The indices of `x`, `y` and `z` among the fields the crate returns (all
/// but the `_` padding).
fn axes(meta: &PcdMeta) -> Result<[usize; 3], CloudProblem> {
    let mut found = [None; 3];
    for (i, field) in meta
        .field_defs
        .iter()
        .filter(|f| !f.is_padding())
        .enumerate()
    {
        match field.name.as_str() {
            "x" => found[0] = Some(i),
            "y" => found[1] = Some(i),
            "z" => found[2] = Some(i),
            _ => {}
        }
    }
    match found {
        [Some(x), Some(y), Some(z)] => Ok([x, y, z]),
        _ => Err(CloudProblem::unsupported(
            CloudFormat::Pcd,
            "the fields do not include x, y and z",
        )),
    }
}

/// Bytes of one binary record (values of one ascii line), checked for
/// overflow and [`MAX_RECORD`].
fn record_size(meta: &PcdMeta) -> Result<u64, CloudProblem> {
    let mut bytes = 0u64;
    let mut values = 0u64;
    for f in meta.field_defs.iter() {
        let size = (f.kind.byte_size() as u64).checked_mul(f.count);
        bytes = size.and_then(|s| bytes.checked_add(s)).unwrap_or(u64::MAX);
        values = values.saturating_add(f.count);
    }
    if bytes > MAX_RECORD || values > MAX_RECORD {
        return Err(CloudProblem::unsupported(
            CloudFormat::Pcd,
            format!(
                "records of {} bytes (at most {MAX_RECORD} are read)",
                number(bytes)
            ),
        ));
    }
    Ok(bytes)
}

/// Prints a size that may be the overflow marker.
fn number(v: u64) -> String {
    if v == u64::MAX {
        "more than 2^64".into()
    } else {
        v.to_string()
    }
}

/// Checks the sizes before LZF-compressed data: the compressed block within
/// the file, the decompressed one exactly the points promised.
fn check_compressed<R: Read + Seek>(
    r: &mut R,
    promised: u64,
    record: u64,
    data_start: u64,
    len: u64,
) -> Result<(), CloudProblem> {
    let mut sizes = [0; 8];
    r.seek(SeekFrom::Start(data_start)).map_err(io)?;
    if r.read_exact(&mut sizes).is_err() {
        return Err(CloudProblem::TruncatedBytes {
            what: "the compressed data's sizes",
            needed: 8,
            available: len - data_start,
        });
    }
    let compressed = u64::from(u32::from_le_bytes([sizes[0], sizes[1], sizes[2], sizes[3]]));
    let uncompressed = u64::from(u32::from_le_bytes([sizes[4], sizes[5], sizes[6], sizes[7]]));
    let available = len - data_start - 8;
    if compressed > available {
        return Err(CloudProblem::TruncatedBytes {
            what: "the compressed point data",
            needed: compressed,
            available,
        });
    }
    if promised.checked_mul(record) != Some(uncompressed) {
        return Err(malformed(format!(
            "the compressed data expands to {uncompressed} bytes, not the {promised} × {record} of the points"
        )));
    }
    Ok(())
}

/// The point of `record`, from the fields at `axes`.
fn position(record: &DynRecord, axes: [usize; 3]) -> Option<[f64; 3]> {
    let value = |i: usize| first_value(record.0.get(i)?);
    Some([value(axes[0])?, value(axes[1])?, value(axes[2])?])
}

/// A field's first value as `f64`.
fn first_value(field: &Field) -> Option<f64> {
    Some(match field {
        Field::I8(v) => f64::from(*v.first()?),
        Field::I16(v) => f64::from(*v.first()?),
        Field::I32(v) => f64::from(*v.first()?),
        Field::I64(v) => *v.first()? as f64,
        Field::U8(v) => f64::from(*v.first()?),
        Field::U16(v) => f64::from(*v.first()?),
        Field::U32(v) => f64::from(*v.first()?),
        Field::U64(v) => *v.first()? as f64,
        Field::F32(v) => f64::from(*v.first()?),
        Field::F64(v) => *v.first()?,
    })
}

/// The crate's complaint, as a malformed-PCD error.
fn malformed(e: impl std::fmt::Display) -> CloudProblem {
    CloudProblem::malformed(CloudFormat::Pcd, e)
}

/// A read failure.
fn io(e: std::io::Error) -> CloudProblem {
    CloudProblem::Io(one_line(e))
}
