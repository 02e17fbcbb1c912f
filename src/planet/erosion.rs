//! Relief from uplift and erosion (beyond the thesis, the default relief; docs/planet.md, "Relief from uplift and
//! erosion"): the land rises by a tectonic uplift field and is cut down by rivers after the stream-power law
//! `dh/dt = U - K A^m S^n` (Howard 1994; Whipple and Tucker 1999), solved implicitly in O(n) per step along the
//! receiver tree (Braun and Willett 2013, with n = 1) on the whole sphere lattice, until the landscape is near
//! its steady state. Ridges, valleys, divides and river profiles then come from one model, and the drainage
//! network the rivers are later cut from is the one the erosion made.
//!
//! While the network forms, hillslope diffusion acts beside the rivers (`dh/dt = U - K A^m S + D lap h`), so
//! neighbouring valleys compete and the smaller ones are captured, as branching networks form (Perron et al.
//! 2012); afterwards the rivers alone shape the relief towards its steady state (docs/planet.md).
//!
//! The model runs without units and is scaled at the end: with n = 1 the steady state is linear in U / K, so a
//! scale factor changes no shape, no slope-area exponent and no network.

use glam::DVec3;
use rayon::prelude::*;

use super::{
    heights::FaceLattice,
    lakes, noise,
    relief::{self, CoastDistances},
};
use crate::{config::PlanetConfig, drainage::grid::SphereGrid, rng};

const STREAM_BELTS: u64 = 0x4552_0001;
const STREAM_PLATEAUS: u64 = 0x4552_0002;
const STREAM_ROCK: u64 = 0x4552_0003;
const STREAM_START: u64 = 0x4552_0004;
const STREAM_WARP: u64 = 0x4552_0005;

/// The stream-power law's area exponent m (with n = 1): with uniform uplift and rock the steady state's
/// slope-area concavity is m / n, within the range erosion studies find (Whipple and Tucker 1999: 0.35-0.6;
/// Mudd et al. 2018: a median of 0.43 over the world's basins). Uplift that grows inland steepens the heads, so
/// the measured concavity runs about 0.1 above m (docs/geomorphology.md).
pub const AREA_EXPONENT: f64 = 0.4;

/// The time steps of the evolution (model units): growing geometrically from the first so the network organises
/// while the relief is still low and the initial roughness steers it, then long steps towards the steady state.
const FIRST_STEP: f64 = 0.002;
const STEP_GROWTH: f64 = 1.6;
const LONGEST_STEP: f64 = 2.0;
const STEPS: usize = 36;
/// The model time over which the young relief diffuses while its network forms (the first 14 of the
/// [`STEPS`] steps, about a 25th of the evolution); the later, long steps are the stream-power law's alone.
const NETWORK_FORMING_TIME: f64 = 1.0;
/// Explicit diffusion substeps keep `dt D sum(1 / angle^2)` below this (stable below 1/2).
const DIFFUSION_STABILITY: f64 = 0.4;
/// Heights of the initial plain's random roughness (model units; the steady state's relief is about 1 to 10).
const INITIAL_ROUGHNESS: f64 = 0.02;

/// Mountain belts: crests of warped ridged noise, this many per radian, kept where the ridge stands above
/// `BELT_FLOOR` (a narrow band, as orogens are).
const BELT_FREQUENCY: f64 = 2.2;
const BELT_FLOOR: f64 = 0.72;
/// Plateaus: broad uplifted regions where a smooth field stands high.
const PLATEAU_FREQUENCY: f64 = 1.6;
/// Uplift of the lowlands, of plateaus and of the belts' crests, relative to each other.
const LOWLAND_UPLIFT: f64 = 0.08;
const PLATEAU_UPLIFT: f64 = 0.35;
const BELT_UPLIFT: f64 = 1.0;
/// Angle over which uplift grows from the coast inland (radians): coastal plains stay low.
const COASTAL_PLAIN: f64 = 0.06;
/// Erodibility varies with the rock by up to this factor either way (exp of fbm).
const ROCK_CONTRAST: f64 = 0.6;
/// The share of land heights at most [`PEAK_QUANTILE`]: the eroded heights are scaled so this quantile of the
/// land stands at `max-mountain-height` (the highest peaks a little above, with diamond-square detail on top).
const PEAK_QUANTILE: f64 = 0.999;

/// What the evolution reached, for stats.json.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct ErosionReport {
    /// Time steps run.
    pub steps: usize,
    /// Largest height change of the last step relative to the highest land (0 at the steady state).
    pub last_change: f64,
}

/// Replaces the continents' two heights with relief from uplift and stream-power erosion on land, with lake basins
/// dug into it (`lakes`, `lake_depth` the configuration's `lake-depth`), and a shelf at sea. Land stays land
/// (every land node ends above the sea level) and sea stays sea.
pub fn raise(
    lattice: &mut FaceLattice,
    grid: &SphereGrid,
    planet: &PlanetConfig,
    lake_depth: f64,
    seed: u64,
) -> ErosionReport {
    let sea_level = planet.sea_level_height as f64;
    let land = relief::land_of(lattice, grid, sea_level);
    let CoastDistances { to_sea, to_land } = CoastDistances::new(grid, &land);
    let uplift = uplift(grid, &land, &to_sea, planet.interior_rise as f64, seed);
    let erodibility = erodibility(grid, seed);
    let diffusivity = planet.network_diffusivity as f64;
    let (eroded, report) = evolve(grid, &land, &uplift, &erodibility, diffusivity, seed);
    let peak = quantile(
        (0..grid.len()).filter(|&k| land[k]).map(|k| eroded[k]),
        PEAK_QUANTILE,
    )
    .max(1e-12);
    let scale = (planet.max_mountain_height as f64 - sea_level) / peak;
    // The lowest land a hair above the sea, so the land mask is kept exactly.
    let floor = 1e-3 * (planet.max_mountain_height as f64 - sea_level);
    let mut heights: Vec<f64> = (0..grid.len())
        .map(|k| match land[k] {
            true => sea_level + (eroded[k] * scale).max(floor),
            false => relief::shelf(planet, to_land[k]),
        })
        .collect();
    lakes::dig(&mut heights, grid, &land, (sea_level, lake_depth), seed);
    grid.write(&heights, lattice);
    report
}

/// Tectonic uplift per land node (0 at sea): low over coastal plains and lowlands (rising inland by
/// `interior_rise` of itself per radian from the sea), higher on plateaus, highest along mountain belts.
fn uplift(
    grid: &SphereGrid,
    land: &[bool],
    to_sea: &[f64],
    interior_rise: f64,
    seed: u64,
) -> Vec<f64> {
    let belts_seed = rng::hash(seed, &[STREAM_BELTS]);
    let plateaus_seed = rng::hash(seed, &[STREAM_PLATEAUS]);
    let warp_seed = rng::hash(seed, &[STREAM_WARP]);
    (0..grid.len())
        .into_par_iter()
        .map(|k| {
            if !land[k] {
                return 0.0;
            }
            let d: DVec3 = grid.directions[k];
            let warp = DVec3::new(
                noise::fbm(warp_seed, d, 2.0, 3),
                noise::fbm(warp_seed ^ 1, d, 2.0, 3),
                noise::fbm(warp_seed ^ 2, d, 2.0, 3),
            );
            let warped = (d + 0.25 * warp).normalize();
            let ridge = noise::ridged(belts_seed, warped, BELT_FREQUENCY, 3);
            let belt = ((ridge - BELT_FLOOR) / (1.0 - BELT_FLOOR)).clamp(0.0, 1.0);
            let plateau = smoothstep(
                0.15,
                0.45,
                noise::fbm(plateaus_seed, warped, PLATEAU_FREQUENCY, 3),
            );
            let inland = 1.0 - (-to_sea[k] / COASTAL_PLAIN).exp();
            let lowland = LOWLAND_UPLIFT * (1.0 + interior_rise * to_sea[k]);
            inland * (lowland + PLATEAU_UPLIFT * plateau + BELT_UPLIFT * belt * belt)
        })
        .collect()
}

/// Erodibility K per node: rock that varies smoothly in strength.
fn erodibility(grid: &SphereGrid, seed: u64) -> Vec<f64> {
    let rock_seed = rng::hash(seed, &[STREAM_ROCK]);
    grid.directions
        .par_iter()
        .map(|&d| (ROCK_CONTRAST * noise::fbm(rock_seed, d, 6.0, 3)).exp())
        .collect()
}

/// Runs the stream-power law from a slightly rough plain to near its steady state, with hillslope diffusion of
/// `diffusivity` (unit-sphere area per model time) over the first [`NETWORK_FORMING_TIME`]. Sea nodes are the
/// base level (height 0); heights are in model units.
fn evolve(
    grid: &SphereGrid,
    land: &[bool],
    uplift: &[f64],
    erodibility: &[f64],
    diffusivity: f64,
    seed: u64,
) -> (Vec<f64>, ErosionReport) {
    let start_seed = rng::hash(seed, &[STREAM_START]);
    // A little white roughness: where the first channels start, so networks branch instead of running parallel.
    let mut h: Vec<f64> = (0..grid.len())
        .map(|k| match land[k] {
            true => {
                INITIAL_ROUGHNESS
                    * (1.0
                        + (rng::hash(start_seed, &[k as u64]) >> 11) as f64 / (1u64 << 53) as f64)
            }
            false => 0.0,
        })
        .collect();
    let mut dt = FIRST_STEP;
    let mut time = 0.0;
    let mut report = ErosionReport::default();
    let mut diffusion = (diffusivity > 0.0).then(|| Diffusion::new(grid, land, diffusivity));
    for step in 0..STEPS {
        let tree = ReceiverTree::new(grid, land, &h);
        // Each node's erosion factor K dt A^m / L does not depend on the heights: taken side by side first.
        let factor: Vec<f64> = (0..grid.len())
            .into_par_iter()
            .map(|k| match land[k] && tree.receiver[k] != k as u32 {
                true => erodibility[k] * dt * tree.area[k].powf(AREA_EXPONENT) / tree.length[k],
                false => 0.0,
            })
            .collect();
        let mut change: f64 = 0.0;
        // Downstream first, so each node's receiver already has its new height (implicit in the slope).
        for &k in &tree.downstream_first {
            let k = k as usize;
            let r = tree.receiver[k];
            if r == k as u32 {
                // A pit: it rises with the land until it spills.
                h[k] += dt * uplift[k];
                continue;
            }
            let f = factor[k];
            let new = (h[k] + dt * uplift[k] + f * h[r as usize]) / (1.0 + f);
            change = change.max((new - h[k]).abs());
            h[k] = new;
        }
        if let Some(diffusion) = diffusion.as_mut().filter(|_| time < NETWORK_FORMING_TIME) {
            diffusion.run(&mut h, dt);
        }
        time += dt;
        let highest = h.iter().copied().fold(0.0, f64::max).max(1e-12);
        report = ErosionReport {
            steps: step + 1,
            last_change: change / highest,
        };
        dt = (dt * STEP_GROWTH).min(LONGEST_STEP);
    }
    (h, report)
}

/// Linear hillslope diffusion `D lap h` on land (the sea stays the base level), in explicit substeps small
/// enough to be stable. The Laplacian weighs each neighbour by one over its squared angle.
struct Diffusion<'a> {
    grid: &'a SphereGrid,
    land: &'a [bool],
    diffusivity: f64,
    /// The largest sum of a node's neighbour weights, which bounds the stable substep.
    stiffest: f64,
    /// The heights being written while the substep reads the others.
    next: Vec<f64>,
}

impl<'a> Diffusion<'a> {
    fn new(grid: &'a SphereGrid, land: &'a [bool], diffusivity: f64) -> Self {
        let stiffest = (0..grid.len() as u32)
            .into_par_iter()
            .map(|k| {
                grid.steps(k)
                    .map(|(_, angle)| 1.0 / (angle * angle))
                    .sum::<f64>()
            })
            .reduce(|| 0.0, f64::max);
        Self {
            grid,
            land,
            diffusivity,
            stiffest,
            next: vec![0.0; grid.len()],
        }
    }

    /// Diffuses `h` over `dt`.
    fn run(&mut self, h: &mut Vec<f64>, dt: f64) {
        let d = self.diffusivity;
        let substeps = (dt * d * self.stiffest / DIFFUSION_STABILITY)
            .ceil()
            .max(1.0);
        let step = dt / substeps;
        let (grid, land) = (self.grid, self.land);
        for _ in 0..substeps as usize {
            let here = &*h;
            self.next.par_iter_mut().enumerate().for_each(|(k, next)| {
                let at = here[k];
                *next = match land[k] {
                    true => {
                        let laplacian: f64 = grid
                            .steps(k as u32)
                            .map(|(n, angle)| (here[n as usize] - at) / (angle * angle))
                            .sum();
                        at + step * d * laplacian
                    }
                    false => at,
                };
            });
            std::mem::swap(h, &mut self.next);
        }
    }
}

/// Where the water of each land node goes in one step of the evolution (Braun and Willett 2013): its steepest
/// lower neighbour (a sea node, or itself in a pit), the land nodes ordered downstream first, and drainage areas.
/// O(n), no depression filling: pits rise with the uplift until they spill.
struct ReceiverTree {
    receiver: Vec<u32>,
    /// Angle to the receiver.
    length: Vec<f64>,
    downstream_first: Vec<u32>,
    area: Vec<f64>,
}

impl ReceiverTree {
    fn new(grid: &SphereGrid, land: &[bool], h: &[f64]) -> Self {
        let (receiver, length): (Vec<u32>, Vec<f64>) = (0..grid.len() as u32)
            .into_par_iter()
            .map(|k| {
                let mut best = (0.0, k, 0.0);
                if land[k as usize] {
                    for (next, angle) in grid.steps(k) {
                        let slope = (h[k as usize] - h[next as usize]) / angle;
                        if slope > best.0 {
                            best = (slope, next, angle);
                        }
                    }
                }
                (best.1, best.2)
            })
            .unzip();
        // Donors of every node, then the land nodes breadth-first from the sea and the pits up.
        let mut count = vec![0u32; grid.len() + 1];
        for (k, &r) in receiver.iter().enumerate() {
            if r != k as u32 {
                count[r as usize + 1] += 1;
            }
        }
        for k in 0..grid.len() {
            count[k + 1] += count[k];
        }
        let mut donors = vec![0u32; count[grid.len()] as usize];
        let mut fill = count.clone();
        for (k, &r) in receiver.iter().enumerate() {
            if r != k as u32 {
                donors[fill[r as usize] as usize] = k as u32;
                fill[r as usize] += 1;
            }
        }
        let mut order: Vec<u32> = (0..grid.len() as u32)
            .filter(|&k| receiver[k as usize] == k)
            .collect();
        let mut at = 0;
        while at < order.len() {
            let k = order[at] as usize;
            order.extend_from_slice(&donors[count[k] as usize..count[k + 1] as usize]);
            at += 1;
        }
        let mut area = grid.areas.clone();
        for &k in order.iter().rev() {
            let r = receiver[k as usize];
            if r != k {
                area[r as usize] += area[k as usize];
            }
        }
        let downstream_first = order.into_iter().filter(|&k| land[k as usize]).collect();
        Self {
            receiver,
            length,
            downstream_first,
            area,
        }
    }
}

fn smoothstep(lo: f64, hi: f64, x: f64) -> f64 {
    let t = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The `q` quantile of `values` (0 when empty).
fn quantile(values: impl Iterator<Item = f64>, q: f64) -> f64 {
    let mut v: Vec<f64> = values.collect();
    if v.is_empty() {
        return 0.0;
    }
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    *v.select_nth_unstable_by(i, f64::total_cmp).1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Diffusion over a step far beyond the explicit limit stays bounded by the heights it starts from (the
    /// maximum principle, which an unstable step breaks at once), smooths them, and leaves the sea at its level.
    #[test]
    fn diffusion_is_stable_smoothing_and_keeps_the_sea() {
        let grid = SphereGrid::new(&FaceLattice::new(16, 0.0));
        let land: Vec<bool> = grid.directions.iter().map(|d| d.z > -0.3).collect();
        let h: Vec<f64> = (0..grid.len())
            .map(|k| match land[k] {
                true => (rng::hash(7, &[k as u64]) >> 11) as f64 / (1u64 << 53) as f64,
                false => 0.0,
            })
            .collect();
        let roughness = |h: &[f64]| -> f64 {
            (0..grid.len() as u32)
                .filter(|&k| land[k as usize])
                .flat_map(|k| grid.steps(k).map(move |(n, _)| (k, n)))
                .map(|(k, n)| (h[k as usize] - h[n as usize]).abs())
                .sum()
        };
        let mut after = h.clone();
        Diffusion::new(&grid, &land, 1e-3).run(&mut after, 50.0);
        assert!(after.iter().all(|&x| (0.0..=1.0).contains(&x)));
        assert!((0..grid.len()).all(|k| land[k] || after[k] == 0.0));
        assert!(roughness(&after) < 0.2 * roughness(&h));
    }
}
