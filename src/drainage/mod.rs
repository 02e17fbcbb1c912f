//! Drainage networks (beyond the thesis; docs/rivers.md): water routed over the whole sphere at the base
//! resolution, so rivers run downhill, join at confluences and end in the sea or in lakes, and the terrain falls
//! towards them in valleys. The thesis's rivers (one random walk per mountain, Chapter 5) stay selectable as
//! `<river-model>thesis</river-model>`.

pub mod drawn;
pub mod finer;
pub mod grid;
pub mod junctions;
pub mod meanders;
pub mod rivers;
pub mod routing;
pub mod streams;
pub mod valleys;

use glam::DVec3;
use serde::Serialize;

use crate::{
    config::{PlanetConfig, RiverConfig},
    planet::heights::FaceLattice,
};
use grid::SphereGrid;
use rivers::{extract, DrainageMeasures, Thresholds};
use routing::route;

/// One reach as the river model needs it: points on the unit sphere in flow order, with the bed height and the
/// drainage area (world units squared) at each.
#[derive(Clone, Debug)]
pub struct ReachPath {
    /// Unit directions, upstream first.
    pub points: Vec<DVec3>,
    /// The bed height at each point, never rising downstream.
    pub beds: Vec<f32>,
    /// The drainage area at each point, world units squared.
    pub areas: Vec<f64>,
    /// Strahler order of the reach.
    pub strahler: u32,
    /// The reach this one flows into (an index into [`Drainage::reaches`]); `None` at a mouth.
    pub downstream: Option<usize>,
}

/// A lake: the directions of its nodes and its water level.
#[derive(Clone, Debug, Serialize)]
pub struct LakeShape {
    /// Unit directions of the lake's lattice nodes.
    #[serde(skip)]
    pub points: Vec<DVec3>,
    /// The water level (the spill height of its depression).
    pub level: f32,
    /// Area on the sphere, world units squared.
    pub area: f64,
}

/// The drained planet: its reaches, lakes and measures.
#[derive(Clone, Debug, Default)]
pub struct Drainage {
    /// Every reach; a reach comes after every reach that flows into it.
    pub reaches: Vec<ReachPath>,
    /// Depressions deep enough to hold water.
    pub lakes: Vec<LakeShape>,
    /// The network's statistics (stats.json, docs/geomorphology.md).
    pub measures: DrainageMeasures,
    /// The largest drainage area of any river node (world units squared): widths scale against it.
    pub largest_area: f64,
}

/// Routes the water of `lattice` (the base heights), extracts rivers and lakes, carves valleys into `lattice`
/// around the rivers, and lets the rivers meander ([`meander_reaches`]).
pub fn drain(
    lattice: &mut FaceLattice,
    grid: &SphereGrid,
    planet: &PlanetConfig,
    river: &RiverConfig,
) -> Drainage {
    let mut drainage = drain_paths(lattice, grid, planet, river);
    drainage.reaches = meander_reaches(
        &drainage.reaches,
        grid.cells,
        planet,
        river,
        drainage.largest_area,
    );
    drainage
}

/// [`drain`] with the reaches along their lattice paths.
pub fn drain_paths(
    lattice: &mut FaceLattice,
    grid: &SphereGrid,
    planet: &PlanetConfig,
    river: &RiverConfig,
) -> Drainage {
    let heights = grid.values(lattice);
    let sea_level = planet.sea_level_height as f64;
    let radius = planet.radius as f64;
    let mut routing = route(grid, &heights, sea_level);
    let network = extract(
        grid,
        &mut routing,
        &heights,
        sea_level,
        Thresholds {
            river_area: river.source_area as f64 / (radius * radius),
            lake_depth: river.lake_depth as f64,
        },
    );
    // Eroded or measured relief has its valleys already: the rivers are the ones the erosion (or the land) cut.
    let carved = if planet.relief_model.has_valleys() {
        valleys::cut_beds(grid, &routing, &network, &heights, sea_level)
    } else {
        valleys::carve(grid, &routing, &network, &heights, sea_level)
    };
    grid.write(&carved, lattice);
    let r2 = radius * radius;
    let directions = |nodes: &[u32]| -> Vec<DVec3> {
        nodes.iter().map(|&k| grid.directions[k as usize]).collect()
    };
    let base_levels = base_levels(&network, sea_level);
    let reaches: Vec<ReachPath> = network
        .reaches
        .iter()
        .zip(&base_levels)
        .map(|(reach, &base_level)| ReachPath {
            points: directions(&reach.nodes),
            beds: beds(reach, &carved, &network, (sea_level, base_level)),
            areas: reach
                .nodes
                .iter()
                .map(|&k| routing.area[k as usize] * r2)
                .collect(),
            strahler: reach.strahler,
            downstream: reach.downstream,
        })
        .collect();
    let largest_area = reaches
        .iter()
        .flat_map(|r| r.areas.iter().copied())
        .fold(0.0, f64::max);
    let lakes = network
        .lakes
        .iter()
        .map(|lake| LakeShape {
            points: directions(&lake.nodes),
            level: lake.level as f32,
            area: lake
                .nodes
                .iter()
                .map(|&k| grid.areas[k as usize])
                .sum::<f64>()
                * r2,
        })
        .collect();
    Drainage {
        reaches,
        lakes,
        measures: network.measures,
        largest_area,
    }
}

/// Rivers on the eroded relief meander through their valleys (the carved relief keeps the thesis-era paths):
/// `reaches` on a lattice of `cells` cells per face edge, widths against `largest_area`.
pub fn meander_reaches(
    reaches: &[ReachPath],
    cells: u32,
    planet: &PlanetConfig,
    river: &RiverConfig,
    largest_area: f64,
) -> Vec<ReachPath> {
    if !planet.relief_model.has_valleys() {
        return reaches.to_vec();
    }
    {
        let radius = planet.radius as f64;
        let scale = meanders::MeanderScale {
            cell: std::f64::consts::FRAC_PI_2 / cells as f64,
            radius,
            relief_slope: (planet.max_mountain_height - planet.sea_level_height) as f64 / radius,
        };
        meanders::meander_all(reaches, &scale, |a| width(river, largest_area, a) as f64)
    }
}

/// Hydraulic geometry: a river's full width grows with the square root of its discharge, taken as proportional
/// to its drainage area (world units squared), from `min-width` at no area to the widest river (`starting-width
/// x ending-factor`) at the planet's largest drainage area.
pub fn width(river: &RiverConfig, largest_area: f64, area: f64) -> f32 {
    let widest = river.starting_width * river.ending_factor.max(1.0);
    let share = (area / largest_area.max(f64::MIN_POSITIVE)).sqrt() as f32;
    river.min_width + (widest - river.min_width) * share.clamp(0.0, 1.0)
}

/// The base level of each reach: the level of the water its river ends in, a lake's or the sea's. Reaches come
/// upstream first, so each one's downstream reach is decided before it when taken in reverse.
fn base_levels(network: &rivers::DrainageNetwork, sea_level: f64) -> Vec<f64> {
    let mut levels = vec![sea_level; network.reaches.len()];
    for (k, reach) in network.reaches.iter().enumerate().rev() {
        levels[k] = match reach.downstream {
            Some(d) => levels[d],
            None => reach
                .nodes
                .last()
                .and_then(|&end| network.lake_of[end as usize])
                .map_or(sea_level, |lake| network.lakes[lake as usize].level),
        };
    }
    levels
}

/// Bed heights along a reach: the carved terrain at its river nodes; at a mouth the sea level or the lake's level;
/// never rising downstream, and never below the `base_level` of the water the river ends in: where the valley
/// carved into the eroded land lies below the level of the lake it runs into, the lake's water stands in it (a
/// drowned mouth), and a river drawn below the lake's surface would pull the lake's water down beside it
/// (tests/river_surface.rs).
fn beds(
    reach: &rivers::Reach,
    carved: &[f64],
    network: &rivers::DrainageNetwork,
    (sea_level, base_level): (f64, f64),
) -> Vec<f32> {
    let mut out: Vec<f32> = Vec::with_capacity(reach.nodes.len());
    for &k in &reach.nodes {
        let k = k as usize;
        let h = match network.lake_of[k] {
            Some(lake) => network.lakes[lake as usize].level,
            None if carved[k] <= sea_level => sea_level,
            None => carved[k],
        };
        let h = h.max(base_level) as f32;
        out.push(out.last().map_or(h, |&above: &f32| above.min(h)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A river whose valley was cut below the level of the lake it runs into (nodes 2-4 below 2.0) has its beds
    /// at the lake's level there, its tributary ends where it begins, and a river to the sea keeps its valley.
    #[test]
    fn beds_never_lie_below_the_lake_their_river_ends_in() {
        let reach = |nodes: Vec<u32>, downstream| rivers::Reach {
            nodes,
            strahler: 1,
            downstream,
        };
        let network = rivers::DrainageNetwork {
            // Upstream first: the tributary, the stem into the lake (node 5), a river to the sea (node 8).
            reaches: vec![
                reach(vec![0, 1, 2], Some(1)),
                reach(vec![2, 3, 4, 5], None),
                reach(vec![6, 7, 8], None),
            ],
            lakes: vec![rivers::Lake {
                nodes: vec![5],
                level: 2.0,
            }],
            lake_of: (0..9).map(|k| (k == 5).then_some(0)).collect(),
            measures: Default::default(),
        };
        let carved = [3.0, 2.5, 1.5, 1.2, 1.0, 0.5, 1.5, 0.8, 0.0];
        let sea_level = 0.0;
        let levels = base_levels(&network, sea_level);
        assert_eq!(levels, vec![2.0, 2.0, 0.0]);
        let beds: Vec<Vec<f32>> = network
            .reaches
            .iter()
            .zip(&levels)
            .map(|(r, &base)| beds(r, &carved, &network, (sea_level, base)))
            .collect();
        assert_eq!(beds[0], vec![3.0, 2.5, 2.0]);
        assert_eq!(beds[1], vec![2.0, 2.0, 2.0, 2.0]);
        assert_eq!(beds[2], vec![1.5, 0.8, 0.0]);
    }
}
