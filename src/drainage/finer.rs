//! The drainage network at a finer level of detail (beyond the thesis; docs/rivers.md, "Rivers at every scale"):
//! the water routed again over the heights of that level, where diamond-square has refined the base lattice and
//! its river beds, with a stream wherever as many lattice cells drain as start one on the base lattice. So each
//! level adds the first-order streams its resolution can hold (a quarter of the source area per level), draining
//! downhill on that level's heights into the rivers they join, with the same guarantees as the base network: no
//! uphill step, no crossing (both measured, [`super::rivers::DrainageMeasures`]).

use super::{drain_paths, grid::SphereGrid, meander_reaches, Drainage};
use crate::{
    config::Config,
    planet::{heights::FaceLattice, Planet},
};

/// Levels above the base lattice's at which the network can be made: two levels is 16 times the base lattice's
/// points (1.6 million on the default planet: about 5 s and 1 GB).
pub const MAX_LEVELS_ABOVE_BASE: u32 = 2;

/// The drainage network of `planet` at `level` (a patch level): the base network at or below the base lattice's
/// level, routed anew above it; `None` for the thesis's river model.
pub fn network_at(planet: &Planet, config: &Config, level: u32) -> Option<Drainage> {
    let base = planet.drainage.as_ref()?;
    if level <= planet.stats.base_level {
        return Some(base.clone());
    }
    let mut lattice = planet.face_lattice(level);
    let mut network = routed_at(planet, config, level, &mut lattice);
    network.reaches = meander_reaches(
        &network.reaches,
        lattice.cells,
        &config.planet,
        &config.river,
        network.largest_area,
    );
    Some(network)
}

/// [`network_at`] above the base level before its rivers meander (along their lattice paths), on `lattice`
/// (that level's heights), which gets the carved beds.
pub fn routed_at(
    planet: &Planet,
    config: &Config,
    level: u32,
    lattice: &mut FaceLattice,
) -> Drainage {
    let grid = SphereGrid::new(lattice);
    let mut river = config.river.clone();
    // The base rule (a stream where `source-area` drains) in cells of this level: a quarter per level.
    river.source_area /= 4f32.powi((level - planet.stats.base_level) as i32);
    drain_paths(lattice, &grid, &config.planet, &river)
}
