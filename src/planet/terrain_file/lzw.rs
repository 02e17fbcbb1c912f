//! TIFF's LZW compression (TIFF 6.0, Section 13) and its predictors (Section 14; Adobe Photoshop TIFF Technical
//! Note 3 for floating point), decoded here: GDAL writes compressed GeoTIFFs with LZW (`-co COMPRESS=LZW`, often
//! with `PREDICTOR=2` or `3`), and the tiff crate's LZW needs a crate this build does not have.

/// Codes are at most 12 bits wide.
const MAX_CODES: usize = 4096;
/// The code that empties the table, and the one that ends a strip.
const CLEAR: usize = 256;
const END: usize = 257;
/// The first code the table assigns.
const FIRST_FREE: usize = 258;

/// A strip's or tile's bytes, decoded: at most `expected` bytes.
pub(super) fn decode(data: &[u8], expected: usize) -> Result<Vec<u8>, String> {
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
pub(super) fn undo_predictor(
    predictor: u16,
    row: &mut [u8],
    bytes: usize,
    little: bool,
) -> Result<(), String> {
    match predictor {
        1 => {}
        2 => {
            let read = |s: &[u8]| {
                let mut word = [0u8; 8];
                match little {
                    true => word[..bytes].copy_from_slice(s),
                    false => word[8 - bytes..].copy_from_slice(s),
                }
                match little {
                    true => u64::from_le_bytes(word),
                    false => u64::from_be_bytes(word),
                }
            };
            for k in 1..row.len() / bytes {
                let sum = read(&row[(k - 1) * bytes..k * bytes])
                    .wrapping_add(read(&row[k * bytes..(k + 1) * bytes]));
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

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// TIFF 6.0's LZW written the plain way (no search structure): the decoder's counterpart, for the tests.
    pub(in crate::planet::terrain_file) fn encode(data: &[u8]) -> Vec<u8> {
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
}
