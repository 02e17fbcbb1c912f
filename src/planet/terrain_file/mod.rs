//! `<terrain-file>` (beyond the thesis; docs/planet.md, "Heights from a file"): a planet's heights from an
//! equirectangular raster, the coarse levels of a planet whose drainage network is then routed on them: the whole
//! planet, or a georeferenced region placed on the procedural planet. Reads what `riverplanet export equirect`
//! and `export region` write (32-bit float GeoTIFF, OpenEXR channel Y, 16-bit PNG with the height scale and
//! offset in the JSON beside it) and other tools' rasters in those formats.

use std::path::Path;

use glam::DVec3;
use rayon::prelude::*;

use super::{cube::FACES, heights::FaceLattice};

mod lzw;
mod read;
use read::{bounds_beside, read_exr, read_png, read_tiff};

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

    /// Refuses a region (read from `path`) spanning fewer than two cells of a base lattice of `base_cells` cells
    /// per face edge: no lattice point, or one, would take its heights.
    pub fn check_spans_cells(&self, path: &str, base_cells: u32) -> Result<(), TerrainFileError> {
        let [west, south, east, north] = self.bounds();
        let cell = 90.0 / base_cells as f64;
        if (east - west).min(north - south) >= 2.0 * cell {
            return Ok(());
        }
        Err(TerrainFileError::BadPlacement {
            path: path.to_string(),
            message: format!(
                "its region spans {:.3} x {:.3} degrees; it must span at least two of the base lattice's cells \
                 ({cell:.3} degrees with base-resolution {})",
                east - west,
                north - south,
                base_cells + 1
            ),
        })
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
        let file_at_base: Vec<f64> = (0..base.data.len())
            .into_par_iter()
            .map(|k| {
                let (face, i, j) = base.point_of(k);
                self.height_towards(base.direction(base.key(face, i, j)))
            })
            .collect();
        let lattice = &*fine;
        let detailed: Vec<f32> = (0..lattice.data.len())
            .into_par_iter()
            .map(|k| {
                let (face, i, j) = lattice.point_of(k);
                let own = lattice.data[k] as f64;
                let p = lattice.direction(lattice.key(face, i, j));
                let weight = self.weight_towards(p);
                if weight == 0.0 {
                    return own as f32;
                }
                let coarse = |stride: u32, at: &dyn Fn(u32, u32) -> f64| {
                    bilinear_between(lattice.cells, stride, (i, j), at)
                };
                // The base lattice (carved, and the file at its points) and the finest resolved level, bilinear.
                let carved = coarse(scale, &|i, j| base.get(face, i, j) as f64);
                let file_coarse = coarse(scale, &|i, j| file_at_base[base.index(face, i, j)]);
                let file_detail = self.height_towards(p) - file_coarse;
                let level = coarse(stride, &|i, j| {
                    lattice.get(face, i * stride, j * stride) as f64
                });
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

/// Bilinear interpolation at point (i, j) of a lattice of `cells` cells per face edge between the points of its
/// coarser lattice of every `stride`-th point, whose values `at` gives by their coarse (i, j).
fn bilinear_between(
    cells: u32,
    stride: u32,
    (i, j): (u32, u32),
    at: &dyn Fn(u32, u32) -> f64,
) -> f64 {
    let (ci, cj) = (
        (i / stride).min(cells / stride - 1),
        (j / stride).min(cells / stride - 1),
    );
    let (fx, fy) = (
        (i - ci * stride) as f64 / stride as f64,
        (j - cj * stride) as f64 / stride as f64,
    );
    let top = at(ci, cj) * (1.0 - fx) + at(ci + 1, cj) * fx;
    let bottom = at(ci, cj + 1) * (1.0 - fx) + at(ci + 1, cj + 1) * fx;
    top * (1.0 - fy) + bottom * fy
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
