//! `riverplanet export region` (beyond the thesis): a longitude-latitude window of the planet at one level of
//! detail, sampled at pixel centres from the carved patches of that level (`runtime::surface`) that it touches,
//! as a georeferenced raster or as a mesh ([`super::mesh`]).

use glam::DVec3;
use rayon::prelude::*;

use super::raster::Georeference;
use crate::{
    config::Config,
    planet::{cube::PatchId, direction_at, Planet},
    river::network::RiverNetwork,
    runtime::surface::{carve_patches, CarvedPatch},
};

/// The most pixels (or mesh vertices) a region may have: 16 M (64 MB per f32 layer).
pub const MAX_REGION_PIXELS: u64 = 1 << 24;

/// A window west..east, south..north (degrees) split into `size` pixels of equal angle, sampled at their centres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// Longitude of the west edge.
    pub west: f64,
    /// Latitude of the south edge.
    pub south: f64,
    /// Longitude of the east edge.
    pub east: f64,
    /// Latitude of the north edge.
    pub north: f64,
    /// Pixels across and down.
    pub size: (u32, u32),
}

impl Region {
    /// The window `bounds` (west, south, east, north in degrees) at about the vertex spacing of `level`: pixels
    /// as tall as the lattice's spacing at a face's centre, and as wide as that on the ground at the window's
    /// middle latitude. Errors name what is wrong.
    pub fn new([west, south, east, north]: [f64; 4], level: u32) -> Result<Self, String> {
        if !(-180.0..=180.0).contains(&west) || !(-180.0..=180.0).contains(&east) || west >= east {
            return Err(format!(
                "--bounds: longitudes {west} and {east} must lie in [-180, 180], west below east"
            ));
        }
        if !(-90.0..=90.0).contains(&south) || !(-90.0..=90.0).contains(&north) || south >= north {
            return Err(format!(
                "--bounds: latitudes {south} and {north} must lie in [-90, 90], south below north"
            ));
        }
        let spacing = 90.0 / (32u64 << level) as f64;
        let middle = (0.5 * (south + north)).to_radians().cos().max(0.05);
        let columns = ((east - west) * middle / spacing).round().max(2.0);
        let rows = ((north - south) / spacing).round().max(2.0);
        if columns * rows > MAX_REGION_PIXELS as f64 {
            return Err(format!(
                "--bounds and --level {level}: {columns} x {rows} samples; at most {MAX_REGION_PIXELS} \
                 (a smaller window or a coarser level)"
            ));
        }
        Ok(Self {
            west,
            south,
            east,
            north,
            size: (columns as u32, rows as u32),
        })
    }

    /// Degrees per pixel along longitude and latitude.
    pub fn degrees_per_pixel(&self) -> (f64, f64) {
        (
            (self.east - self.west) / self.size.0 as f64,
            (self.north - self.south) / self.size.1 as f64,
        )
    }

    /// The unit direction at the centre of pixel (x, y), row 0 in the north.
    pub fn direction(&self, x: u32, y: u32) -> DVec3 {
        let (dx, dy) = self.degrees_per_pixel();
        direction_at(
            self.west + (x as f64 + 0.5) * dx,
            self.north - (y as f64 + 0.5) * dy,
        )
    }

    /// Its GeoTIFF georeference on a sphere of `radius`.
    pub fn georeference(&self, radius: f64) -> Georeference {
        Georeference {
            west: self.west,
            north: self.north,
            degrees_per_pixel: self.degrees_per_pixel(),
            radius,
        }
    }
}

/// A region's surface, row by row from the north-west: terrain heights (river beds carved in), water heights, and
/// how far inside a river's basin each sample lies ([`CarvedPatch::basin`]).
pub struct RegionSurface {
    /// Terrain heights with the river beds carved in.
    pub terrain: Vec<f32>,
    /// Water heights.
    pub water: Vec<f32>,
    /// How far inside a river's basin each sample lies.
    pub basin: Vec<f32>,
}

/// Samples `region` from the carved patches of `level` that contain its pixels' centres, bilinear between each
/// patch's vertices. A pixel on a face edge reads one face's patch (they can differ there; docs/exports.md).
/// `carved` is called with the number of patches to carve as each one is done (from any thread: progress).
pub fn sample_region(
    planet: &Planet,
    network: &RiverNetwork,
    config: &Config,
    level: u32,
    region: &Region,
    carved: &(dyn Fn(usize) + Sync),
) -> RegionSurface {
    let (width, height) = region.size;
    let pixels: Vec<(DVec3, PatchId)> = (0..width * height)
        .into_par_iter()
        .map(|k| {
            let d = region.direction(k % width, k / width);
            (d, PatchId::containing(d, level as u8))
        })
        .collect();
    let mut patches: Vec<PatchId> = pixels.iter().map(|(_, p)| *p).collect();
    patches.sort_unstable();
    patches.dedup();
    let total = patches.len();
    let carved = carve_patches(&patches, planet, network, config, &|| carved(total));
    let n = config.rendering.vertices;
    let sample = |layer: fn(&CarvedPatch) -> &[f32]| -> Vec<f32> {
        pixels
            .par_iter()
            .map(|(d, patch)| carved[patch].at(layer(&carved[patch]), *d, n))
            .collect()
    };
    RegionSurface {
        terrain: sample(|c| &c.terrain),
        water: sample(|c| &c.water),
        basin: sample(|c| &c.basin),
    }
}
