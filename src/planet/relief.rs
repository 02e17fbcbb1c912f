//! Relief worth draining (drainage model, beyond the thesis; docs/planet.md): instead of a plateau at one height
//! with square mountains, land rises from the coast inland, mountain ranges follow the crests of ridged noise, and
//! hills roughen the rest; the sea floor falls from the coast to the ocean depth over a shelf, so coasts lie where
//! smooth heights cross the sea level instead of on the base lattice's cell edges.

use glam::DVec3;
use rayon::prelude::*;

use super::{heights::FaceLattice, noise};
use crate::{config::PlanetConfig, drainage::grid::SphereGrid, rng};

const STREAM_RANGES: u64 = 0x524c_0001;
const STREAM_HILLS: u64 = 0x524c_0002;

/// Angle over which land rises to its full height from the coast (radians; about 380 km on Earth).
const RISE_ANGLE: f64 = 0.25;
/// Angle over which the sea floor falls to the ocean depth from the coast.
const SHELF_ANGLE: f64 = 0.1;
/// Angle over which the shore rises from the sea level to `continent-height`.
const SHORE_ANGLE: f64 = 0.08;
/// Ranges per radian: the frequency of the ridged noise's first octave.
const RANGE_FREQUENCY: f64 = 5.0;
const HILL_FREQUENCY: f64 = 24.0;

/// Replaces the continents' two heights (land at `continent-height`, sea at `ocean-height`) with relief: on land
/// a shore rising from the sea level to `continent-height`, and inland a rise to `max-mountain-height` on the
/// crests of the ranges; at sea a shelf falling from the sea level to `ocean-height`. Land stays land and sea
/// stays sea.
pub fn raise(lattice: &mut FaceLattice, grid: &SphereGrid, planet: &PlanetConfig, seed: u64) {
    let heights = grid.values(lattice);
    let sea_level = planet.sea_level_height as f64;
    let land: Vec<bool> = heights.iter().map(|&h| h > sea_level).collect();
    let coast = |is_land: bool| -> Vec<u32> {
        (0..grid.len() as u32)
            .filter(|&k| land[k as usize] != is_land)
            .filter(|&k| {
                grid.neighbours(k)
                    .iter()
                    .any(|&n| land[n as usize] == is_land)
            })
            .collect()
    };
    // Distance of every land node from the nearest sea node, and of every sea node from the nearest land node.
    let (to_sea, _) = grid.nearest(&coast(true), f64::INFINITY);
    let (to_land, _) = grid.nearest(&coast(false), f64::INFINITY);
    let low = planet.continent_height as f64;
    let high = planet.max_mountain_height as f64;
    let ocean = planet.ocean_height as f64;
    let ranges_seed = rng::hash(seed, &[STREAM_RANGES]);
    let hills_seed = rng::hash(seed, &[STREAM_HILLS]);
    let raised: Vec<f64> = (0..grid.len())
        .into_par_iter()
        .map(|k| {
            let d: DVec3 = grid.directions[k];
            if land[k] {
                let rise = 1.0 - (-to_sea[k] / RISE_ANGLE).exp();
                let ranges = noise::ridged(ranges_seed, d, RANGE_FREQUENCY, 5);
                let hills = noise::fbm(hills_seed, d, HILL_FREQUENCY, 3);
                let relief = 0.15 + 0.85 * ranges * ranges + 0.08 * hills;
                let shore = 1.0 - (-to_sea[k] / SHORE_ANGLE).exp();
                let h = sea_level + (low - sea_level) * shore + (high - low) * rise * relief;
                h.max(sea_level + 0.01 * (low - sea_level))
            } else {
                let shelf = 1.0 - (-to_land[k] / SHELF_ANGLE).exp();
                sea_level - (sea_level - ocean) * shelf
            }
        })
        .collect();
    grid.write(&raised, lattice);
}
