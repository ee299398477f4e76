//! A structural check of a LAZ file's compressed point data before the `laz`
//! decoder sees it, for what the decoder does not check itself:
//! - a LASzip record whose items do not add up to the point record length
//!   (with no items at all the decoder panics, with a wrong total it reads past
//!   its buffers);
//! - a chunk table that claims more chunks than the file could hold (the
//!   decoder reserves memory for every claimed chunk first);
//! - variable-size chunks whose table covers fewer points than the header
//!   promises (the decoder indexes past the table's end and panics);
//! - layered chunks (point formats 6–10) whose layer sizes exceed the file (the
//!   decoder allocates every layer's size before reading it).
//!
//! The layout followed is LASzip's: the point data starts with the 8-byte
//! offset of the chunk table (or, when the writer could not update it, the
//! table's offset is the file's last 8 bytes); the table starts with a version
//! and the number of chunks. A layered chunk holds its first point raw, then
//! its point count, one 32-bit size per layer, then the layers.

use std::io::{Read, Seek, SeekFrom};

use laz::laszip::ChunkTable;
use laz::{LazItemType, LazVlr};

use super::{CloudFormat, CloudProblem};

/// What a check found wrong: the problem to report.
type Checked<T> = Result<T, CloudProblem>;

/// Checks the compressed point data of a LAZ file of `len` bytes whose header
/// promises `points` records of `record_len` bytes from `data_start`.
pub(crate) fn check<R: Read + Seek>(
    r: &mut R,
    vlr: &LazVlr,
    points: u64,
    record_len: u16,
    data_start: u64,
    len: u64,
) -> Checked<()> {
    if vlr.items_size() != u64::from(record_len) {
        return Err(bad(format!(
            "the LASzip items describe {}-byte points, the header {record_len}-byte ones",
            vlr.items_size()
        )));
    }
    let table = chunk_table(r, vlr, points, data_start, len)?;
    let layered = vlr.items().first().is_some_and(|i| i.version() >= 3);
    if layered {
        walk_layers(r, vlr, table.as_ref(), points, record_len, data_start, len)?;
    }
    Ok(())
}

/// A problem with the compressed data, as a malformed-LAZ error.
fn bad(message: String) -> CloudProblem {
    CloudProblem::malformed(CloudFormat::Laz, message)
}

/// Reads a little-endian integer of `N` bytes at `pos`, `None` past the end.
fn read_at<R: Read + Seek, const N: usize>(r: &mut R, pos: u64, len: u64) -> Option<[u8; N]> {
    if pos.checked_add(N as u64)? > len {
        return None;
    }
    r.seek(SeekFrom::Start(pos)).ok()?;
    let mut b = [0; N];
    r.read_exact(&mut b).ok()?;
    Some(b)
}

/// Checks the chunk table's size where the decoder will look for it; for
/// variable-size chunks, decodes it and checks that it covers `points`.
fn chunk_table<R: Read + Seek>(
    r: &mut R,
    vlr: &LazVlr,
    points: u64,
    data_start: u64,
    len: u64,
) -> Checked<Option<ChunkTable>> {
    let offset_at = |r: &mut R, pos| read_at::<R, 8>(r, pos, len).map(i64::from_le_bytes);
    let Some(first) = offset_at(r, data_start) else {
        return Err(CloudProblem::Truncated {
            promised: points,
            found: 0,
        });
    };
    let start = data_start as i64;
    let offset = if first > start {
        Some(first)
    } else {
        len.checked_sub(8)
            .and_then(|end| offset_at(r, end))
            .filter(|&o| o > start)
    };
    let Some(offset) = offset.map(|o| o as u64) else {
        // No table: the decoder goes on without one, or says it needs one.
        return Ok(None);
    };
    let Some(count) = read_at::<R, 4>(r, offset.saturating_add(4), len).map(u32::from_le_bytes)
    else {
        // No readable table: the decoder goes on without one (or says so).
        return Ok(None);
    };
    let most = points.saturating_add(1).min(len);
    if u64::from(count) > most {
        return Err(bad(format!(
            "the chunk table claims {count} chunks, more than the file can hold"
        )));
    }
    if !vlr.uses_variable_size_chunks() {
        return Ok(None);
    }
    r.seek(SeekFrom::Start(data_start))
        .map_err(|e| CloudProblem::Io(e.to_string()))?;
    let table = ChunkTable::read_from(&mut *r, vlr)
        .map_err(|e| bad(format!("unreadable chunk table: {e}")))?;
    let covered = table
        .as_ref()
        .iter()
        .fold(0u64, |sum, e| sum.saturating_add(e.point_count));
    if covered < points {
        return Err(bad(format!(
            "the chunk table covers {covered} points, the header promises {points}"
        )));
    }
    Ok(Some(table))
}

/// Layer-size fields a layered item's chunk header holds.
fn layers_of(item: LazItemType) -> u64 {
    match item {
        LazItemType::Point14 => 9,
        LazItemType::RGBNIR14 => 2,
        LazItemType::Byte14(n) => u64::from(n),
        _ => 1,
    }
}

/// Walks the chunks of layered data as the decoder will, checking that each
/// chunk's layers lie within the file.
fn walk_layers<R: Read + Seek>(
    r: &mut R,
    vlr: &LazVlr,
    table: Option<&ChunkTable>,
    points: u64,
    record_len: u16,
    data_start: u64,
    len: u64,
) -> Checked<()> {
    let layers: u64 = vlr.items().iter().map(|i| layers_of(i.item_type())).sum();
    let fixed = (!vlr.uses_variable_size_chunks()).then(|| u64::from(vlr.chunk_size()));
    let mut pos = data_start + 8;
    let mut covered = 0u64;
    let mut chunk = 0usize;
    while covered < points {
        let in_chunk = match (fixed, table) {
            (Some(n), _) if n > 0 => n,
            (None, Some(t)) => t.as_ref().get(chunk).map_or(0, |e| e.point_count),
            _ => 0,
        };
        // A chunk of unknown size runs to the end of the points.
        let in_chunk = if in_chunk == 0 {
            points - covered
        } else {
            in_chunk
        };
        let truncated = CloudProblem::Truncated {
            promised: points,
            found: covered,
        };
        let sizes_at = pos + u64::from(record_len) + 4;
        let mut end = sizes_at + 4 * layers;
        if end > len {
            return Err(truncated);
        }
        for k in 0..layers {
            let size = read_at::<R, 4>(r, sizes_at + 4 * k, len)
                .ok_or_else(|| bad("unreadable layer sizes".to_string()))?;
            end += u64::from(u32::from_le_bytes(size));
        }
        if end > len {
            return Err(truncated);
        }
        pos = end;
        covered = covered.saturating_add(in_chunk);
        chunk += 1;
    }
    Ok(())
}
