//! `<terrain-file>` (beyond the thesis; docs/planet.md, "Heights from a file"): a planet's heights from an
//! equirectangular raster, the coarse levels of a planet whose drainage network is then routed on them: the whole
//! planet, or a georeferenced region placed on the procedural planet. Reads what `riverplanet export equirect`
//! and `export region` write (32-bit float GeoTIFF, OpenEXR channel Y, 16-bit PNG with the height scale and
//! offset in the JSON beside it) and other tools' rasters in those formats.

use std::path::Path;

use glam::DVec3;
use rayon::prelude::*;

use super::{cube::FACES, heights::FaceLattice};

/// Why a terrain file cannot be used; each names the file and what a usable one needs.
#[derive(Debug, thiserror::Error)]
pub enum TerrainFileError {
    /// The file is missing, of another format, or its decoder failed.
    #[error("cannot read terrain-file {path}: {message}")]
    Unreadable {
        /// The file.
        path: String,
        /// What went wrong, and what a usable file is.
        message: String,
    },
    #[error(
        "terrain-file {path} is {width}x{height}; a whole planet's equirectangular raster must be twice as wide as \
         high (e.g. 2048x1024) and at least 8x4"
    )]
    /// Too small, or a whole planet not twice as wide as high.
    WrongSize {
        /// The file.
        path: String,
        /// Its pixels across.
        width: u32,
        /// Its pixels down.
        height: u32,
    },
    #[error("terrain-file {path} has no height at pixel ({x}, {y}) (the value is {value}): every pixel needs one")]
    /// A pixel holds NaN or an infinity.
    NotFinite {
        /// The file.
        path: String,
        /// The pixel's column.
        x: u32,
        /// The pixel's row.
        y: u32,
        /// What it holds.
        value: f32,
    },
    #[error(
        "terrain-file {path} is all {what} at sea-level-height {sea_level} (heights {lowest} to {highest}); a \
         whole planet needs land and sea"
    )]
    /// A whole planet all land or all sea.
    Uniform {
        /// The file.
        path: String,
        /// "land" or "sea".
        what: &'static str,
        /// The configuration's sea level.
        sea_level: f32,
        /// The file's lowest height.
        lowest: f32,
        /// The file's highest height.
        highest: f32,
    },
    #[error(
        "terrain-file {path} has no georeference and is {width}x{height}: a region needs GeoTIFF tags \
         (ModelTiepoint and ModelPixelScale in degrees, as `export region` writes) or <terrain-bounds>, and a whole \
         planet's raster must be twice as wide as high"
    )]
    /// Neither a georeference nor a whole planet's shape.
    NoPlacement {
        /// The file.
        path: String,
        /// Its pixels across.
        width: u32,
        /// Its pixels down.
        height: u32,
    },
    /// A georeference the planet cannot use (projected, other units, out of range, too small a region).
    #[error("terrain-file {path}: {message}")]
    BadPlacement {
        /// The file.
        path: String,
        /// Why, and what would do.
        message: String,
    },
}

/// Where a raster lies on the planet: the longitude of its west edge, the latitude of its north edge (degrees) and
/// the degrees each pixel spans along longitude and latitude (pixels as areas, row 0 in the north).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Longitude of the west edge, degrees.
    pub west: f64,
    /// Latitude of the north edge, degrees.
    pub north: f64,
    /// Degrees a pixel spans along longitude and latitude.
    pub degrees_per_pixel: (f64, f64),
}

impl Placement {
    /// The whole sphere, from longitude -180 and the north pole.
    pub fn whole(width: u32, height: u32) -> Self {
        Self {
            west: -180.0,
            north: 90.0,
            degrees_per_pixel: (360.0 / width as f64, 180.0 / height as f64),
        }
    }

    /// `[west, south, east, north]` in degrees over `width` x `height` pixels.
    pub fn from_bounds([west, south, east, north]: [f64; 4], width: u32, height: u32) -> Self {
        Self {
            west,
            north,
            degrees_per_pixel: (
                (east - west) / width as f64,
                (north - south) / height as f64,
            ),
        }
    }

    /// `[west, south, east, north]` of `width` x `height` pixels.
    pub fn bounds(&self, width: u32, height: u32) -> [f64; 4] {
        let (dx, dy) = self.degrees_per_pixel;
        [
            self.west,
            self.north - dy * height as f64,
            self.west + dx * width as f64,
            self.north,
        ]
    }

    /// Whether `width` x `height` pixels cover the whole sphere.
    pub fn covers_the_sphere(&self, width: u32, height: u32) -> bool {
        let [_, south, east, north] = self.bounds(width, height);
        let close = |a: f64, b: f64| (a - b).abs() < 1e-6;
        close(east - self.west, 360.0) && close(north, 90.0) && close(south, -90.0)
    }

    /// Why these bounds cannot place a raster on the sphere, if they cannot.
    fn check(&self, width: u32, height: u32) -> Result<(), String> {
        let [west, south, east, north] = self.bounds(width, height);
        let finite = [west, south, east, north].iter().all(|v| v.is_finite());
        if !(finite && west < east && east - west <= 360.0 + 1e-9) {
            return Err(format!(
                "its longitudes {west} to {east} must rise from west to east over at most 360 degrees"
            ));
        }
        if !(-90.0 - 1e-9..=90.0 + 1e-9).contains(&south)
            || !(-90.0 - 1e-9..=90.0 + 1e-9).contains(&north)
            || south >= north
        {
            return Err(format!(
                "its latitudes {south} to {north} must rise from south to north within [-90, 90]"
            ));
        }
        Ok(())
    }
}

/// A raster's heights, row 0 in the north (pixel centres half a pixel in), where [`Placement`] says.
pub struct TerrainFile {
    width: u32,
    height: u32,
    heights: Vec<f32>,
    placement: Placement,
    region: bool,
}

/// The share of a region's width and height over which its heights blend into the procedural planet's.
pub const REGION_BLEND: f64 = 0.1;

impl TerrainFile {
    /// Reads `path` and checks it holds heights for every pixel. A PNG's 16-bit values become `height_offset +
    /// height_scale x value`, from the JSON beside it (`PATH.json`, as `export` writes) where there is one, else
    /// from `scale_offset`. The raster lies where `bounds` (`[west, south, east, north]` in degrees) says, else
    /// where a TIFF's GeoTIFF tags say, else where the JSON beside it says (`bounds`, as `export` writes for a PNG
    /// or EXR), else over the whole sphere if it is twice as wide as high; a whole planet needs land and sea at
    /// `sea_level`.
    pub fn load(
        path: &Path,
        scale_offset: (f32, f32),
        sea_level: f32,
        bounds: Option<[f64; 4]>,
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
        let ((width, height, heights), tagged) = match extension.as_deref() {
            Some("tif" | "tiff") => read_tiff(path).map_err(unreadable)?,
            Some("exr") => (read_exr(path).map_err(unreadable)?, None),
            Some("png") => (read_png(path, scale_offset).map_err(unreadable)?, None),
            _ => {
                return Err(unreadable(
                    "the name must end in .tif, .tiff, .exr or .png (32-bit float TIFF, OpenEXR channel Y, or \
                     16-bit grey PNG)"
                        .into(),
                ))
            }
        };
        // The configuration's bounds, else the GeoTIFF tags, else the bounds in the JSON beside the file.
        let beside = bounds_beside(path).map_err(unreadable)?;
        let placement = match (bounds, tagged, beside) {
            (Some(bounds), ..) => Placement::from_bounds(bounds, width, height),
            (None, Some(tagged), _) => tagged,
            (None, None, Some(bounds)) => Placement::from_bounds(bounds, width, height),
            (None, None, None) if width == 2 * height => Placement::whole(width, height),
            (None, None, None) => {
                return Err(TerrainFileError::NoPlacement {
                    path: name,
                    width,
                    height,
                })
            }
        };
        placement
            .check(width, height)
            .map_err(|message| TerrainFileError::BadPlacement {
                path: name.clone(),
                message,
            })?;
        let region = !placement.covers_the_sphere(width, height);
        if (!region && (width < 8 || height < 4)) || width < 2 || height < 2 {
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
        if !region && (lowest > sea_level || highest <= sea_level) {
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
            placement,
            region,
        })
    }

    /// Whether the raster is a region on a procedural planet rather than the whole sphere.
    pub fn is_region(&self) -> bool {
        self.region
    }

    /// `[west, south, east, north]` in degrees.
    pub fn bounds(&self) -> [f64; 4] {
        self.placement.bounds(self.width, self.height)
    }

    /// Where direction `p` falls on the raster, in pixels from its north-west corner (longitudes east of the west
    /// edge, wrapping once round the sphere).
    fn pixel_of(&self, p: DVec3) -> (f64, f64) {
        let (lon, lat) = super::lon_lat(p);
        let (dx, dy) = self.placement.degrees_per_pixel;
        let east_of_west = (lon - self.placement.west).rem_euclid(360.0);
        (east_of_west / dx, (self.placement.north - lat) / dy)
    }

    /// The height towards direction `p`: bilinear between the four nearest pixel centres; a whole planet's across
    /// the antimeridian, a region's clamped to its edge pixels; poleward of the first and last rows' centres, the
    /// row's value.
    pub fn height_towards(&self, p: DVec3) -> f64 {
        let (px, py) = self.pixel_of(p);
        let (w, h) = (self.width as f64, self.height as f64);
        let x = match self.region {
            true => (px - 0.5).clamp(0.0, w - 1.0),
            false => px - 0.5,
        };
        let y = (py - 0.5).clamp(0.0, h - 1.0);
        let (x0, y0) = (x.floor().min(w - 2.0), y.floor().min(h - 2.0));
        let (fx, fy) = (x - x0, y - y0);
        let at = |i: f64, j: f64| {
            let i = (i as i64).rem_euclid(self.width as i64) as usize;
            self.heights[j as usize * self.width as usize + i] as f64
        };
        let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1.0, y0) * fx;
        let bottom = at(x0, y0 + 1.0) * (1.0 - fx) + at(x0 + 1.0, y0 + 1.0) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// Blends a region's heights into `lattice` (the procedural planet's), by [`TerrainFile::weight_towards`].
    pub fn paste(&self, lattice: &mut FaceLattice) {
        let side = lattice.cells + 1;
        for face in 0..FACES {
            for j in 0..side {
                for i in 0..side {
                    let p = lattice.direction(lattice.key(face, i, j));
                    let weight = self.weight_towards(p);
                    if weight > 0.0 {
                        let index = lattice.index(face, i, j);
                        let own = lattice.data[index] as f64;
                        lattice.data[index] =
                            (own + (self.height_towards(p) - own) * weight) as f32;
                    }
                }
            }
        }
    }

    /// The file's detail finer than the base lattice, into `fine` (diamond-square's refinement of the carved
    /// `base`, `fine.cells` a power-of-two multiple of `base.cells`): where the file gives a point's height
    /// (weight `w`, [`TerrainFile::weight_towards`]), the displacement of diamond-square's levels whose cells are at
    /// least the file's pixels gives way to the file's own detail, the file's height less its bilinear
    /// interpolation between the base lattice's points: `fine + w ((base bilinear - level bilinear) + (file -
    /// file's base bilinear))`, with `level` the lattice of the finest such level (its points are `fine`'s at its
    /// stride). The carved beds, everything the base lattice holds, and diamond-square's detail below the file's
    /// pixels stay; a file no finer than the base lattice is left out.
    pub fn add_detail(&self, base: &FaceLattice, fine: &mut FaceLattice) {
        let (side, base_side) = (fine.side(), base.side());
        let scale = fine.cells / base.cells;
        // Levels below the base lattice whose cells the file's pixels resolve (cells of 90 / cells degrees).
        let (dx, dy) = self.placement.degrees_per_pixel;
        let base_cell = 90.0 / base.cells as f64;
        let resolved =
            ((base_cell / dx.max(dy)).log2().floor().max(0.0) as u32).min(scale.trailing_zeros());
        if resolved == 0 {
            return;
        }
        let stride = scale >> resolved;
        let file_at_base: Vec<f64> = (0..FACES * base_side * base_side)
            .into_par_iter()
            .map(|k| {
                let (face, rest) = (k / (base_side * base_side), k % (base_side * base_side));
                let (i, j) = ((rest % base_side) as u32, (rest / base_side) as u32);
                self.height_towards(base.direction(base.key(face, i, j)))
            })
            .collect();
        let lattice = &*fine;
        let detailed: Vec<f32> = (0..FACES * side * side)
            .into_par_iter()
            .map(|k| {
                let (face, rest) = (k / (side * side), k % (side * side));
                let (i, j) = ((rest % side) as u32, (rest / side) as u32);
                let own = lattice.data[k] as f64;
                let p = lattice.direction(lattice.key(face, i, j));
                let weight = self.weight_towards(p);
                if weight == 0.0 {
                    return own as f32;
                }
                // The base cell holding the point, and where in it.
                let (bi, bj) = (
                    (i / scale).min(base.cells - 1),
                    (j / scale).min(base.cells - 1),
                );
                let (fx, fy) = (
                    (i - bi * scale) as f64 / scale as f64,
                    (j - bj * scale) as f64 / scale as f64,
                );
                let bilinear = |at: &dyn Fn(u32, u32) -> f64| {
                    let top = at(bi, bj) * (1.0 - fx) + at(bi + 1, bj) * fx;
                    let bottom = at(bi, bj + 1) * (1.0 - fx) + at(bi + 1, bj + 1) * fx;
                    top * (1.0 - fy) + bottom * fy
                };
                let carved = bilinear(&|i, j| base.get(face, i, j) as f64);
                let file_coarse = bilinear(&|i, j| file_at_base[base.index(face, i, j)]);
                let file_detail = self.height_towards(p) - file_coarse;
                // The finest resolved level's lattice, bilinear at the point.
                let (li, lj) = (
                    (i / stride).min(fine.cells / stride - 1),
                    (j / stride).min(fine.cells / stride - 1),
                );
                let (gx, gy) = (
                    (i - li * stride) as f64 / stride as f64,
                    (j - lj * stride) as f64 / stride as f64,
                );
                let at = |i: u32, j: u32| lattice.get(face, i * stride, j * stride) as f64;
                let level = (at(li, lj) * (1.0 - gx) + at(li + 1, lj) * gx) * (1.0 - gy)
                    + (at(li, lj + 1) * (1.0 - gx) + at(li + 1, lj + 1) * gx) * gy;
                (own + weight * (carved - level + file_detail)) as f32
            })
            .collect();
        fine.data = detailed;
    }

    /// How much of the height towards `p` the file gives: 1 on a whole planet and inside a region, falling
    /// smoothly to 0 over the region's outer [`REGION_BLEND`] of its width and height, 0 outside it.
    pub fn weight_towards(&self, p: DVec3) -> f64 {
        if !self.region {
            return 1.0;
        }
        let (px, py) = self.pixel_of(p);
        let (u, v) = (px / self.width as f64, py / self.height as f64);
        let ramp = |t: f64| {
            let s = (t.min(1.0 - t) / REGION_BLEND).clamp(0.0, 1.0);
            s * s * (3.0 - 2.0 * s)
        };
        if !(0.0..=1.0).contains(&u) || !(0.0..=1.0).contains(&v) {
            return 0.0;
        }
        ramp(u) * ramp(v)
    }
}

type Heights = (u32, u32, Vec<f32>);

/// A TIFF's heights, and where its GeoTIFF tags place it, if they do.
fn read_tiff(path: &Path) -> Result<(Heights, Option<Placement>), String> {
    use tiff::decoder::{Decoder, DecodingResult};
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut decoder = Decoder::new(std::io::BufReader::new(file)).map_err(|e| e.to_string())?;
    let (width, height) = decoder.dimensions().map_err(|e| e.to_string())?;
    let placement = georeference(&mut decoder)?;
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

/// `bounds` (`[west, south, east, north]` in degrees) from the JSON `export` writes beside a raster, if it has
/// them.
fn bounds_beside(path: &Path) -> Result<Option<[f64; 4]>, String> {
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
            placement: Placement::whole(8, 4),
            region: false,
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
