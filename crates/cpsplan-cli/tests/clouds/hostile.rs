//! Damaged and hostile clouds: claims larger than the file, truncations, bit
//! flips, and every size a decoder would trust, refused in one line and never
//! a panic.

use super::*;

/// A LAS 1.4 file of two points whose header then claims `claimed` points.
fn las14_claiming(claimed: u64) -> Vec<u8> {
    let mut builder = las::Builder::from((1, 4));
    builder.point_format = las::point::Format::new(0).unwrap();
    let mut writer = las::Writer::new(
        std::io::Cursor::new(Vec::new()),
        builder.into_header().unwrap(),
    )
    .unwrap();
    for x in [1.0, 2.0] {
        writer
            .write_point(las::Point {
                x,
                ..las::Point::default()
            })
            .unwrap();
    }
    let mut bytes = writer.into_inner().unwrap().into_inner();
    bytes[107..111].copy_from_slice(&0u32.to_le_bytes()); // legacy count
    bytes[247..255].copy_from_slice(&claimed.to_le_bytes());
    bytes
}

#[test]
fn huge_point_claims_are_refused_before_allocating() {
    let e = parse_cloud(
        &las14_claiming(1_000_000_000_000),
        CloudFormat::Las,
        &CloudReadOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "LAS data: holds 1000000000000 points, more than `limits.max_cloud_points` = 200000000"
    );
    let unlimited = CloudReadOptions {
        max_points: u64::MAX,
        ..CloudReadOptions::default()
    };
    let e = parse_cloud(
        &las14_claiming(1_000_000_000_000),
        CloudFormat::Las,
        &unlimited,
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "LAS data: truncated: the header promises 1000000000000 points, the file ends after 2"
    );
    // A count whose size overflows 64 bits.
    let e = parse_cloud(&las14_claiming(u64::MAX), CloudFormat::Las, &unlimited).unwrap_err();
    assert_one_line(&e, "LAS data");
    assert!(parse_cloud(&las14_claiming(2), CloudFormat::Las, &unlimited).is_ok());

    // A LAS 1.2 header claiming 4 billion points.
    let mut las12 = encode_las(&model(1, 10), false).unwrap();
    las12[107..111].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = parse_cloud(&las12, CloudFormat::Las, &CloudReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("limits.max_cloud_points"), "{e}");
    let e = parse_cloud(&las12, CloudFormat::Las, &unlimited).unwrap_err();
    assert_eq!(
        e.to_string(),
        "LAS data: truncated: the header promises 4294967295 points, the file ends after 10"
    );
}

/// Copies of `bytes` cut at a spread of lengths, from the first byte to one
/// short of the end.
fn cuts(bytes: &[u8]) -> Vec<usize> {
    let n = bytes.len();
    let mut at: Vec<usize> = [1, 7, 100, 230, 400, 1000, 4096]
        .into_iter()
        .chain([0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99].map(|f| (n as f64 * f) as usize))
        .chain([n - 100, n - 8, n - 1])
        .filter(|&c| c > 0 && c < n)
        .collect();
    at.sort_unstable();
    at.dedup();
    at
}

/// Every copy of `bytes` cut before `points_end` (where the data the points
/// need ends) is refused with a one-line message, and those cut after
/// `points_from` (inside the point data of a format whose size the header
/// fixes) say how many of the `points` the file holds; copies cut later read
/// all the points.
fn check_truncations(
    bytes: &[u8],
    format: CloudFormat,
    points: u64,
    points_from: usize,
    points_end: usize,
) {
    let name = format!("{format} data");
    let whole = parse_cloud(bytes, format, &CloudReadOptions::default()).unwrap();
    for cut in cuts(bytes) {
        let result = parse_cloud(&bytes[..cut], format, &CloudReadOptions::default());
        if cut >= points_end {
            match result {
                Ok(cloud) => assert_eq!(cloud.points, whole.points, "cut at {cut}"),
                Err(e) => assert_one_line(&e, &name),
            }
            continue;
        }
        let Err(e) = result else {
            panic!("{format} cut at {cut} of {} was read", bytes.len());
        };
        assert_one_line(&e, &name);
        if cut > points_from {
            let m = e.to_string();
            let prefix = format!(
                "{name}: truncated: the header promises {points} points, the file ends after "
            );
            let found: u64 = m
                .strip_prefix(&prefix)
                .and_then(|n| n.parse().ok())
                .unwrap_or_else(|| panic!("cut at {cut}: {m}"));
            assert!(found < points, "cut at {cut}: {m}");
        }
    }
}

/// Where a LAZ file's compressed points end: at its chunk table.
fn laz_points_end(bytes: &[u8]) -> usize {
    let data = u32::from_le_bytes(bytes[96..100].try_into().unwrap()) as usize;
    i64::from_le_bytes(bytes[data..data + 8].try_into().unwrap()) as usize
}

/// Where the data of a PCD file ends (its header and binary or compressed data).
fn pcd_points_end(bytes: &[u8], record: usize, points: usize) -> usize {
    let header = bytes.windows(5).position(|w| w == b"DATA ").unwrap();
    let data = header + bytes[header..].iter().position(|&b| b == b'\n').unwrap() + 1;
    if bytes[header..data].starts_with(b"DATA binary_compressed") {
        let compressed = u32::from_le_bytes(bytes[data..data + 4].try_into().unwrap());
        data + 8 + compressed as usize
    } else {
        data + record * points
    }
}

#[test]
fn truncated_shared_clouds_are_refused() {
    let Some(dir) = shared_clouds("truncated_shared_clouds_are_refused") else {
        return;
    };
    let autzen = std::fs::read(dir.join(AUTZEN.0)).unwrap();
    // Past the header, the VLRs and the first few points.
    let laz_data = u32::from_le_bytes(autzen[96..100].try_into().unwrap()) as usize;
    let end = laz_points_end(&autzen);
    check_truncations(&autzen, CloudFormat::Laz, AUTZEN.1, laz_data + 100, end);
    let (room, velodyne, pump) = (SHARED[0], SHARED[1], SHARED[2]);
    let bytes = std::fs::read(dir.join(velodyne.0)).unwrap();
    let end = pcd_points_end(&bytes, 16, velodyne.1 as usize);
    assert_eq!(end, bytes.len());
    check_truncations(&bytes, CloudFormat::Pcd, velodyne.1, 300, end);
    let bytes = std::fs::read(dir.join(room.0)).unwrap();
    let end = pcd_points_end(&bytes, 12, room.1 as usize);
    check_truncations(&bytes, CloudFormat::Pcd, room.1, usize::MAX, end);
    let bytes = std::fs::read(dir.join(pump.0)).unwrap();
    check_truncations(&bytes, CloudFormat::E57, pump.1, usize::MAX, bytes.len());
}

#[test]
fn truncated_encoded_models_are_refused() {
    let points = model(4, 2000);
    let las = encode_las(&points, false).unwrap();
    check_truncations(&las, CloudFormat::Las, 8000, 227, las.len());
    let laz = encode_las(&points, true).unwrap();
    let data = u32::from_le_bytes(laz[96..100].try_into().unwrap()) as usize;
    check_truncations(
        &laz,
        CloudFormat::Laz,
        8000,
        data + 100,
        laz_points_end(&laz),
    );
    let ply = encode_ply(&points).unwrap();
    let header_end = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    check_truncations(&ply, CloudFormat::Ply, 8000, header_end, ply.len());
    let positions: Vec<[f64; 3]> = points.iter().map(|p| p.position).collect();
    let pcd = binary_pcd(&positions, false);
    check_truncations(&pcd, CloudFormat::Pcd, 8000, 200, pcd.len());
    let pcd = binary_pcd(&positions, true);
    check_truncations(&pcd, CloudFormat::Pcd, 8000, usize::MAX, pcd.len());
}

/// A small deterministic generator for byte flips.
struct Flips(u64);

impl Flips {
    fn next(&mut self) -> u64 {
        // xorshift64*
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// `bytes` with 1 to 8 bytes changed, half the time within the first 4 KiB.
    fn damage(&mut self, bytes: &[u8]) -> Vec<u8> {
        let mut out = bytes.to_vec();
        let span = if self.next().is_multiple_of(2) {
            out.len().min(4096)
        } else {
            out.len()
        };
        for _ in 0..1 + self.next() % 8 {
            let at = (self.next() % span as u64) as usize;
            out[at] ^= 1 << (self.next() % 8);
            if self.next().is_multiple_of(4) {
                out[at] = self.next() as u8;
            }
        }
        out
    }
}

/// Damaged copies of `bytes` read to a cloud or a one-line error, never a
/// panic.
fn check_flips(bytes: &[u8], format: CloudFormat, copies: usize, seed: u64) {
    let mut flips = Flips(seed);
    let name = format!("{format} data");
    for _ in 0..copies {
        let damaged = flips.damage(bytes);
        if let Err(e) = parse_cloud(&damaged, format, &CloudReadOptions::default()) {
            assert_one_line(&e, &name);
        }
    }
}

#[test]
fn damaged_shared_clouds_never_panic() {
    let Some(dir) = shared_clouds("damaged_shared_clouds_never_panic") else {
        return;
    };
    for (i, file) in [AUTZEN.0, SHARED[0].0, SHARED[1].0, SHARED[2].0]
        .into_iter()
        .enumerate()
    {
        let bytes = std::fs::read(dir.join(file)).unwrap();
        let format = CloudFormat::from_path(Path::new(file)).unwrap();
        check_flips(&bytes, format, 24, 0x5eed + i as u64);
    }
}

#[test]
fn damaged_encoded_models_never_panic() {
    let points = model(3, 500);
    let positions: Vec<[f64; 3]> = points.iter().map(|p| p.position).collect();
    let inputs = [
        (encode_las(&points, false).unwrap(), CloudFormat::Las),
        (encode_las(&points, true).unwrap(), CloudFormat::Laz),
        (encode_ply(&points).unwrap(), CloudFormat::Ply),
        (binary_pcd(&positions, false), CloudFormat::Pcd),
        (binary_pcd(&positions, true), CloudFormat::Pcd),
        (ASCII_PCD.as_bytes().to_vec(), CloudFormat::Pcd),
        (ASCII_PLY.as_bytes().to_vec(), CloudFormat::Ply),
    ];
    for (i, (bytes, format)) in inputs.iter().enumerate() {
        check_flips(bytes, *format, 200, 0xf00d + i as u64);
    }
}

/// Small inputs: random bytes, or a valid file's first bytes and random ones.
fn arb_input() -> impl Strategy<Value = (Vec<u8>, CloudFormat)> {
    let formats = prop_oneof![
        Just(CloudFormat::Las),
        Just(CloudFormat::Laz),
        Just(CloudFormat::E57),
        Just(CloudFormat::Ply),
        Just(CloudFormat::Pcd),
    ];
    (
        formats,
        proptest::collection::vec(any::<u8>(), 0..600),
        0usize..700,
    )
        .prop_map(|(format, tail, keep)| {
            let valid = match format {
                CloudFormat::Las => encode_las(&model(2, 3), false).unwrap(),
                CloudFormat::Laz => encode_las(&model(2, 3), true).unwrap(),
                CloudFormat::Ply => encode_ply(&model(2, 3)).unwrap(),
                CloudFormat::Pcd => ASCII_PCD.as_bytes().to_vec(),
                CloudFormat::E57 => b"ASTM-E57".to_vec(),
            };
            let mut bytes = valid[..keep.min(valid.len())].to_vec();
            if keep % 3 == 0 {
                bytes.clear();
            }
            bytes.extend(tail);
            (bytes, format)
        })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 600,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_bytes_never_panic((bytes, format) in arb_input()) {
        if let Err(e) = parse_cloud(&bytes, format, &CloudReadOptions::default()) {
            let m = e.to_string();
            prop_assert!(!m.contains('\n'), "{}", m);
        }
    }
}

/// Where the data of the LASzip VLR of a LAZ file start.
fn laszip_record(bytes: &[u8]) -> usize {
    let user_id = bytes
        .windows(14)
        .position(|w| w == b"laszip encoded")
        .unwrap();
    user_id - 2 + 54
}

/// A LAZ 1.4 file of point format 6 (layered chunks of 50 000 points).
fn layered_laz(points: u32) -> Vec<u8> {
    let mut builder = las::Builder::from((1, 4));
    builder.point_format = las::point::Format::new(6).unwrap();
    builder.point_format.is_compressed = true;
    let header = builder.into_header().unwrap();
    let mut writer = las::Writer::new(std::io::Cursor::new(Vec::new()), header).unwrap();
    for i in 0..points {
        writer
            .write_point(las::Point {
                x: f64::from(i) * 0.01,
                y: f64::from(i % 100),
                z: f64::from(i % 7),
                gps_time: Some(f64::from(i)),
                ..las::Point::default()
            })
            .unwrap();
    }
    writer.into_inner().unwrap().into_inner()
}

#[test]
fn layered_laz_reads_and_its_layer_sizes_are_checked() {
    let bytes = layered_laz(60_000);
    let cloud = parse_cloud(&bytes, CloudFormat::Laz, &CloudReadOptions::default()).unwrap();
    assert_eq!(cloud.points.len(), 60_000);
    assert_eq!(cloud.points[12_345], [123.45, 45.0, 4.0]);
    // The second chunk cut off: the first's 50 000 points are there.
    let half = parse_cloud(
        &bytes[..bytes.len() * 9 / 10],
        CloudFormat::Laz,
        &CloudReadOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        half.to_string(),
        "LAZ data: truncated: the header promises 60000 points, the file ends after 50000"
    );
    // A first layer claiming 4 GB (the decoder would allocate it first).
    let data = u32::from_le_bytes(bytes[96..100].try_into().unwrap()) as usize;
    let record = usize::from(u16::from_le_bytes(bytes[105..107].try_into().unwrap()));
    let mut huge = bytes.clone();
    let first_layer = data + 8 + record + 4;
    huge[first_layer..first_layer + 4].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
    let e = parse_cloud(&huge, CloudFormat::Laz, &CloudReadOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "LAZ data: truncated: the header promises 60000 points, the file ends after 0"
    );
}

#[test]
fn laszip_records_the_decoder_trusts_are_checked() {
    let bytes = encode_las(&model(2, 100), true).unwrap();
    let record = laszip_record(&bytes);
    // No items (the decoder panics on these).
    let mut none = bytes.clone();
    none[record + 32..record + 34].copy_from_slice(&0u16.to_le_bytes());
    let e = parse_cloud(&none, CloudFormat::Laz, &CloudReadOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "LAZ data: not a valid LAZ file: the LASzip items describe 0-byte points, the header 34-byte ones"
    );
    // Items that add up to another point size: the RGB item left out.
    let mut short = bytes.clone();
    short[record + 32..record + 34].copy_from_slice(&2u16.to_le_bytes());
    let e = parse_cloud(&short, CloudFormat::Laz, &CloudReadOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("the LASzip items describe 28-byte points"),
        "{e}"
    );
    // An item of a fixed-size type declaring another size.
    let mut odd = bytes.clone();
    let first_item_size = record + 34 + 2;
    odd[first_item_size..first_item_size + 2].copy_from_slice(&10u16.to_le_bytes());
    let e = parse_cloud(&odd, CloudFormat::Laz, &CloudReadOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("the LASzip item Point10 is of 20 bytes, the record says 10"),
        "{e}"
    );
    // A chunk table claiming 4 billion chunks (the decoder reserves them first).
    let mut chunks = bytes.clone();
    let table = laz_points_end(&bytes);
    chunks[table + 4..table + 8].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = parse_cloud(&chunks, CloudFormat::Laz, &CloudReadOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "LAZ data: not a valid LAZ file: the chunk table claims 4294967295 chunks, more than the file can hold"
    );
    // A chunk-table offset pointing past the end: read without the table.
    let mut lost = bytes.clone();
    let data = u32::from_le_bytes(bytes[96..100].try_into().unwrap()) as usize;
    lost[data..data + 8].copy_from_slice(&(1i64 << 40).to_le_bytes());
    let cloud = parse_cloud(&lost, CloudFormat::Laz, &CloudReadOptions::default()).unwrap();
    assert_eq!(cloud.points.len(), 200);
}

#[test]
fn extended_vlrs_longer_than_the_file_are_refused() {
    let mut bytes = las14_claiming(2);
    let at = bytes.len() as u64;
    let mut evlr = vec![0u8; 60];
    evlr[20..28].copy_from_slice(&(u64::MAX / 2).to_le_bytes());
    bytes.extend(evlr);
    bytes[235..243].copy_from_slice(&at.to_le_bytes());
    bytes[243..247].copy_from_slice(&1u32.to_le_bytes());
    let e = parse_cloud(&bytes, CloudFormat::Las, &CloudReadOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "LAS data: truncated: the first extended VLR needs {} bytes, the file has 60",
            u64::MAX / 2 + 60
        )
    );
}

#[test]
fn pcd_sizes_the_reader_trusts_are_checked() {
    let header = |count: &str, points: u32, data: &str| {
        format!(
            "VERSION 0.7\nFIELDS _ x y z\nSIZE 1 4 4 4\nTYPE U F F F\nCOUNT {count} 1 1 1\nWIDTH {points}\nHEIGHT 1\nPOINTS {points}\nDATA {data}\n"
        )
        .into_bytes()
    };
    // Padding of a terabyte a point (the reader allocates it per point).
    let mut huge = header("1000000000000", 1, "binary");
    huge.extend([0; 16]);
    let e = parse_cloud(&huge, CloudFormat::Pcd, &CloudReadOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("PCD data: unsupported PCD file: records of"),
        "{e}"
    );
    let mut overflow = header("18446744073709551615", 1, "ascii");
    overflow.extend(b"0 1 2 3\n");
    let e = parse_cloud(&overflow, CloudFormat::Pcd, &CloudReadOptions::default()).unwrap_err();
    assert_one_line(&e, "PCD data");
    // A compressed block that expands to less than the points (the reader
    // indexes past it) or claims more bytes than there are.
    let mut short = header("1", 10, "binary_compressed");
    short.extend(13u32.to_le_bytes());
    short.extend(16u32.to_le_bytes());
    short.push(15);
    short.extend([0; 16]);
    let e = parse_cloud(&short, CloudFormat::Pcd, &CloudReadOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "PCD data: not a valid PCD file: the compressed data expands to 16 bytes, not the 10 × 13 of the points"
    );
    let mut long = header("1", 10, "binary_compressed");
    long.extend(u32::MAX.to_le_bytes());
    long.extend(160u32.to_le_bytes());
    let e = parse_cloud(&long, CloudFormat::Pcd, &CloudReadOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "PCD data: truncated: the compressed point data needs 4294967295 bytes, the file has 0"
    );
}
