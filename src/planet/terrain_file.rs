//! `<terrain-file>` (beyond the thesis; docs/planet.md, "Heights from a file"): a whole planet's heights from an
//! equirectangular raster, the coarse levels of a planet whose drainage network is then routed on them. Reads
//! what `riverplanet export equirect` writes (32-bit float TIFF, OpenEXR channel Y, 16-bit PNG with the height
//! scale and offset in the JSON beside it) and other tools' rasters in those formats.

use std::path::Path;

use glam::DVec3;

/// Why a terrain file cannot be used; each names the file and what a usable one needs.
#[derive(Debug, thiserror::Error)]
pub enum TerrainFileError {
    #[error("cannot read terrain-file {path}: {message}")]
    Unreadable { path: String, message: String },
    #[error(
        "terrain-file {path} is {width}x{height}; a whole planet's equirectangular raster must be twice as wide as \
         high (e.g. 2048x1024) and at least 8x4"
    )]
    WrongSize {
        path: String,
        width: u32,
        height: u32,
    },
    #[error("terrain-file {path} has no height at pixel ({x}, {y}) (the value is {value}): every pixel needs one")]
    NotFinite {
        path: String,
        x: u32,
        y: u32,
        value: f32,
    },
    #[error(
        "terrain-file {path} is all {what} at sea-level-height {sea_level} (heights {lowest} to {highest}); a \
         planet needs land and sea"
    )]
    Uniform {
        path: String,
        what: &'static str,
        sea_level: f32,
        lowest: f32,
        highest: f32,
    },
}

/// A whole planet's heights, row 0 in the north, column 0 at longitude -180 (pixel centres half a pixel in).
pub struct TerrainFile {
    width: u32,
    height: u32,
    heights: Vec<f32>,
}

impl TerrainFile {
    /// Reads `path` and checks it holds heights for every pixel, with land and sea at `sea_level`. A PNG's 16-bit
    /// values become `height_offset + height_scale x value`, from the JSON beside it (`PATH.json`, as `export`
    /// writes) where there is one, else from `scale_offset`.
    pub fn load(
        path: &Path,
        scale_offset: (f32, f32),
        sea_level: f32,
    ) -> Result<Self, TerrainFileError> {
        let name = path.display().to_string();
        let unreadable = |message: String| TerrainFileError::Unreadable {
            path: name.clone(),
            message,
        };
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let (width, height, heights) = match extension.as_deref() {
            Some("tif" | "tiff") => read_tiff(path).map_err(unreadable)?,
            Some("exr") => read_exr(path).map_err(unreadable)?,
            Some("png") => read_png(path, scale_offset).map_err(unreadable)?,
            _ => {
                return Err(unreadable(
                    "the name must end in .tif, .tiff, .exr or .png (32-bit float TIFF, OpenEXR channel Y, or \
                     16-bit grey PNG)"
                        .into(),
                ))
            }
        };
        if width != 2 * height || height < 4 {
            return Err(TerrainFileError::WrongSize {
                path: name,
                width,
                height,
            });
        }
        if let Some(k) = heights.iter().position(|h| !h.is_finite()) {
            return Err(TerrainFileError::NotFinite {
                path: name,
                x: k as u32 % width,
                y: k as u32 / width,
                value: heights[k],
            });
        }
        let lowest = heights.iter().copied().fold(f32::INFINITY, f32::min);
        let highest = heights.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        if lowest > sea_level || highest <= sea_level {
            return Err(TerrainFileError::Uniform {
                path: name,
                what: if lowest > sea_level { "land" } else { "sea" },
                sea_level,
                lowest,
                highest,
            });
        }
        Ok(Self {
            width,
            height,
            heights,
        })
    }

    /// The height towards direction `p`: bilinear between the four nearest pixel centres, across the
    /// antimeridian; poleward of the first and last rows' centres, the row's value.
    pub fn height_towards(&self, p: DVec3) -> f64 {
        let (lon, lat) = super::lon_lat(p);
        let x = (lon + 180.0) / 360.0 * self.width as f64 - 0.5;
        let y =
            ((90.0 - lat) / 180.0 * self.height as f64 - 0.5).clamp(0.0, self.height as f64 - 1.0);
        let (x0, y0) = (x.floor(), y.floor().min(self.height as f64 - 2.0));
        let (fx, fy) = (x - x0, y - y0);
        let at = |i: f64, j: f64| {
            let i = (i as i64).rem_euclid(self.width as i64) as usize;
            self.heights[j as usize * self.width as usize + i] as f64
        };
        let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1.0, y0) * fx;
        let bottom = at(x0, y0 + 1.0) * (1.0 - fx) + at(x0 + 1.0, y0 + 1.0) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

type Heights = (u32, u32, Vec<f32>);

fn read_tiff(path: &Path) -> Result<Heights, String> {
    use tiff::decoder::{Decoder, DecodingResult};
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut decoder = Decoder::new(std::io::BufReader::new(file)).map_err(|e| e.to_string())?;
    let (width, height) = decoder.dimensions().map_err(|e| e.to_string())?;
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
    one_channel(width, height, heights)
}

fn read_exr(path: &Path) -> Result<Heights, String> {
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

fn read_png(path: &Path, (scale, offset): (f32, f32)) -> Result<Heights, String> {
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

/// `height_scale` and `height_offset` from the JSON `export` writes beside a raster, if there is one.
fn scale_offset_beside(path: &Path) -> Result<Option<(f32, f32)>, String> {
    let beside = path.with_extension("json");
    let Ok(text) = std::fs::read_to_string(&beside) else {
        return Ok(None);
    };
    let value: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| format!("{} beside it is not JSON: {e}", beside.display()))?;
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

    #[test]
    fn heights_are_bilinear_between_pixel_centres_and_wrap_at_the_antimeridian() {
        // 8x4: the value of each pixel is its column, except the last column, 100.
        let heights: Vec<f32> = (0..32)
            .map(|k| if k % 8 == 7 { 100.0 } else { (k % 8) as f32 })
            .collect();
        let file = TerrainFile {
            width: 8,
            height: 4,
            heights,
        };
        // Column 2's centre: longitude -180 + 2.5 x 45.
        let at = |lon: f64, lat: f64| file.height_towards(super::super::direction_at(lon, lat));
        assert!((at(-180.0 + 2.5 * 45.0, 22.5) - 2.0).abs() < 1e-9);
        assert!((at(-180.0 + 3.0 * 45.0, 10.0) - 2.5).abs() < 1e-9);
        // Across the antimeridian: half way between column 7 (100) and column 0 (0).
        assert!((at(180.0, 0.0) - 50.0).abs() < 1e-9);
        assert!((at(-179.999_999, 80.0) - 50.0).abs() < 1e-3);
    }
}
