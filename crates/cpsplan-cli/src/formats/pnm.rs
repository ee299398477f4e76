//! The samples of a PGM/PPM/PAM image exactly as stored, with the header's
//! `maxval`: the `image` crate rescales samples to the full 8- or 16-bit range,
//! which would turn `mode: raw` occupancy percentages into other numbers and hide
//! samples above `maxval`. Bitmaps (P1, P4, black-and-white PAM) are left to the
//! `image` crate (`None`): their one-bit samples have no such ambiguity.

use std::io::{Cursor, Read};

use image::codecs::pnm::{ArbitraryTuplType, PnmDecoder, PnmSubtype, SampleEncoding};

/// Raw samples of a gray or colour anymap, rows from the top.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RawSamples {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Samples per pixel (1 gray, 2 gray + alpha, 3 RGB, 4 RGBA).
    pub channels: usize,
    /// The header's maxval: every sample is at most this.
    pub maxval: u32,
    /// `width × height × channels` samples.
    pub samples: Vec<u16>,
}

/// The layout of an anymap's samples, from its header.
struct Layout {
    width: u32,
    height: u32,
    channels: usize,
    maxval: u32,
    ascii: bool,
}

/// Reads the raw samples of a PNM/PAM image (`None` for bitmaps). `max_pixels`
/// bounds `width × height` before anything is allocated. Errors are one-line
/// descriptions of what is wrong with the file.
pub(crate) fn read_raw(bytes: &[u8], max_pixels: u64) -> Result<Option<RawSamples>, String> {
    let decoder = PnmDecoder::new(Cursor::new(bytes)).map_err(|e| e.to_string())?;
    let (mut reader, header) = decoder.into_inner();
    let layout = match header.subtype() {
        PnmSubtype::Bitmap(_) => return Ok(None),
        PnmSubtype::Graymap(encoding) | PnmSubtype::Pixmap(encoding) => Layout {
            width: header.width(),
            height: header.height(),
            channels: if matches!(header.subtype(), PnmSubtype::Pixmap(_)) {
                3
            } else {
                1
            },
            maxval: header.maximal_sample(),
            ascii: matches!(encoding, SampleEncoding::Ascii),
        },
        PnmSubtype::ArbitraryMap => {
            let Some(pam) = header.as_arbitrary() else {
                return Err("PAM header without its fields".into());
            };
            if pam.maxval <= 1
                || matches!(
                    pam.tupltype,
                    Some(ArbitraryTuplType::BlackAndWhite | ArbitraryTuplType::BlackAndWhiteAlpha)
                )
            {
                return Ok(None);
            }
            if !(1..=4).contains(&pam.depth) {
                return Err(format!("PAM depth {} (expected 1 to 4)", pam.depth));
            }
            Layout {
                width: pam.width,
                height: pam.height,
                channels: pam.depth as usize,
                maxval: pam.maxval,
                ascii: false,
            }
        }
    };
    if layout.maxval == 0 || layout.maxval > u32::from(u16::MAX) {
        return Err(format!("maxval {} (expected 1 to 65535)", layout.maxval));
    }
    let pixels = u64::from(layout.width) * u64::from(layout.height);
    if pixels > max_pixels {
        return Err(format!(
            "{} × {} pixels, more than `limits.max_grid_cells` = {max_pixels}",
            layout.width, layout.height
        ));
    }
    // Bounded by `max_pixels` (a `usize` cell count) times at most 4 channels.
    let count = usize::try_from(pixels)
        .ok()
        .and_then(|p| p.checked_mul(layout.channels))
        .ok_or("image too large for this machine")?;
    let samples = if layout.ascii {
        read_ascii(&mut reader, count)?
    } else {
        read_binary(&mut reader, count, layout.maxval > 255)?
    };
    if let Some(&bad) = samples.iter().find(|&&s| u32::from(s) > layout.maxval) {
        return Err(format!("sample {bad} above the maxval {}", layout.maxval));
    }
    Ok(Some(RawSamples {
        width: layout.width,
        height: layout.height,
        channels: layout.channels,
        maxval: layout.maxval,
        samples,
    }))
}

/// `count` binary samples: one byte each, or two (big-endian) when `wide`.
fn read_binary(reader: &mut impl Read, count: usize, wide: bool) -> Result<Vec<u16>, String> {
    let size = if wide { 2 } else { 1 };
    let mut raw = Vec::new();
    let want = count.checked_mul(size).ok_or("image too large")?;
    reader
        .take(want as u64)
        .read_to_end(&mut raw)
        .map_err(|e| e.to_string())?;
    if raw.len() < want {
        return Err(format!(
            "the image data ends after {} of {want} bytes",
            raw.len()
        ));
    }
    Ok(if wide {
        raw.chunks_exact(2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
            .collect()
    } else {
        raw.into_iter().map(u16::from).collect()
    })
}

/// `count` samples written as decimal numbers separated by whitespace.
fn read_ascii(reader: &mut impl Read, count: usize) -> Result<Vec<u16>, String> {
    let mut text = Vec::new();
    reader.read_to_end(&mut text).map_err(|e| e.to_string())?;
    let mut samples = Vec::with_capacity(count.min(text.len() / 2 + 1));
    for token in text
        .split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
        .take(count)
    {
        let value = std::str::from_utf8(token)
            .ok()
            .and_then(|t| t.parse::<u32>().ok())
            .ok_or_else(|| {
                format!(
                    "`{}` is not a sample value",
                    String::from_utf8_lossy(&token[..token.len().min(20)])
                )
            })?;
        let value = u16::try_from(value).map_err(|_| format!("sample {value} above 65535"))?;
        samples.push(value);
    }
    if samples.len() < count {
        return Err(format!(
            "the image data ends after {} of {count} samples",
            samples.len()
        ));
    }
    Ok(samples)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sixteen_bit_samples_stay_as_stored() {
        let mut bytes = b"P5\n2 1\n65535\n".to_vec();
        bytes.extend([0, 100, 0xff, 0xff]);
        let raw = read_raw(&bytes, 10).unwrap().unwrap();
        assert_eq!(raw.samples, vec![100, 65535]);
        assert_eq!(raw.maxval, 65535);
    }

    #[test]
    fn small_maxvals_are_not_rescaled() {
        let raw = read_raw(b"P2\n3 1\n100\n0 50 100\n", 10).unwrap().unwrap();
        assert_eq!((raw.samples, raw.maxval), (vec![0, 50, 100], 100));
    }

    #[test]
    fn samples_above_maxval_are_errors() {
        let e = read_raw(b"P2\n2 1\n100\n0 101\n", 10).unwrap_err();
        assert!(e.contains("101") && e.contains("100"), "{e}");
        let e = read_raw(b"P5\n1 1\n100\n\xff", 10).unwrap_err();
        assert!(e.contains("255"), "{e}");
    }

    #[test]
    fn sizes_are_checked_before_reading() {
        let e = read_raw(b"P5\n100000 100000\n255\n", 1_000_000).unwrap_err();
        assert!(e.contains("100000 × 100000"), "{e}");
        let e = read_raw(b"P5\n4 4\n255\n\0\0", 100).unwrap_err();
        assert!(e.contains("ends after 2 of 16"), "{e}");
    }

    #[test]
    fn colour_and_bitmaps() {
        let raw = read_raw(b"P3\n1 1\n255\n1 2 3\n", 10).unwrap().unwrap();
        assert_eq!((raw.channels, raw.samples), (3, vec![1, 2, 3]));
        assert_eq!(read_raw(b"P1\n2 1\n0 1\n", 10).unwrap(), None);
    }
}
