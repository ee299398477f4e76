//! A structural check of a PNG's chunks before it is decoded, for what the
//! `png` crate does not check itself and panics on: a palette (`PLTE`) whose
//! length is not a whole number of RGB entries (PNG specification 11.2.3: a
//! multiple of 3, at most 256 entries).

/// The PNG signature.
const SIGNATURE: &[u8; 8] = b"\x89PNG\r\n\x1a\n";

/// Checks the chunk layout of `bytes` (a PNG); a one-line description of the
/// first problem found. Truncated files pass: the decoder reports those.
pub(crate) fn check(bytes: &[u8]) -> Result<(), String> {
    let Some(mut rest) = bytes.strip_prefix(SIGNATURE) else {
        return Ok(());
    };
    while rest.len() >= 8 {
        let len = u32::from_be_bytes([rest[0], rest[1], rest[2], rest[3]]);
        let kind = &rest[4..8];
        if kind == b"PLTE" && (len == 0 || len % 3 != 0 || len > 768) {
            return Err(format!(
                "palette chunk of {len} bytes (it must hold 1 to 256 RGB entries, a multiple of 3 bytes)"
            ));
        }
        if kind == b"IEND" {
            break;
        }
        // Chunk: length, type, data, CRC.
        let Some(next) = usize::try_from(len).ok().and_then(|l| l.checked_add(12)) else {
            break;
        };
        if next > rest.len() {
            break;
        }
        rest = &rest[next..];
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chunk(kind: &[u8], data: &[u8]) -> Vec<u8> {
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        c.extend_from_slice(kind);
        c.extend_from_slice(data);
        c.extend_from_slice(&[0; 4]); // CRC: not checked here
        c
    }

    #[test]
    fn palettes_must_be_whole_rgb_entries() {
        let mut png = SIGNATURE.to_vec();
        png.extend(chunk(b"IHDR", &[0; 13]));
        let mut good = png.clone();
        good.extend(chunk(b"PLTE", &[0; 9]));
        assert_eq!(check(&good), Ok(()));
        png.extend(chunk(b"PLTE", &[0; 521]));
        let e = check(&png).unwrap_err();
        assert!(e.contains("521"), "{e}");
    }

    #[test]
    fn other_files_and_truncations_pass_to_the_decoder() {
        assert_eq!(check(b"P5\n1 1\n255\n\0"), Ok(()));
        assert_eq!(check(&SIGNATURE[..]), Ok(()));
        let mut png = SIGNATURE.to_vec();
        png.extend_from_slice(&[0xff, 0xff, 0xff, 0xff, b'I', b'D', b'A', b'T']);
        assert_eq!(check(&png), Ok(()));
    }
}
