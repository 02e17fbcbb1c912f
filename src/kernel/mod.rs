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
    /// How far a sample reaches (Procedure 3).
    pub influence_distance: f32,
    /// The depth of the river basins (Procedure 5).
    pub basin_depth: f32,
    /// The sea's height: water never stands below it.
    pub sea_level: f32,
    /// How far the water surface lies below the basin's top (Procedure 5).
    pub basin_water_offset: f32,
    /// Beyond the thesis: the least distance between samples along a river, in vertex spacings (1 /
    /// `samples-per-vertex-spacing`; 0: no such floor): a vertex beside a river lies within half of it along the
    /// flow from the river's nearest sample, which tells a river's end apart ([`cpu::beyond_end`]).
    pub sample_floor: f32,
}

impl KernelParams {
    /// The constants of `config`.
    pub fn from_config(config: &crate::config::Config) -> Self {
        Self {
            influence_distance: config.river.influence_distance,
            basin_depth: config.river.basin_depth,
            sea_level: config.planet.sea_level_height,
            basin_water_offset: config.river.basin_water_offset,
            sample_floor: match config.river.samples_per_vertex_spacing {
                0 => 0.0,
                k => 1.0 / k as f32,
            },
        }
    }
}

/// The five per-vertex outputs of Procedure 5, and the flow. `river_width` is the weighted *half* width, as the procedure
/// accumulates it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RiverTexel {
    /// The river terrain's height (the carved bed and banks).
    pub terrain_height: f32,
    /// How much of the base terrain shows: 0 in a river, 1 beyond every river's influence (Section 8.2).
    pub lerp_factor: f32,
    /// The water surface's height.
    pub water_height: f32,
    /// The signed distance to the nearest river sample (Procedure 3).
    pub min_distance: f32,
    /// The weighted half width.
    pub river_width: f32,
    /// Beyond the thesis: the water's flow, the mean of the unit directions (downstream, in the patch frame) of
    /// the samples whose river covers the vertex, weighted as in the river depth (`w_river`); shorter than 1
    /// where they disagree, zero outside every river.
    pub flow: [f32; 2],
    /// Beyond the thesis (docs/rendering.md, "Painted confluences"): the signed distance to the nearest sample of
    /// another river than the nearest sample's ([`RiverSample::river`]); the influence distance where none reaches.
    pub second_distance: f32,
    /// That sample's half width (0 where none reaches).
    pub second_width: f32,
    /// The nearest sample's own half width (0 where none reaches): with `min_distance`, the nearest river's
    /// band measured as the second river's is.
    pub nearest_sample_width: f32,
    /// 1 where the nearest river's number is below the second river's, -1 where above, 0 without a second: the
    /// shaders put the two in the rivers' order, so that a triangle's vertices agree on which is which.
    pub river_order: f32,
}

/// The work for one patch: the grid spacing and the samples that influence it.
#[derive(Clone, Copy, Debug)]
pub struct PatchJob<'a> {
    /// World units between neighbouring vertices.
    pub spacing: f32,
    /// The samples whose influence reaches the patch.
    pub samples: &'a [RiverSample],
}

/// Where a child patch's river data can come from its parent (10.2, the thesis's future work): with an odd number
/// of vertices per side, the child's even vertices (2i, 2j) are the parent's vertices `offset + (i, j)` of the
/// quadrant the child covers. When the parent's samples are the rivers' final detail
/// ([`crate::river::samples::PatchSamples::final_detail`]), the river data there is the same, so only the other
/// three quarters of the vertices need the kernel (docs/kernel.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParentQuadrant {
    /// The parent's vertex under the child's vertex (0, 0).
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

/// The names of a texel's outputs, in [`RiverTexel::outputs`] order.
pub const OUTPUT_NAMES: [&str; 11] = [
    "terrain_height",
    "lerp_factor",
    "water_height",
    "min_distance",
    "river_width",
    "flow_x",
    "flow_y",
    "second_distance",
    "second_width",
    "nearest_sample_width",
    "river_order",
];

impl RiverTexel {
    /// The outputs as one array, in [`OUTPUT_NAMES`] order.
    pub fn outputs(&self) -> [f32; 11] {
        [
            self.terrain_height,
            self.lerp_factor,
            self.water_height,
            self.min_distance,
            self.river_width,
            self.flow[0],
            self.flow[1],
            self.second_distance,
            self.second_width,
            self.nearest_sample_width,
            self.river_order,
        ]
    }
}

/// The largest difference of one output between two sets of patches, and where it is: which output, patch and
/// vertex, and both values (so a mismatch on one device can be traced to its case).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct OutputDiff {
    /// Which output ([`RiverTexel`]'s field name).
    pub output: &'static str,
    /// The largest absolute difference.
    pub max_abs_diff: f32,
    /// The patch where it is.
    pub patch: usize,
    /// The vertex where it is.
    pub vertex: [u32; 2],
    /// The reference's value there.
    pub expected: f32,
    /// The compared value there.
    pub actual: f32,
}

/// The largest difference per output between `expected` (the CPU reference) and `actual`, patches of `n x n`
/// texels in row-major order.
pub fn diff_by_output(
    expected: &[Vec<RiverTexel>],
    actual: &[Vec<RiverTexel>],
    n: u32,
) -> Vec<OutputDiff> {
    let mut worst: Vec<OutputDiff> = OUTPUT_NAMES
        .iter()
        .map(|&output| OutputDiff {
            output,
            max_abs_diff: 0.0,
            patch: 0,
            vertex: [0, 0],
            expected: 0.0,
            actual: 0.0,
        })
        .collect();
    for (patch, (a, b)) in expected.iter().zip(actual).enumerate() {
        for (k, (x, y)) in a.iter().zip(b).enumerate() {
            for (w, (e, g)) in worst
                .iter_mut()
                .zip(x.outputs().into_iter().zip(y.outputs()))
            {
                let d = (e - g).abs();
                // NaN on either side counts as the largest difference.
                if d > w.max_abs_diff || (d.is_nan() && !w.max_abs_diff.is_nan()) {
                    *w = OutputDiff {
                        max_abs_diff: d,
                        patch,
                        vertex: [k as u32 % n, k as u32 / n],
                        expected: e,
                        actual: g,
                        ..*w
                    };
                }
            }
        }
    }
    worst
}

/// The largest difference in any output (the five and the flow) between two sets of patches (GPU vs CPU reference).
pub fn max_abs_diff(a: &[Vec<RiverTexel>], b: &[Vec<RiverTexel>]) -> f32 {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| {
            x.outputs()
                .into_iter()
                .zip(y.outputs())
                .map(|(e, g)| (e - g).abs())
                .fold(0.0f32, f32::max)
        })
        .fold(0.0, f32::max)
}
