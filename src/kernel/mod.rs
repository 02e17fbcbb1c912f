//! The river-height kernel of Sections 6.5-6.6 (Procedures 3-5) and Chapter 7: for every vertex of a patch, a
//! weighted sum over the river samples that influence the patch.
//!
//! [`cpu`] is the reference (single-threaded, as the thesis's baseline, and a rayon version); [`gpu`] dispatches
//! the same kernel body (`glsl/river_kernel.glsl`) as the simple (7.3.1) or the tiled (7.3.2) compute shader.
//!
//! Coordinates: a patch's vertex (i, j) sits at `(i, j) * spacing` in the patch's own 2D frame, and its samples are
//! given in that frame too (relative to the patch corner), which keeps f32 precise at any depth of the quadtree.

pub mod cpu;
pub mod gpu;
pub mod workload;

pub use crate::shader_types::RiverSample;

/// The constants of Procedures 3-5, from the configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KernelParams {
    pub influence_distance: f32,
    pub basin_depth: f32,
    pub sea_level: f32,
    pub basin_water_offset: f32,
}

impl KernelParams {
    pub fn from_config(config: &crate::config::Config) -> Self {
        Self {
            influence_distance: config.river.influence_distance,
            basin_depth: config.river.basin_depth,
            sea_level: config.planet.sea_level_height,
            basin_water_offset: config.river.basin_water_offset,
        }
    }
}

/// The five per-vertex outputs of Procedure 5, and the flow. `river_width` is the weighted *half* width, as the procedure
/// accumulates it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RiverTexel {
    pub terrain_height: f32,
    pub lerp_factor: f32,
    pub water_height: f32,
    pub min_distance: f32,
    pub river_width: f32,
    /// Beyond the thesis: the water's flow, the mean of the unit directions (downstream, in the patch frame) of
    /// the samples whose river covers the vertex, weighted as in the river depth (`w_river`); shorter than 1
    /// where they disagree, zero outside every river.
    pub flow: [f32; 2],
}

/// The work for one patch: the grid spacing and the samples that influence it.
#[derive(Clone, Copy, Debug)]
pub struct PatchJob<'a> {
    pub spacing: f32,
    pub samples: &'a [RiverSample],
}

/// Where a child patch's river data can come from its parent (10.2, the thesis's future work): with an odd number
/// of vertices per side, the child's even vertices (2i, 2j) are the parent's vertices `offset + (i, j)` of the
/// quadrant the child covers. When the parent's samples are the rivers' final detail
/// ([`crate::river::samples::PatchSamples::final_detail`]), the river data there is the same, so only the other
/// three quarters of the vertices need the kernel (docs/kernel.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParentQuadrant {
    pub offset: [u32; 2],
}

impl ParentQuadrant {
    /// The quadrant of `patch`'s parent that `patch` covers; `None` for a root or an even vertex count.
    pub fn of(patch: crate::planet::cube::PatchId, n: u32) -> Option<Self> {
        (patch.level > 0 && n % 2 == 1).then(|| {
            let half = (n - 1) / 2;
            Self {
                offset: [(patch.x % 2) * half, (patch.y % 2) * half],
            }
        })
    }

    /// The parent vertex that child vertex (i, j) coincides with, if both are even.
    pub fn parent_vertex(self, i: u32, j: u32) -> Option<(u32, u32)> {
        (i % 2 == 0 && j % 2 == 0).then(|| (self.offset[0] + i / 2, self.offset[1] + j / 2))
    }
}

/// Vertex (i, j) of a patch, in the patch frame.
pub fn vertex_position(i: u32, j: u32, spacing: f32) -> [f32; 2] {
    [i as f32 * spacing, j as f32 * spacing]
}

impl<'a> PatchJob<'a> {
    /// Jobs for (vertex spacing, samples) pairs, as workloads and renderer batches hold them.
    pub fn from_pairs(pairs: &'a [(f32, Vec<RiverSample>)]) -> Vec<PatchJob<'a>> {
        pairs
            .iter()
            .map(|(spacing, samples)| PatchJob {
                spacing: *spacing,
                samples,
            })
            .collect()
    }
}

/// The largest difference in any output (the five and the flow) between two sets of patches (GPU vs CPU reference).
pub fn max_abs_diff(a: &[Vec<RiverTexel>], b: &[Vec<RiverTexel>]) -> f32 {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| {
            [
                (x.terrain_height - y.terrain_height).abs(),
                (x.lerp_factor - y.lerp_factor).abs(),
                (x.water_height - y.water_height).abs(),
                (x.min_distance - y.min_distance).abs(),
                (x.river_width - y.river_width).abs(),
                (x.flow[0] - y.flow[0]).abs(),
                (x.flow[1] - y.flow[1]).abs(),
            ]
            .into_iter()
            .fold(0.0f32, f32::max)
        })
        .fold(0.0, f32::max)
}
