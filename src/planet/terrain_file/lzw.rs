//! A TIFF's LZW-compressed heights: the codes (TIFF 6.0, Section 13), the predictors (Section 14; Adobe Photoshop
//! TIFF Technical Note 3 for floating point) and the strips or tiles they fill, decoded here: GDAL writes compressed GeoTIFFs with LZW (`-co COMPRESS=LZW`, often
//! with `PREDICTOR=2` or `3`), and the tiff crate's LZW needs a crate this build does not have.

/// Codes are at most 12 bits wide.
const MAX_CODES: usize = 4096;
/// The code that empties the table, and the one that ends a strip.
const CLEAR: usize = 256;
const END: usize = 257;
/// The first code the table assigns.
const FIRST_FREE: usize = 258;

/// A strip's or tile's bytes, decoded: at most `expected` bytes.
fn decode(data: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    // libtiff's test for the bit order before TIFF 6.0 (least significant bit first, no code 256 first).
    if data.len() >= 2 && data[0] == 0 && data[1] & 1 == 1 {
        return Err(
            "its LZW data is in the bit order before TIFF 6.0; rewrite it (gdal_translate -co COMPRESS=LZW)".into(),
        );
    }
    let mut table = Table::new();
    let mut out = Vec::with_capacity(expected);
    let mut bits = Bits { data, at: 0 };
    let mut width = 9;
    let mut previous: Option<usize> = None;
    while out.len() < expected {
        let Some(code) = bits.read(width) else { break };
        match (code, previous) {
            (END, _) => break,
            (CLEAR, _) => {
                table.clear();
                width = 9;
                previous = None;
                continue;
            }
            (code, None) if code < CLEAR => table.write(code, &mut out),
            (code, Some(old)) if code < table.next => {
                table.add(old, table.first[code]);
                table.write(code, &mut out);
            }
            // The string just being defined: the previous one and its own first byte.
            (code, Some(old)) if code == table.next && code < MAX_CODES => {
                table.add(old, table.first[old]);
                table.write(code, &mut out);
            }
            (code, _) => {
                return Err(format!(
                    "its LZW data has code {code} where at most {} is defined (corrupt data)",
                    table.next
                ))
            }
        }
        previous = Some(code);
        // "Early change": the codes widen one code before the table needs it (TIFF 6.0, Section 13).
        if table.next + 1 >= 1 << width && width < 12 {
            width += 1;
        }
    }
    out.truncate(expected);
    Ok(out)
}

/// The string table: each code is a shorter code's string and one byte more.
struct Table {
    prefix: Vec<u16>,
    last: Vec<u8>,
    first: Vec<u8>,
    length: Vec<u16>,
    next: usize,
}

impl Table {
    fn new() -> Self {
        let mut table = Table {
            prefix: vec![0; MAX_CODES],
            last: vec![0; MAX_CODES],
            first: vec![0; MAX_CODES],
            length: vec![0; MAX_CODES],
            next: FIRST_FREE,
        };
        for byte in 0..CLEAR {
            table.last[byte] = byte as u8;
            table.first[byte] = byte as u8;
            table.length[byte] = 1;
        }
        table
    }

    fn clear(&mut self) {
        self.next = FIRST_FREE;
    }

    /// Defines the next code as `prefix`'s string and `byte`; a full table defines nothing (the writer clears it).
    fn add(&mut self, prefix: usize, byte: u8) {
        if self.next < MAX_CODES {
            let k = self.next;
            self.prefix[k] = prefix as u16;
            self.last[k] = byte;
            self.first[k] = self.first[prefix];
            self.length[k] = self.length[prefix] + 1;
            self.next += 1;
        }
    }

    /// Appends `code`'s string.
    fn write(&self, code: usize, out: &mut Vec<u8>) {
        let start = out.len();
        out.resize(start + self.length[code] as usize, 0);
        let mut k = code;
        for byte in out[start..].iter_mut().rev() {
            *byte = self.last[k];
            k = self.prefix[k] as usize;
        }
    }
}

/// Codes read most significant bit first.
struct Bits<'a> {
    data: &'a [u8],
    at: usize,
}

impl Bits<'_> {
    fn read(&mut self, width: u32) -> Option<usize> {
        if self.at + width as usize > self.data.len() * 8 {
            return None;
        }
        let mut code = 0;
        for _ in 0..width {
            let bit = (self.data[self.at / 8] >> (7 - self.at % 8)) & 1;
            code = code << 1 | bit as usize;
            self.at += 1;
        }
        Some(code)
    }
}

/// Undoes a predictor on one row of samples `bytes` wide each, stored in the file's byte order (`little`):
/// 2, horizontal differencing of the samples as integers; 3, the floating-point predictor (each row's bytes
/// regrouped most significant first, then differenced byte by byte).
fn undo_predictor(
    predictor: u16,
    row: &mut [u8],
    bytes: usize,
    little: bool,
) -> Result<(), String> {
    match predictor {
        1 => {}
        2 => {
            for k in 1..row.len() / bytes {
                let sum = word(&row[(k - 1) * bytes..k * bytes], little)
                    .wrapping_add(word(&row[k * bytes..(k + 1) * bytes], little));
                let sample = &mut row[k * bytes..(k + 1) * bytes];
                match little {
                    true => sample.copy_from_slice(&sum.to_le_bytes()[..bytes]),
                    false => sample.copy_from_slice(&sum.to_be_bytes()[8 - bytes..]),
                }
            }
        }
        3 => {
            for k in 1..row.len() {
                row[k] = row[k].wrapping_add(row[k - 1]);
            }
            let planes = row.to_vec();
            let samples = row.len() / bytes;
            for k in 0..samples {
                for significance in 0..bytes {
                    let at = if little {
                        bytes - 1 - significance
                    } else {
                        significance
                    };
                    row[k * bytes + at] = planes[significance * samples + k];
                }
            }
        }
        other => {
            return Err(format!(
                "its Predictor is {other}; 1 (none), 2 (horizontal) and 3 (floating point) are read"
            ))
        }
    }
    Ok(())
}

/// TIFF's Compression tag for LZW.
pub(super) const LZW: u16 = 5;
/// The most bytes an LZW TIFF may decode to: the tiff crate's default limit for the other compressions.
const DECODED_LIMIT: usize = 256 << 20;

/// An LZW-compressed TIFF's width, height and heights, strip by strip or tile by tile: one channel of the sample
/// types `read_tiff` takes, in chunky order.
pub(super) fn read_image<R: std::io::Read + std::io::Seek>(
    decoder: &mut tiff::decoder::Decoder<R>,
    (width, height): (u32, u32),
) -> Result<(u32, u32, Vec<f32>), String> {
    use tiff::tags::Tag;
    let mut unsigned = |tag: Tag| -> Result<Option<Vec<u64>>, String> {
        decoder
            .find_tag_unsigned_vec(tag)
            .map_err(|e| e.to_string())
    };
    let first =
        |v: Option<Vec<u64>>, default: u64| v.and_then(|v| v.first().copied()).unwrap_or(default);
    let channels = first(unsigned(Tag::SamplesPerPixel)?, 1);
    let bits = first(unsigned(Tag::BitsPerSample)?, 1);
    let format = first(unsigned(Tag::SampleFormat)?, 1);
    let predictor = first(unsigned(Tag::Predictor)?, 1) as u16;
    if channels != 1 {
        return Err(format!(
            "{channels} samples per pixel: a terrain has one channel"
        ));
    }
    let sample: fn(&[u8], bool) -> f32 = match (format, bits) {
        (3, 32) => |b, little| f32::from_bits(word(b, little) as u32),
        (3, 64) => |b, little| f64::from_bits(word(b, little)) as f32,
        (2, 16) => |b, little| word(b, little) as u16 as i16 as f32,
        (2, 32) => |b, little| word(b, little) as u32 as i32 as f32,
        _ => {
            return Err(format!(
                "its samples are {bits}-bit of SampleFormat {format}; a TIFF's samples must be 32- or 64-bit floats \
                 or 16- or 32-bit signed integers (heights as they are)"
            ))
        }
    };
    let bytes = bits as usize / 8;
    if width as usize * height as usize * bytes > DECODED_LIMIT {
        return Err(format!(
            "{width}x{height} samples of {bytes} bytes exceed the {} MiB a TIFF may decode to",
            DECODED_LIMIT >> 20
        ));
    }
    // Tiles, or strips: chunks as wide as the image, RowsPerStrip tall (the last one cut at the image's end).
    let tile_width = unsigned(Tag::TileWidth)?;
    let tiled = tile_width.is_some();
    let (chunk, offsets, counts) = match tile_width {
        Some(tile_width) => (
            (
                first(Some(tile_width), 0),
                first(unsigned(Tag::TileLength)?, 0),
            ),
            unsigned(Tag::TileOffsets)?,
            unsigned(Tag::TileByteCounts)?,
        ),
        None => (
            (
                width as u64,
                first(unsigned(Tag::RowsPerStrip)?, height as u64).min(height as u64),
            ),
            unsigned(Tag::StripOffsets)?,
            unsigned(Tag::StripByteCounts)?,
        ),
    };
    let (Some(offsets), Some(counts)) = (offsets, counts) else {
        return Err("its strips' or tiles' offsets or byte counts are missing".into());
    };
    let (chunk_width, chunk_height) = (chunk.0 as usize, chunk.1 as usize);
    if chunk_width == 0 || chunk_height == 0 {
        return Err(
            "its tiles or strips are empty (TileWidth, TileLength or RowsPerStrip 0)".into(),
        );
    }
    let (width, height) = (width as usize, height as usize);
    // TIFF 6.0 pads tiles to multiples of 16; more than that is no tiling of this image.
    if chunk_width > width.next_multiple_of(16) || chunk_height > height.next_multiple_of(16) {
        return Err(format!(
            "its {chunk_width}x{chunk_height} tiles are larger than its {width}x{height} image"
        ));
    }
    let file_length = decoder
        .inner()
        .seek(std::io::SeekFrom::End(0))
        .map_err(|e| e.to_string())?;
    let across = width.div_ceil(chunk_width);
    let chunks = across * height.div_ceil(chunk_height);
    if offsets.len() < chunks || counts.len() < chunks {
        return Err(format!(
            "it has {} strip or tile offsets and {} byte counts for {chunks} strips or tiles",
            offsets.len(),
            counts.len()
        ));
    }
    let little = decoder.byte_order() == tiff::tags::ByteOrder::LittleEndian;
    let mut heights = vec![0.0f32; width * height];
    for k in 0..chunks {
        let (x0, y0) = ((k % across) * chunk_width, (k / across) * chunk_height);
        // A strip holds only the image's rows; a tile is whole at the image's edges too.
        let rows = match tiled {
            true => chunk_height,
            false => chunk_height.min(height - y0),
        };
        if offsets[k].saturating_add(counts[k]) > file_length {
            return Err(format!(
                "its strip or tile {k} ({} bytes at {}) reaches past the file's end ({file_length} bytes)",
                counts[k], offsets[k]
            ));
        }
        let mut data = vec![0u8; counts[k] as usize];
        let reader = decoder.inner();
        reader
            .seek(std::io::SeekFrom::Start(offsets[k]))
            .and_then(|_| reader.read_exact(&mut data))
            .map_err(|e| format!("strip or tile {k}: {e}"))?;
        let row_bytes = chunk_width * bytes;
        let mut decoded =
            decode(&data, rows * row_bytes).map_err(|e| format!("strip or tile {k}: {e}"))?;
        if decoded.len() < rows * row_bytes {
            return Err(format!(
                "its LZW strip or tile {k} ends after {} of {} bytes",
                decoded.len(),
                rows * row_bytes
            ));
        }
        for (r, row) in decoded.chunks_exact_mut(row_bytes).enumerate() {
            undo_predictor(predictor, row, bytes, little)?;
            let y = y0 + r;
            if y >= height {
                break;
            }
            for (x, value) in (x0..width.min(x0 + chunk_width)).zip(row.chunks_exact(bytes)) {
                heights[y * width + x] = sample(value, little);
            }
        }
    }
    Ok((width as u32, height as u32, heights))
}

/// Up to eight bytes as an unsigned number in the file's byte order.
fn word(bytes: &[u8], little: bool) -> u64 {
    let fold = |w: u64, b: &u8| w << 8 | *b as u64;
    match little {
        true => bytes.iter().rev().fold(0, fold),
        false => bytes.iter().fold(0, fold),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// TIFF 6.0's LZW written the plain way (no search structure): the decoder's counterpart, for the tests.
    fn encode(data: &[u8]) -> Vec<u8> {
        let mut out = BitWriter::default();
        let mut codes: std::collections::HashMap<Vec<u8>, usize> = Default::default();
        let mut width = 9;
        let mut next = FIRST_FREE;
        out.write(CLEAR, width);
        let mut current: Vec<u8> = Vec::new();
        let code_of = |s: &[u8], codes: &std::collections::HashMap<Vec<u8>, usize>| match s.len() {
            1 => s[0] as usize,
            _ => codes[s],
        };
        for &byte in data {
            let mut longer = current.clone();
            longer.push(byte);
            if longer.len() == 1 || codes.contains_key(&longer) {
                current = longer;
                continue;
            }
            out.write(code_of(&current, &codes), width);
            codes.insert(longer, next);
            next += 1;
            // The writer widens one code after the reader would (it defines each code a step earlier).
            if next >= 1 << width && width < 12 {
                width += 1;
            }
            if next >= MAX_CODES - 2 {
                out.write(CLEAR, width);
                codes.clear();
                next = FIRST_FREE;
                width = 9;
            }
            current = vec![byte];
        }
        if !current.is_empty() {
            out.write(code_of(&current, &codes), width);
            // As libtiff: the last code counts as defining one, so the end code has the width the reader expects.
            if next + 1 >= 1 << width && width < 12 {
                width += 1;
            }
        }
        out.write(END, width);
        out.bytes()
    }

    #[derive(Default)]
    struct BitWriter {
        bits: Vec<bool>,
    }

    impl BitWriter {
        fn write(&mut self, code: usize, width: u32) {
            self.bits
                .extend((0..width).rev().map(|b| (code >> b) & 1 == 1));
        }

        fn bytes(&self) -> Vec<u8> {
            self.bits
                .chunks(8)
                .map(|c| {
                    (0..8).fold(0u8, |b, k| {
                        b << 1 | c.get(k).copied().unwrap_or(false) as u8
                    })
                })
                .collect()
        }
    }

    #[test]
    fn lzw_round_trips_through_table_resets_and_growing_codes() {
        // Repetitive and random bytes: codes of every width, the KwKwK case and at least one full table.
        let mut state = 12345u32;
        let data: Vec<u8> = (0..200_000)
            .map(|k| {
                state = state.wrapping_mul(1_103_515_245).wrapping_add(12345);
                if k % 3000 < 1500 {
                    (k % 7) as u8
                } else {
                    (state >> 24) as u8
                }
            })
            .collect();
        let encoded = encode(&data);
        assert!(encoded.len() < data.len());
        assert_eq!(decode(&encoded, data.len()).unwrap(), data);
        // A run of one byte: every new code is the one being defined.
        let run = vec![7u8; 5000];
        assert_eq!(decode(&encode(&run), run.len()).unwrap(), run);
        // At most what a strip holds is returned.
        assert_eq!(decode(&encode(&run), 100).unwrap().len(), 100);
    }

    #[test]
    fn corrupt_and_old_style_lzw_are_refused() {
        // Code 300 right after the table was cleared.
        let mut bits = BitWriter::default();
        bits.write(CLEAR, 9);
        bits.write(65, 9);
        bits.write(300, 9);
        let err = decode(&bits.bytes(), 10).unwrap_err();
        assert!(err.contains("code 300"), "{err}");
        let err = decode(&[0, 1, 2, 3], 10).unwrap_err();
        assert!(err.contains("before TIFF 6.0"), "{err}");
    }

    #[test]
    fn predictors_restore_the_samples() {
        // Horizontal differencing of 16-bit samples 100, 90, 300 (wrapping), both byte orders.
        let deltas: [i16; 3] = [100, -10, 210];
        for little in [true, false] {
            let mut row: Vec<u8> = deltas
                .iter()
                .flat_map(|d| match little {
                    true => d.to_le_bytes(),
                    false => d.to_be_bytes(),
                })
                .collect();
            undo_predictor(2, &mut row, 2, little).unwrap();
            let samples: Vec<i16> = row
                .chunks(2)
                .map(|b| match little {
                    true => i16::from_le_bytes([b[0], b[1]]),
                    false => i16::from_be_bytes([b[0], b[1]]),
                })
                .collect();
            assert_eq!(samples, [100, 90, 300]);
        }
        // The floating-point predictor: planes of bytes, most significant first, differenced.
        let values = [1.5f32, -2.25, 1000.0];
        let planes: Vec<u8> = (0..4)
            .flat_map(|s| values.iter().map(move |v| v.to_be_bytes()[s]))
            .collect();
        let mut row: Vec<u8> = planes
            .iter()
            .enumerate()
            .map(|(k, &b)| b.wrapping_sub(if k == 0 { 0 } else { planes[k - 1] }))
            .collect();
        undo_predictor(3, &mut row, 4, true).unwrap();
        let restored: Vec<f32> = row
            .chunks(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        assert_eq!(restored, values);
        assert!(undo_predictor(4, &mut row, 4, true)
            .unwrap_err()
            .contains("Predictor is 4"));
    }

    fn data(name: &str) -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name)
    }

    /// Written by libtiff (Pillow 13, `compression="tiff_lzw"` with the Predictor tag): 96 x 48 samples in strips of
    /// 7 and 10 rows (the last one shorter), little-endian.
    #[test]
    fn lzw_tiffs_written_by_libtiff_read_as_their_heights() {
        let formula =
            |x: usize, y: usize| ((x * 37 + y * 101) % 1000) as f32 - 200.0 + 0.25 * x as f32;
        let ((width, height, heights), placement) =
            super::super::read::read_tiff(&data("lzw-float32-predictor3.tif")).unwrap();
        assert_eq!((width, height), (96, 48));
        for (k, h) in heights.iter().enumerate() {
            assert_eq!(*h, formula(k % 96, k / 96), "float predictor, sample {k}");
        }
        let placement = placement.expect("its GeoTIFF tags place it");
        assert_eq!(
            (placement.west, placement.north, placement.degrees_per_pixel),
            (10.0, 50.0, (0.5, 0.5))
        );
        let ((width, height, heights), placement) =
            super::super::read::read_tiff(&data("lzw-int32-predictor2.tif")).unwrap();
        assert_eq!((width, height), (96, 48));
        assert!(placement.is_none());
        for (k, h) in heights.iter().enumerate() {
            let (x, y) = (k % 96, k / 96);
            assert_eq!(
                *h,
                ((x * 37 + y * 101) % 3000) as f32 - 1000.0,
                "horizontal predictor, sample {k}"
            );
        }
    }

    /// A hostile probe: libtiff's LZW files with bytes changed at random (in the directory, the offsets, the codes)
    /// are read or refused, never a panic or an allocation of what they claim.
    #[test]
    fn damaged_lzw_tiffs_are_refused_or_read_never_a_panic() {
        let mut rng = crate::rng::Rng::new(35, &[39]);
        let path = std::env::temp_dir().join(format!(
            "riverplanet-damaged-lzw-{}.tif",
            std::process::id()
        ));
        let (mut refused, mut read) = (0, 0);
        for name in ["lzw-float32-predictor3.tif", "lzw-int32-predictor2.tif"] {
            let original = std::fs::read(data(name)).unwrap();
            for _ in 0..300 {
                let mut file = original.clone();
                for _ in 0..1 + rng.below(4) {
                    let at = rng.below(file.len() as u64) as usize;
                    file[at] = rng.next_u64() as u8;
                }
                std::fs::write(&path, &file).unwrap();
                match super::super::read::read_tiff(&path) {
                    Ok(_) => read += 1,
                    Err(_) => refused += 1,
                }
            }
        }
        std::fs::remove_file(&path).unwrap();
        println!("{refused} damaged files refused, {read} read");
        // Most changes land in the compressed codes, which decode to other heights or are refused.
        assert!(refused > 0 && read > 0, "{refused} refused, {read} read");
    }

    /// A big-endian tiled TIFF (16 x 16 tiles over 40 x 20 pixels, the edge tiles padded), floating-point
    /// predictor: the tiles' layout and the byte order, which libtiff's strips above do not cover; and the same
    /// file made hostile.
    #[test]
    fn a_big_endian_tiled_lzw_tiff_reads() {
        let (width, height, tile) = (40usize, 20usize, 16usize);
        let value = |x: usize, y: usize| x as f32 * 1.5 - y as f32 * 2.25 + 0.125;
        let (across, down) = (width.div_ceil(tile), height.div_ceil(tile));
        let mut tiles = Vec::new();
        for t in 0..across * down {
            let (x0, y0) = ((t % across) * tile, (t / across) * tile);
            let mut bytes = Vec::new();
            for y in y0..y0 + tile {
                let row: Vec<f32> = (x0..x0 + tile)
                    .map(|x| {
                        if x < width && y < height {
                            value(x, y)
                        } else {
                            0.0
                        }
                    })
                    .collect();
                // The floating-point predictor: byte planes, most significant first, then differences.
                let planes: Vec<u8> = (0..4)
                    .flat_map(|b| row.iter().map(move |v| v.to_be_bytes()[b]))
                    .collect();
                bytes.extend(
                    (0..planes.len())
                        .map(|k| planes[k].wrapping_sub(if k == 0 { 0 } else { planes[k - 1] })),
                );
            }
            tiles.push(super::super::lzw::tests::encode(&bytes));
        }
        // Header, tiles, the offsets and byte counts, then the directory.
        let mut file = b"MM\0\x2a\0\0\0\0".to_vec();
        let mut offsets = Vec::new();
        for t in &tiles {
            offsets.push(file.len() as u32);
            file.extend(t);
        }
        let long_array = |file: &mut Vec<u8>, values: &[u32]| {
            let at = file.len() as u32;
            file.extend(values.iter().flat_map(|v| v.to_be_bytes()));
            at
        };
        let counts: Vec<u32> = tiles.iter().map(|t| t.len() as u32).collect();
        let offsets_at = long_array(&mut file, &offsets);
        let counts_at = long_array(&mut file, &counts);
        let directory = file.len() as u32;
        file[4..8].copy_from_slice(&directory.to_be_bytes());
        let (short, long) = (3u16, 4u16);
        let entries: [(u16, u16, u32, u32); 12] = [
            (256, long, 1, width as u32),
            (257, long, 1, height as u32),
            (258, short, 1, 32),
            (259, short, 1, 5),
            (262, short, 1, 1),
            (277, short, 1, 1),
            (317, short, 1, 3),
            (322, long, 1, tile as u32),
            (323, long, 1, tile as u32),
            (324, long, tiles.len() as u32, offsets_at),
            (325, long, tiles.len() as u32, counts_at),
            (339, short, 1, 3),
        ];
        file.extend((entries.len() as u16).to_be_bytes());
        for (tag, kind, count, value) in entries {
            file.extend(tag.to_be_bytes());
            file.extend(kind.to_be_bytes());
            file.extend(count.to_be_bytes());
            // A short value fills the field's first two bytes.
            match (kind, count) {
                (3, 1) => file.extend([(value as u16).to_be_bytes(), [0, 0]].concat()),
                _ => file.extend(value.to_be_bytes()),
            }
        }
        file.extend(0u32.to_be_bytes());
        let read = |file: &[u8]| {
            let path = std::env::temp_dir()
                .join(format!("riverplanet-tiled-lzw-{}.tif", std::process::id()));
            std::fs::write(&path, file).unwrap();
            let read = super::super::read::read_tiff(&path);
            std::fs::remove_file(&path).unwrap();
            read
        };
        // A hostile file is refused before it allocates what it claims: a tile's byte count past the file's end,
        // tiles larger than the image.
        let mut bad = file.clone();
        bad[counts_at as usize..counts_at as usize + 4]
            .copy_from_slice(&0xffff_fff0u32.to_be_bytes());
        let err = read(&bad).unwrap_err();
        assert!(err.contains("past the file's end"), "{err}");
        let mut bad = file.clone();
        let field = |entry: usize, at: usize| directory as usize + 2 + entry * 12 + at;
        bad[field(7, 8)..field(7, 12)].copy_from_slice(&(1u32 << 30).to_be_bytes());
        // One tile across then: two offsets and byte counts, as the tile count the decoder checks.
        for entry in [9, 10] {
            bad[field(entry, 4)..field(entry, 8)].copy_from_slice(&2u32.to_be_bytes());
        }
        let err = read(&bad).unwrap_err();
        assert!(err.contains("larger than its 40x20 image"), "{err}");
        let ((w, h, heights), placement) = read(&file).unwrap();
        assert_eq!((w, h), (width as u32, height as u32));
        assert!(placement.is_none());
        for (k, v) in heights.iter().enumerate() {
            assert_eq!(*v, value(k % width, k / width), "sample {k}");
        }
    }
}
