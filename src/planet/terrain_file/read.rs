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
    if compression == Some(super::lzw::LZW) {
        return Ok((
            super::lzw::read_image(&mut decoder, (width, height))?,
            placement,
        ));
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
