//! Lake basins (beyond the thesis, with the eroded relief; docs/planet.md, "Lakes"): a landscape at the steady
//! state of stream-power erosion has no closed depression, yet 1-4 % of real land lies under lakes, most of it in
//! basins that ice sheets scoured (Verpoorter et al. 2014: lake density rises steeply towards high latitudes).
//! Basins are dug into the eroded land as smooth bowls of many sizes, more of them towards the poles; the drainage
//! model then finds them as depressions, fills them to their spill height and makes them lakes, so a lake's shore
//! is the eroded surface's contour at its level and rivers flow into and out of it.

use glam::DVec3;

use crate::{drainage::grid::SphereGrid, rng};

const STREAM_LAKES: u64 = 0x4c41_4b45;
/// Basins per steradian of land at the poles (fewer towards the equator, [`EQUATOR_SHARE`] as many).
const BASINS_PER_STERADIAN: f64 = 800.0;
const EQUATOR_SHARE: f64 = 0.3;
/// Latitudes (degrees) over which basins grow from the equator's share to the poles'.
const GLACIAL_LATITUDES: (f64, f64) = (30.0, 60.0);
/// Basin radii in base cells, spread as r^-2 between these (lake areas over two decades and more).
const SMALLEST_RADIUS: f64 = 1.2;
const LARGEST_RADIUS: f64 = 14.0;
/// A basin's floor below its spill height, in units of `lake-depth` (the depth a depression needs to hold a lake).
const DEPTH: f64 = 2.0;
/// The rim: the outer part of a basin's radius, whose lowest point is where the lake spills.
const RIM: f64 = 0.85;

/// Digs lake basins into the land of `heights` (one per grid node; `land` marks the land nodes). `lake_depth` is
/// the configuration's `lake-depth`; a basin's floor stays half of it above `sea_level`.
pub fn dig(
    heights: &mut [f64],
    grid: &SphereGrid,
    land: &[bool],
    (sea_level, lake_depth): (f64, f64),
    seed: u64,
) {
    let cell = std::f64::consts::FRAC_PI_2 / grid.cells as f64;
    let land_area: f64 = (0..grid.len())
        .filter(|&k| land[k])
        .map(|k| grid.areas[k])
        .sum();
    let candidates = (BASINS_PER_STERADIAN * land_area).round() as u64;
    let seed = rng::hash(seed, &[STREAM_LAKES]);
    for b in 0..candidates {
        let mut r = rng::Rng::new(seed, &[b]);
        let node = r.below(grid.len() as u64) as usize;
        if !land[node] {
            continue;
        }
        let centre: DVec3 = grid.directions[node];
        let latitude = centre.y.clamp(-1.0, 1.0).asin().to_degrees().abs();
        let (lo, hi) = GLACIAL_LATITUDES;
        let t = ((latitude - lo) / (hi - lo)).clamp(0.0, 1.0);
        let share = EQUATOR_SHARE + (1.0 - EQUATOR_SHARE) * t * t * (3.0 - 2.0 * t);
        if r.range_f64(0.0, 1.0) > share {
            continue;
        }
        // r^-2: the inverse of its distribution function between the smallest and largest radius.
        let u = r.range_f64(0.0, 1.0);
        let radius =
            cell / (1.0 / SMALLEST_RADIUS - u * (1.0 / SMALLEST_RADIUS - 1.0 / LARGEST_RADIUS));
        // The nodes within the radius, breadth-first from the centre.
        let mut region = vec![node as u32];
        let mut seen = std::collections::HashSet::from([node as u32]);
        let mut at = 0;
        while at < region.len() {
            for &next in grid.neighbours(region[at]) {
                if grid.directions[next as usize].angle_between(centre) < radius
                    && seen.insert(next)
                {
                    region.push(next);
                }
            }
            at += 1;
        }
        let x = |k: u32| grid.directions[k as usize].angle_between(centre) / radius;
        // The basin spills at the lowest point of its rim; its floor lies DEPTH lake depths below that.
        let spill = region
            .iter()
            .filter(|&&k| x(k) > RIM)
            .map(|&k| heights[k as usize])
            .fold(f64::INFINITY, f64::min);
        let floor = spill - DEPTH * lake_depth;
        // A basin that reaches the sea would drain into it, and one whose floor came near the sea level would
        // leave puddles at sea level once diamond-square roughens it: such land is too low to hold a lake basin.
        if !spill.is_finite()
            || floor < sea_level + 0.5 * lake_depth
            || region.iter().any(|&k| !land[k as usize])
        {
            continue;
        }
        // Flat-floored and steep-sided, as scoured basins are: the land blends from the floor at the centre to
        // itself at the rim, so the shore (where it crosses the spill height) follows the land's own contours.
        for &k in &region {
            let t = x(k).powi(4);
            let h = &mut heights[k as usize];
            *h = h.min(floor + (*h - floor) * t);
        }
    }
}
