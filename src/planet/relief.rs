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
    let sea_level = planet.sea_level_height as f64;
    let land = land_of(lattice, grid, sea_level);
    let CoastDistances { to_sea, to_land } = CoastDistances::new(grid, &land);
    let low = planet.continent_height as f64;
    let high = planet.max_mountain_height as f64;
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
                shelf(planet, to_land[k])
            }
        })
        .collect();
    grid.write(&raised, lattice);
}

/// Which nodes of `lattice` stand above `sea_level`.
pub fn land_of(lattice: &FaceLattice, grid: &SphereGrid, sea_level: f64) -> Vec<bool> {
    grid.values(lattice)
        .iter()
        .map(|&h| h > sea_level)
        .collect()
}

/// The height of the sea floor `to_land` radians from the nearest land: falling from the sea level to
/// `ocean-height` over a shelf.
pub fn shelf(planet: &PlanetConfig, to_land: f64) -> f64 {
    let (sea_level, ocean) = (planet.sea_level_height as f64, planet.ocean_height as f64);
    sea_level - (sea_level - ocean) * (1.0 - (-to_land / SHELF_ANGLE).exp())
}

/// Distances along the grid (radians) of every land node from the nearest sea node, and of every sea node from
/// the nearest land node.
pub struct CoastDistances {
    /// Per node: from a land node to the nearest sea node (0 at sea).
    pub to_sea: Vec<f64>,
    /// Per node: from a sea node to the nearest land node (0 on land).
    pub to_land: Vec<f64>,
}

impl CoastDistances {
    /// Both distances on `grid` for the nodes `land` marks, along the grid from the nodes beside the coast.
    pub fn new(grid: &SphereGrid, land: &[bool]) -> Self {
        Self::within(grid, land, f64::INFINITY)
    }

    /// Both distances where they are at most `limit` (radians), `f64::INFINITY` beyond; the two searches run
    /// side by side.
    pub fn within(grid: &SphereGrid, land: &[bool], limit: f64) -> Self {
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
        let (to_sea, to_land) = rayon::join(
            || grid.nearest(&coast(true), limit).0,
            || grid.nearest(&coast(false), limit).0,
        );
        Self { to_sea, to_land }
    }
}
