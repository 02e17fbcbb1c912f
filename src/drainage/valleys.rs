//! Valleys around the rivers (drainage model): the terrain near a river falls towards the river's bed, over a
//! half-width that grows with the river's drainage area, so rivers lie in valleys rather than in trenches at every
//! level of detail (the finer levels refine the carved base heights).

use super::{grid::SphereGrid, rivers::DrainageNetwork, routing::Routing};

/// Half-width of the smallest river's valley, in base lattice cells.
const NARROWEST: f64 = 1.5;
/// Half-width of the largest river's valley, in base lattice cells.
const WIDEST: f64 = 4.0;

/// The river nodes (on dry land) and the bed of each: its filled height, lowered to the lowest of its neighbours
/// (D8 lets a river run along a side slope, whose lower side would otherwise stand below the water), and never
/// rising downstream.
fn river_beds(
    grid: &SphereGrid,
    routing: &Routing,
    network: &DrainageNetwork,
    heights: &[f64],
    sea_level: f64,
) -> (Vec<u32>, Vec<f64>) {
    let dry = |k: usize| heights[k] > sea_level && network.lake_of[k].is_none();
    let river_nodes: Vec<u32> = network
        .reaches
        .iter()
        .flat_map(|r| r.nodes.iter().copied())
        .filter(|&k| dry(k as usize))
        .collect();
    let mut bed: Vec<f64> = routing.filled.clone();
    for &k in &river_nodes {
        // A neighbour under the sea or a lake counts at the water's surface: a river beside the coast comes
        // down to the sea level.
        let lowest = grid
            .neighbours(k)
            .iter()
            .map(|&j| match network.lake_of[j as usize] {
                Some(lake) => network.lakes[lake as usize].level,
                None => heights[j as usize].max(sea_level),
            })
            .fold(f64::INFINITY, f64::min);
        bed[k as usize] = bed[k as usize].min(lowest);
    }
    let is_river = {
        let mut is = vec![false; grid.len()];
        river_nodes.iter().for_each(|&k| is[k as usize] = true);
        is
    };
    for &k in &routing.upstream_first {
        let r = routing.receiver[k as usize];
        if is_river[k as usize] && r != super::routing::NONE && is_river[r as usize] {
            bed[r as usize] = bed[r as usize].min(bed[k as usize]);
        }
    }
    (river_nodes, bed)
}

/// The heights with every river node at its bed (`river_beds`) and nothing else changed: the eroded relief's
/// valleys are the erosion's own, only the sills that filled depressions leave along a river are cut.
pub fn cut_beds(
    grid: &SphereGrid,
    routing: &Routing,
    network: &DrainageNetwork,
    heights: &[f64],
    sea_level: f64,
) -> Vec<f64> {
    let (river_nodes, bed) = river_beds(grid, routing, network, heights, sea_level);
    let mut out = heights.to_vec();
    for k in river_nodes {
        out[k as usize] = bed[k as usize];
    }
    out
}

/// The heights with valleys carved. A river node sits at its bed (`river_beds`). A node within a valley's
/// half-width `w` at distance `d` of its nearest river node keeps its height above that bed scaled by
/// `(d / w)^2`, never raised. Sea and lake nodes keep their heights.
pub fn carve(
    grid: &SphereGrid,
    routing: &Routing,
    network: &DrainageNetwork,
    heights: &[f64],
    sea_level: f64,
) -> Vec<f64> {
    let dry = |k: usize| heights[k] > sea_level && network.lake_of[k].is_none();
    let cell = std::f64::consts::FRAC_PI_2 / grid.cells as f64;
    let (river_nodes, bed) = river_beds(grid, routing, network, heights, sea_level);
    let largest = river_nodes
        .iter()
        .map(|&k| routing.area[k as usize])
        .fold(0.0, f64::max);
    let half_width = |k: u32| {
        let share = (routing.area[k as usize] / largest).sqrt();
        cell * (NARROWEST + (WIDEST - NARROWEST) * share)
    };
    let (distance, nearest) = grid.nearest(&river_nodes, WIDEST * cell);
    let mut out = heights.to_vec();
    for k in 0..grid.len() {
        let source = nearest[k];
        if source == u32::MAX || !dry(k) {
            continue;
        }
        let bed = bed[source as usize];
        if source == k as u32 {
            out[k] = bed;
            continue;
        }
        let w = half_width(source);
        if distance[k] < w && heights[k] > bed {
            let t = distance[k] / w;
            out[k] = bed + (heights[k] - bed) * t * t;
        }
    }
    out
}
