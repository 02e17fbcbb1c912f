//! The surface as the renderer draws it, computed on the CPU (beyond the thesis: for exports and for keeping the
//! viewer's camera above ground): per patch, the river kernel's texels from the patch's samples (Sections 6.3-6.6,
//! the CPU reference, which the GPU kernels equal bit for bit) blended into the base heights by the lerp factor
//! as the vertex shaders blend them (Section 8.2), the water above it, and how far inside a river's basin each
//! vertex lies.

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use crate::{
    config::Config,
    kernel::{cpu::compute_patch, KernelParams, PatchJob},
    planet::{
        cube::{face_of_on, PatchId},
        Planet,
    },
    river::{
        network::RiverNetwork,
        samples::{patch_samples, PatchFrame},
    },
};

/// One patch's surface as the renderer draws it, per vertex row by row: the terrain height (river beds carved in),
/// the water height (the river's water, at least sea level), as `surfaceAt` in glsl/terrain_vertex.glsl, and how
/// far inside a river's basin the vertex lies (half width - |signed distance|; positive inside, as the geometry
/// shader's test).
pub struct CarvedPatch {
    /// The patch.
    pub patch: PatchId,
    /// Per vertex (row-major), the drawn terrain's height.
    pub terrain: Vec<f32>,
    /// Per vertex, the water's height.
    pub water: Vec<f32>,
    /// Per vertex, how far inside a river's basin it lies.
    pub basin: Vec<f32>,
}

/// `patch`'s surface from its base height at vertex (i, j), `base`, and the river kernel where rivers reach it.
pub fn carve_patch(
    patch: PatchId,
    base: impl Fn(u32, u32) -> f32,
    planet: &Planet,
    network: &RiverNetwork,
    n: u32,
    params: &KernelParams,
) -> CarvedPatch {
    let frame = PatchFrame::new(patch, planet.radius, n);
    let samples = patch_samples(network, &frame).samples;
    let base_at = |k: u32| base(k % n, k / n);
    if samples.is_empty() {
        return CarvedPatch {
            patch,
            terrain: (0..n * n).map(base_at).collect(),
            water: vec![planet.sea_level; (n * n) as usize],
            basin: vec![-params.influence_distance; (n * n) as usize],
        };
    }
    let job = PatchJob {
        spacing: frame.spacing() as f32,
        samples: &samples,
    };
    let texels = compute_patch(&job, n, params);
    CarvedPatch {
        patch,
        terrain: texels
            .iter()
            .zip(0..)
            .map(|(t, k)| mix(t.terrain_height, base_at(k), t.lerp_factor))
            .collect(),
        water: texels
            .iter()
            .map(|t| t.water_height.max(planet.sea_level))
            .collect(),
        basin: texels
            .iter()
            .map(|t| t.river_width - t.min_distance.abs())
            .collect(),
    }
}

/// The surfaces of `patches` (all of one level), in parallel, each patch's base heights refined on the CPU as the
/// renderer refines them on the GPU ([`Planet::patch_heights`]); `carved` is called as each one is done (from any
/// thread: progress).
pub fn carve_patches(
    patches: &[PatchId],
    planet: &Planet,
    network: &RiverNetwork,
    config: &Config,
    carved: &(dyn Fn() + Sync),
) -> HashMap<PatchId, CarvedPatch> {
    let n = config.rendering.vertices;
    let params = KernelParams::from_config(config);
    patches
        .par_iter()
        .map(|&patch| {
            let heights = planet.patch_heights(patch);
            let base = |i: u32, j: u32| heights.get(i as i64, j as i64);
            let surface = carve_patch(patch, base, planet, network, n, &params);
            carved();
            (patch, surface)
        })
        .collect()
}

/// GLSL's `mix`, as the vertex shaders blend.
fn mix(a: f32, b: f32, t: f32) -> f32 {
    a * (1.0 - t) + b * t
}

impl CarvedPatch {
    /// `values` (one per vertex of this patch, `n` a side) at direction `d` within the patch, bilinear.
    pub fn at(&self, values: &[f32], d: DVec3, n: u32) -> f32 {
        let patch = self.patch;
        let (_, u, v) = face_of_on(patch.face as usize, d);
        let (u0, v0) = patch.origin();
        let cells = (n - 1) as f64;
        let grid = (
            (u - u0) / patch.size() * cells,
            (v - v0) / patch.size() * cells,
        );
        bilinear(n - 1, grid, |i, j| values[(j * n + i) as usize])
    }

    /// The height at which the terrain pass places vertex `index` with the water in the mesh (`placedHeight` in
    /// glsl/terrain_vertex.glsl, for the `auto` and `geometry` water modes): the water's surface under the sea or
    /// inside a river's basin, else the terrain.
    pub fn placed(&self, index: usize, sea_level: f32) -> f32 {
        let height = self.terrain[index].max(sea_level);
        if self.basin[index] > 0.0 {
            height.max(self.water[index])
        } else {
            height
        }
    }

    /// The height of what is drawn at direction `d`: the water where the vertices around it are in a river's
    /// basin or the terrain is below sea level, else the terrain.
    pub fn surface(&self, d: DVec3, n: u32, sea_level: f32) -> f32 {
        let terrain = self.at(&self.terrain, d, n);
        let wet = self.at(&self.basin, d, n) > 0.0 || terrain < sea_level;
        if wet {
            terrain.max(self.at(&self.water, d, n))
        } else {
            terrain
        }
    }
}

/// Bilinear interpolation on a grid of `cells` x `cells` cells whose point (i, j) holds `value(i, j)`, at grid
/// coordinates `(x, y)` (clamped to the grid).
pub fn bilinear(cells: u32, (x, y): (f64, f64), value: impl Fn(u32, u32) -> f32) -> f32 {
    let limit = cells as f64;
    let (x, y) = (x.clamp(0.0, limit), y.clamp(0.0, limit));
    let (i, j) = ((x as u32).min(cells - 1), (y as u32).min(cells - 1));
    let (fx, fy) = ((x - i as f64) as f32, (y - j as f64) as f32);
    let bottom = value(i, j) + (value(i + 1, j) - value(i, j)) * fx;
    let top = value(i, j + 1) + (value(i + 1, j + 1) - value(i, j + 1)) * fx;
    bottom + (top - bottom) * fy
}
