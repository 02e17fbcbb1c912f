//! Reading a terrain file's heights (beyond the thesis; docs/planet.md, "Heights from a file"): 32- or 64-bit float
//! or signed-integer TIFF with its GeoTIFF georeference, OpenEXR channel Y, 16-bit grey PNG with the height scale
//! and offset (and the bounds) from the JSON `export` writes beside it.

use std::path::Path;

use super::Placement;

/// Width, height and one height per pixel, row 0 in the north.
pub(super) type Heights = (u32, u32, Vec<f32>);

/// A TIFF's heights, and where its GeoTIFF tags place it, if they do.
pub(super) fn read_tiff(path: &Path) -> Result<(Heights, Option<Placement>), String> {
    use tiff::decoder::{Decoder, DecodingResult};
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut decoder = Decoder::new(std::io::BufReader::new(file)).map_err(|e| e.to_string())?;
    let (width, height) = decoder.dimensions().map_err(|e| e.to_string())?;
    let placement = georeference(&mut decoder)?;
    let compression: Option<u16> = decoder
        .find_tag_unsigned(tiff::tags::Tag::Compression)
        .map_err(|e| e.to_string())?;
    if compression == Some(LZW) {
        return Ok((read_lzw(&mut decoder, (width, height))?, placement));
    }
    let heights = match decoder.read_image().map_err(|e| e.to_string())? {
        DecodingResult::F32(v) => v,
        DecodingResult::F64(v) => v.into_iter().map(|h| h as f32).collect(),
        DecodingResult::I16(v) => v.into_iter().map(f32::from).collect(),
        DecodingResult::I32(v) => v.into_iter().map(|h| h as f32).collect(),
        _ => {
            return Err(
                "a TIFF's samples must be one channel of 32- or 64-bit floats or 16- or 32-bit signed integers \
                 (heights as they are)"
                    .into(),
            )
        }
    };
    Ok((one_channel(width, height, heights)?, placement))
}

/// TIFF's Compression tag for LZW.
const LZW: u16 = 5;
/// The most bytes an LZW TIFF may decode to: the tiff crate's default limit for the other compressions.
const DECODED_LIMIT: usize = 256 << 20;

/// An LZW-compressed TIFF's heights, strip by strip or tile by tile (`lzw`): one channel of the sample types
/// `read_tiff` takes, in chunky order.
fn read_lzw<R: std::io::Read + std::io::Seek>(
    decoder: &mut tiff::decoder::Decoder<R>,
    (width, height): (u32, u32),
) -> Result<Heights, String> {
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
        let mut decoded = super::lzw::decode(&data, rows * row_bytes)
            .map_err(|e| format!("strip or tile {k}: {e}"))?;
        if decoded.len() < rows * row_bytes {
            return Err(format!(
                "its LZW strip or tile {k} ends after {} of {} bytes",
                decoded.len(),
                rows * row_bytes
            ));
        }
        for (r, row) in decoded.chunks_exact_mut(row_bytes).enumerate() {
            super::lzw::undo_predictor(predictor, row, bytes, little)?;
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

/// GeoTIFF 1.1 (OGC 19-008): ModelPixelScale and one ModelTiepoint in a geographic model in degrees (GTModelType 2,
/// angular units 9102 where given); a raster of points (GTRasterType 2) covers half a pixel more on each side.
fn georeference<R: std::io::Read + std::io::Seek>(
    decoder: &mut tiff::decoder::Decoder<R>,
) -> Result<Option<Placement>, String> {
    use tiff::tags::Tag;
    let mut doubles = |tag: Tag| -> Result<Option<Vec<f64>>, String> {
        match decoder.find_tag(tag).map_err(|e| e.to_string())? {
            Some(value) => value.into_f64_vec().map(Some).map_err(|e| e.to_string()),
            None => Ok(None),
        }
    };
    let (Some(scale), Some(tie)) = (
        doubles(Tag::ModelPixelScaleTag)?,
        doubles(Tag::ModelTiepointTag)?,
    ) else {
        return Ok(None);
    };
    if scale.len() < 2 || tie.len() < 6 || scale[0] <= 0.0 || scale[1] <= 0.0 {
        return Err(format!(
            "its GeoTIFF tags need ModelPixelScale (two positive numbers) and a ModelTiepoint (six numbers); it has \
             {scale:?} and {tie:?}"
        ));
    }
    let keys: Vec<u16> = match decoder
        .find_tag(Tag::GeoKeyDirectoryTag)
        .map_err(|e| e.to_string())?
    {
        Some(value) => value.into_u16_vec().map_err(|e| e.to_string())?,
        None => Vec::new(),
    };
    let key = |id: u16| {
        keys.get(4..)
            .unwrap_or_default()
            .chunks_exact(4)
            .find(|k| k[0] == id && k[1] == 0)
            .map(|k| k[3])
    };
    if let Some(model) = key(1024).filter(|&m| m != 2) {
        return Err(format!(
            "its GeoTIFF model type is {model} (1: projected, 3: geocentric); a terrain file must be in longitude \
             and latitude (model type 2, e.g. EPSG:4326; reproject with gdalwarp -t_srs EPSG:4326)"
        ));
    }
    if let Some(units) = key(2054).filter(|&u| u != 9102) {
        return Err(format!(
            "its GeoTIFF angular units are {units}; a terrain file's must be degrees (9102)"
        ));
    }
    let (dx, dy) = (scale[0], scale[1]);
    let half = if key(1025) == Some(2) { 0.5 } else { 0.0 };
    Ok(Some(Placement {
        west: tie[3] - (tie[0] + half) * dx,
        north: tie[4] + (tie[1] + half) * dy,
        degrees_per_pixel: (dx, dy),
    }))
}

pub(super) fn read_exr(path: &Path) -> Result<Heights, String> {
    use exr::prelude::*;
    let image = read_first_flat_layer_from_file(path).map_err(|e| e.to_string())?;
    let size = image.layer_data.size;
    let channel = image
        .layer_data
        .channel_data
        .list
        .iter()
        .find(|c| c.name.eq("Y"))
        .ok_or("an OpenEXR terrain needs its heights in channel Y")?;
    let heights = channel.sample_data.values_as_f32().collect();
    one_channel(size.0 as u32, size.1 as u32, heights)
}

pub(super) fn read_png(path: &Path, (scale, offset): (f32, f32)) -> Result<Heights, String> {
    let image = image::ImageReader::open(path)
        .map_err(|e| e.to_string())?
        .decode()
        .map_err(|e| e.to_string())?;
    if image.color() != image::ColorType::L16 {
        return Err(format!(
            "a PNG terrain must be 16-bit grey (this one is {:?})",
            image.color()
        ));
    }
    let (scale, offset) = match scale_offset_beside(path)? {
        Some(beside) => beside,
        None => (scale, offset),
    };
    let image = image.into_luma16();
    let (width, height) = image.dimensions();
    let heights = image
        .pixels()
        .map(|p| offset + scale * p.0[0] as f32)
        .collect();
    Ok((width, height, heights))
}

/// `bounds` (`[west, south, east, north]` in degrees) from the JSON `export` writes beside a raster, if it has
/// them.
pub(super) fn bounds_beside(path: &Path) -> Result<Option<[f64; 4]>, String> {
    let Some((value, beside)) = json_beside(path)? else {
        return Ok(None);
    };
    let Some(bounds) = value.get("bounds") else {
        return Ok(None);
    };
    let numbers: Option<Vec<f64>> = bounds
        .as_array()
        .map(|a| a.iter().filter_map(|v| v.as_f64()).collect());
    match numbers.as_deref() {
        Some(&[west, south, east, north]) => Ok(Some([west, south, east, north])),
        _ => Err(format!(
            "{} beside it has bounds {bounds} where four numbers [west, south, east, north] belong",
            beside.display()
        )),
    }
}

/// The JSON `export` writes beside a raster (`PATH.json`), and its path, if there is one.
fn json_beside(path: &Path) -> Result<Option<(serde_json::Value, std::path::PathBuf)>, String> {
    let beside = path.with_extension("json");
    let Ok(text) = std::fs::read_to_string(&beside) else {
        return Ok(None);
    };
    let value = serde_json::from_str(&text)
        .map_err(|e| format!("{} beside it is not JSON: {e}", beside.display()))?;
    Ok(Some((value, beside)))
}

/// `height_scale` and `height_offset` from the JSON `export` writes beside a raster, if there is one.
fn scale_offset_beside(path: &Path) -> Result<Option<(f32, f32)>, String> {
    let Some((value, beside)) = json_beside(path)? else {
        return Ok(None);
    };
    let number = |key: &str| {
        value[key].as_f64().map(|v| v as f32).ok_or_else(|| {
            format!(
                "{} beside it has no number {key} (height = height_offset + height_scale x value)",
                beside.display()
            )
        })
    };
    Ok(Some((number("height_scale")?, number("height_offset")?)))
}

fn one_channel(width: u32, height: u32, heights: Vec<f32>) -> Result<Heights, String> {
    if heights.len() != width as usize * height as usize {
        return Err(format!(
            "{} samples for {width}x{height} pixels: a terrain has one channel",
            heights.len()
        ));
    }
    Ok((width, height, heights))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
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
            read_tiff(&data("lzw-float32-predictor3.tif")).unwrap();
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
            read_tiff(&data("lzw-int32-predictor2.tif")).unwrap();
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
                match read_tiff(&path) {
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
            let read = read_tiff(&path);
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
