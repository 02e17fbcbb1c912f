//! The CPU reference of Procedures 3-5 (Section 6.5-6.6), line by line, plus a rayon version over patches and rows.
//!
//! Where the printed procedures leave a value undefined, the choices (docs/kernel.md) are:
//! - no relevant sample (`weightSum` = 0): the vertex keeps the base terrain: lerp factor 1, terrain height 0,
//!   water at sea level, minimum distance = influence distance, river width 0;
//! - the in-basin test is strict on the projection distance (a vertex exactly on the basin's end has river weight
//!   0 and would make `inRiverSum / inRiverWSum` 0/0), so `inRiverWSum` > 0 whenever `inRiver`;
//! - `influenceDistance - riverWidth` <= 0 (a river wider than its influence): lerp factor 0;
//! - the lerp factor is clamped to [0, 1] (a vertex beyond the river's ends but closer than its width would
//!   otherwise get a negative factor).

use rayon::prelude::*;

use super::{vertex_position, KernelParams, ParentQuadrant, PatchJob, RiverSample, RiverTexel};

/// What Procedure 3 returns for a relevant sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleContribution {
    /// The sample's bed height (Procedure 3's `height`).
    pub height: f32,
    /// The distance weight `w_dist`: 1 at the sample, 0 at its influence distance.
    pub w_dist: f32,
    /// The basin depth at the vertex from this sample.
    pub basin_depth: f32,
    /// The sample's half width.
    pub river_width: f32,
    /// Whether the vertex lies within the sample's river.
    pub in_river: bool,
    /// The river's depth at the vertex (`inRiverDepth`).
    pub in_river_depth: f32,
    /// The weight of that depth (`w_river`).
    pub w_river: f32,
    /// Distance to the sample, negated when the vertex lies left of the sample's direction.
    pub dist: f32,
    /// The squared distance: the nearest sample is chosen on it, exactly alike on every device.
    pub dist2: f32,
    /// Beyond the thesis: the squared distance along the flow times `scale2` (`(r.d)^2`; `dist2` for a zero
    /// derivative), and `scale2` (`|d|^2`; 1 for a zero derivative): whether the vertex lies beyond a river's end
    /// is decided on them ([`beyond_end`]).
    pub along2: f32,
    /// See `along2`.
    pub scale2: f32,
    /// The sample's influence distance (beyond the thesis: [`RiverSample::reach`]).
    pub reach: f32,
    /// Beyond the thesis: the sample's unit direction (downstream) times `w_river`, for the water's flow.
    pub flow: [f32; 2],
}

/// Procedure 3, Section 6.5: one vertex against one sample; `None` when the sample is not relevant (or a lake's).
///
/// The quantities are the procedure's, rearranged so that every conforming device takes the same decisions
/// (docs/kernel.md, "Decisions every device takes alike"): whether the sample is relevant, whether its basin holds
/// the vertex and which side of its line the vertex lies on are decided on squared distances, dot and cross
/// products, made of additions and multiplications that Vulkan rounds correctly (the kernel body marks them
/// `precise`, so no driver fuses them), and the weights are written so that they are positive whenever the
/// decision says so. With r = v - p and d the derivative: projection distance |r.d| / |d|, normal distance
/// |d x r| / |d|, side d x r.
pub fn calculate_height_by_sample(
    v: [f32; 2],
    sample: &RiverSample,
    params: &KernelParams,
) -> Option<SampleContribution> {
    if sample.width < 0.0 {
        return None;
    }
    let p = sample.position;
    let d = sample.derivative;
    let r = [v[0] - p[0], v[1] - p[1]];
    let dist2 = r[0] * r[0] + r[1] * r[1];
    let reach = if sample.reach > 0.0 {
        sample.reach
    } else {
        params.influence_distance
    };
    // Strict: a sample at exactly the influence distance has weight 0 and changes nothing but the sentinels.
    if dist2 >= reach * reach {
        return None;
    }
    let dist = dist2.sqrt();
    // 1 - dist / reach, as (reach^2 - dist^2) / (reach (reach + dist)): positive for every relevant sample.
    let w_dist = (reach * reach - dist2) / (reach * (reach + dist));
    let half_width = sample.width * 0.5;
    let dd = d[0] * d[0] + d[1] * d[1];
    let zero = d == [0.0, 0.0];
    // Distance along the flow, unnormalised (|r.d|; the distance to p for a zero derivative, whose normal line
    // degenerates to p), its square and the square of its limit, the half width (times |d|).
    let dot = r[0] * d[0] + r[1] * d[1];
    let (along, along2) = if zero {
        (dist, dist2)
    } else {
        (dot.abs(), dot * dot)
    };
    let limit2 = if zero {
        half_width * half_width
    } else {
        half_width * half_width * dd
    };
    // Side of the line p -> p + p' (2D cross product); left of the flow direction is negative.
    let side = d[0] * r[1] - d[1] * r[0];
    let mut c = SampleContribution {
        height: w_dist * sample.height,
        w_dist,
        basin_depth: w_dist * params.basin_depth,
        river_width: w_dist * half_width,
        in_river: false,
        in_river_depth: 0.0,
        w_river: 0.0,
        dist: if side > 0.0 { -dist } else { dist },
        dist2,
        along2,
        scale2: if zero { 1.0 } else { dd },
        reach,
        flow: [0.0; 2],
    };
    // projection distance < half width and normal distance <= half width.
    if along2 < limit2 && side * side <= limit2 {
        // 1 / (half width x |d|): the fractions of the half width along and across the flow.
        let inverse_scale = 1.0 / (half_width * if zero { 1.0 } else { dd.sqrt() });
        let normal_factor = side.abs() * inverse_scale;
        let factor = normal_factor * normal_factor * normal_factor;
        c.in_river = true;
        // 1 - along / limit, as (limit^2 - along^2) / (limit (limit + along)): positive in the basin.
        c.w_river =
            (limit2 - along2) * (inverse_scale * inverse_scale) / (1.0 + along * inverse_scale);
        c.in_river_depth = c.w_river * factor * c.basin_depth;
        // 1 / |p'| as (1 / (half width x |p'|)) x half width; a zero p' gives a zero flow.
        let unit = inverse_scale * half_width;
        c.flow = [c.w_river * (d[0] * unit), c.w_river * (d[1] * unit)];
    }
    Some(c)
}

/// The accumulators of Procedure 4.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Accumulators {
    /// Sum of `w_dist`-weighted bed heights.
    pub height_sum: f32,
    /// Sum of `w_dist`.
    pub weight_sum: f32,
    /// Sum of `w_dist`-weighted basin depths.
    pub basin_sum: f32,
    /// Sum of `w_dist`-weighted half widths.
    pub width_sum: f32,
    /// Whether any sample's river covers the vertex.
    pub in_river: bool,
    /// Sum of `w_river`-weighted river depths.
    pub in_river_sum: f32,
    /// Sum of `w_river`.
    pub in_river_w_sum: f32,
    /// The nearest sample: its signed distance (Procedure 4's `minDistance`), the square of it, its half width
    /// and, beyond the thesis, its river and how far along its flow the vertex lies.
    pub nearest: NearestSample,
    /// The influence distance of the nearest sample: the lerp factor reaches 1 there.
    pub nearest_reach: f32,
    /// Beyond the thesis: the nearest sample of another river than the nearest sample's.
    pub second: NearestSample,
    /// Beyond the thesis: the highest water level of the lake samples within half their width of the vertex
    /// (`-f32::MAX` where none is).
    pub lake_level: f32,
    /// Beyond the thesis: how far into that lake's reach the vertex lies from the lake's nearest sample, as the
    /// squared share of the reach (0 on the lake's line, towards 1 at the reach's edge).
    pub lake_offset2: f32,
    /// Beyond the thesis: sum of `w_river`-weighted downstream directions (the water's flow).
    pub flow_sum: [f32; 2],
}

/// The nearest sample of a river: its signed distance, the square of it, its half width, its river number and
/// how far along the flow the vertex lies from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NearestSample {
    /// The signed distance ([`SampleContribution::dist`]).
    pub distance: f32,
    /// Its square.
    pub distance2: f32,
    /// The sample's half width.
    pub half_width: f32,
    /// The sample's river number (-1: none yet).
    pub river: f32,
    /// [`SampleContribution::along2`] and [`SampleContribution::scale2`].
    pub along2: f32,
    /// See `along2`.
    pub scale2: f32,
}

impl NearestSample {
    const NONE: Self = Self {
        distance: f32::MAX,
        distance2: f32::MAX,
        half_width: 0.0,
        river: -1.0,
        along2: 0.0,
        scale2: 1.0,
    };

    fn of(c: &SampleContribution, sample: &RiverSample) -> Self {
        Self {
            distance: c.dist,
            distance2: c.dist2,
            half_width: sample.width * 0.5,
            river: sample.river,
            along2: c.along2,
            scale2: c.scale2,
        }
    }
}

/// Beyond the thesis (docs/rendering.md, "Rivers end where they end"): whether a vertex lies beyond the end of the
/// river whose `nearest` sample it measured: farther along the flow from it than the samples' floor (`sample_floor`
/// vertex spacings) and its half width. Beside a river its nearest sample lies within half a sample step along the
/// flow (half the floor, or a twelfth of the width), so only an end's sample is that far; its signed distance
/// changes sign along the line the river points, which interpolated between vertices would paint the river on
/// beyond its end. Decided on products, alike on every device.
pub fn beyond_end(nearest: &NearestSample, spacing: f32, sample_floor: f32) -> bool {
    let limit = (sample_floor * spacing).max(nearest.half_width);
    nearest.along2 > limit * limit * nearest.scale2
}

/// Procedure 4, Section 6.5: accumulate the weighted contributions of every relevant sample.
pub fn accumulate_height(
    v: [f32; 2],
    samples: &[RiverSample],
    params: &KernelParams,
) -> Accumulators {
    let mut acc = Accumulators {
        height_sum: 0.0,
        weight_sum: 0.0,
        basin_sum: 0.0,
        width_sum: 0.0,
        in_river: false,
        in_river_sum: 0.0,
        in_river_w_sum: 0.0,
        nearest: NearestSample::NONE,
        nearest_reach: params.influence_distance,
        second: NearestSample::NONE,
        lake_level: -f32::MAX,
        lake_offset2: 1.0,
        flow_sum: [0.0; 2],
    };
    for sample in samples {
        if sample.width < 0.0 {
            // A lake's sample: its level reaches the vertices within half its width (decided on the exact
            // squares, as Procedure 3's decisions).
            let r = [v[0] - sample.position[0], v[1] - sample.position[1]];
            let half_width = sample.width * 0.5;
            let (dist2, reach2) = (r[0] * r[0] + r[1] * r[1], half_width * half_width);
            if dist2 < reach2 {
                let offset2 = dist2 / reach2;
                if sample.height > acc.lake_level {
                    (acc.lake_level, acc.lake_offset2) = (sample.height, offset2);
                } else if sample.height == acc.lake_level {
                    acc.lake_offset2 = acc.lake_offset2.min(offset2);
                }
            }
            continue;
        }
        let Some(c) = calculate_height_by_sample(v, sample, params) else {
            continue;
        };
        acc.height_sum += c.height;
        acc.weight_sum += c.w_dist;
        acc.basin_sum += c.basin_depth;
        acc.width_sum += c.river_width;
        if c.in_river {
            acc.in_river = true;
            acc.in_river_sum += c.in_river_depth;
            acc.in_river_w_sum += c.w_river;
            acc.flow_sum[0] += c.flow[0];
            acc.flow_sum[1] += c.flow[1];
        }
        // Beyond the thesis: the nearest sample, and the nearest of another river (whose sample, nearer than
        // the second, becomes the second when another river's sample comes nearer still).
        if c.dist2 < acc.nearest.distance2 {
            if sample.river != acc.nearest.river {
                acc.second = acc.nearest;
            }
            acc.nearest_reach = c.reach;
            acc.nearest = NearestSample::of(&c, sample);
        } else if sample.river != acc.nearest.river && c.dist2 < acc.second.distance2 {
            acc.second = NearestSample::of(&c, sample);
        }
    }
    acc
}

/// Procedure 5, Section 6.6: the final terrain height, lerp factor, water height, signed minimum distance and
/// river (half) width of one vertex; beyond the thesis, the second river, for a patch of vertices `spacing` apart.
pub fn calculate_height(
    v: [f32; 2],
    samples: &[RiverSample],
    spacing: f32,
    params: &KernelParams,
) -> RiverTexel {
    let acc = accumulate_height(v, samples, params);
    let texel = with_second_river(river_outputs(&acc, params), &acc, spacing, params);
    with_lake(texel, &acc)
}

/// Beyond the thesis (docs/kernel.md, "Lakes"): a vertex a lake reaches, outside every river's basin, gets the
/// lake's level as its water (outside a basin Procedure 5's water lies just below the terrain, hidden), a signed
/// distance of 0 and a half width of [`LAKE_HALF_WIDTH`], which the shaders
/// read as "in a basin whose water the mesh shows": the water is drawn where the terrain lies below the level, so
/// the shore is the terrain's contour. The lerp factor stays as the rivers make it, so the terrain is the
/// planet's own; but the rivers' terrain there (an inflow's valley floor, which the lerp factor blends in beside it)
/// comes down to the level as an inflow's water does, so the drawn ground does not stand above the lake's water at
/// its points (tests/river_surface.rs) and the valley beyond is as it was.
/// A river's basin keeps its river's water (an outlet's falls below the level), except that an inflow's water
/// standing above the level comes down to it across the lake's reach, its bed with it: by the excess times 1 -
/// `lake_offset2`, so it meets the level on the lake's line and is unchanged at the reach's edge.
fn with_lake(mut texel: RiverTexel, acc: &Accumulators) -> RiverTexel {
    if acc.lake_level == -f32::MAX {
        return texel;
    }
    if acc.in_river {
        let excess = texel.water_height - acc.lake_level;
        if excess > 0.0 {
            let drop = excess * (1.0 - acc.lake_offset2);
            texel.water_height -= drop;
            texel.terrain_height -= drop;
        }
    } else {
        let excess = texel.terrain_height - acc.lake_level;
        if excess > 0.0 {
            texel.terrain_height -= excess * (1.0 - acc.lake_offset2);
        }
        texel.water_height = acc.lake_level;
        texel.min_distance = 0.0;
        texel.river_width = LAKE_HALF_WIDTH;
        // A lake's vertex paints no river band of its own (its distance is the lake's).
        texel.nearest_sample_width = 0.0;
        texel.river_order = 0.0;
    }
    texel
}

/// The half width a lake's vertices report: wider than any vertex spacing, so no lake is painted (8.4) and the
/// mesh always draws its water, as it draws the sea's.
pub const LAKE_HALF_WIDTH: f32 = 1e9;

/// Procedure 5's outputs from the accumulators.
fn river_outputs(acc: &Accumulators, params: &KernelParams) -> RiverTexel {
    if acc.weight_sum <= 0.0 {
        return RiverTexel {
            terrain_height: 0.0,
            lerp_factor: 1.0,
            water_height: params.sea_level,
            min_distance: params.influence_distance,
            river_width: 0.0,
            flow: [0.0; 2],
            ..RiverTexel::default()
        };
    }
    let height = acc.height_sum / acc.weight_sum;
    let basin = acc.basin_sum / acc.weight_sum;
    // Beyond the thesis: a vertex nearest to a sample with its own, shorter reach (a finer level's stream) has
    // that stream's width, not the mean with the wide river whose valley it runs down.
    let river_width = if acc.nearest_reach < params.influence_distance {
        acc.nearest.half_width
    } else {
        acc.width_sum / acc.weight_sum
    };
    let (terrain_height, lerp_factor, water_height) = if acc.in_river {
        let in_river_basin = acc.in_river_sum / acc.in_river_w_sum;
        let height_offset = basin - params.basin_water_offset;
        (
            height + in_river_basin,
            0.0,
            params.sea_level.max(height + height_offset),
        )
    } else {
        let terrain_height = height + basin;
        let divisor = acc.nearest_reach - river_width;
        let lerp = if divisor > 0.0 {
            ((acc.nearest.distance.abs() - river_width) / divisor).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (
            terrain_height,
            lerp,
            params
                .sea_level
                .max(terrain_height - params.basin_water_offset),
        )
    };
    RiverTexel {
        terrain_height,
        lerp_factor,
        water_height,
        min_distance: acc.nearest.distance,
        river_width,
        flow: if acc.in_river {
            acc.flow_sum.map(|f| f / acc.in_river_w_sum)
        } else {
            [0.0; 2]
        },
        ..RiverTexel::default()
    }
}

/// Beyond the thesis (docs/rendering.md, "The two nearest rivers"): `texel` with the second river's outputs, and
/// the nearest sample's own half width; each half width negative where the vertex lies [`beyond_end`] of that
/// river, for the shaders to narrow the river to nothing there.
fn with_second_river(
    texel: RiverTexel,
    acc: &Accumulators,
    spacing: f32,
    params: &KernelParams,
) -> RiverTexel {
    let signed_width = |s: &NearestSample| {
        if beyond_end(s, spacing, params.sample_floor) {
            -s.half_width
        } else {
            s.half_width
        }
    };
    let second = acc.second.river >= 0.0;
    RiverTexel {
        second_distance: if second {
            acc.second.distance
        } else {
            params.influence_distance
        },
        second_width: if second {
            signed_width(&acc.second)
        } else {
            0.0
        },
        nearest_sample_width: signed_width(&acc.nearest),
        river_order: match (second, acc.nearest.river < acc.second.river) {
            (false, _) => 0.0,
            (true, true) => 1.0,
            (true, false) => -1.0,
        },
        ..texel
    }
}

/// One patch, single-threaded: `n x n` texels in row-major order (index `j * n + i`).
pub fn compute_patch(job: &PatchJob, n: u32, params: &KernelParams) -> Vec<RiverTexel> {
    (0..n * n)
        .map(|k| {
            calculate_height(
                vertex_position(k % n, k / n, job.spacing),
                job.samples,
                job.spacing,
                params,
            )
        })
        .collect()
}

/// One patch whose even vertices come from its parent's `quadrant` (`parent`: the parent's `n x n` texels), the
/// others computed: the reference of the GPU kernels' parent reuse.
pub fn compute_patch_from_parent(
    job: &PatchJob,
    parent: &[RiverTexel],
    quadrant: ParentQuadrant,
    n: u32,
    params: &KernelParams,
) -> Vec<RiverTexel> {
    (0..n * n)
        .map(|k| {
            let (i, j) = (k % n, k / n);
            match quadrant.parent_vertex(i, j) {
                Some((pi, pj)) => parent[(pj * n + pi) as usize],
                None => calculate_height(
                    vertex_position(i, j, job.spacing),
                    job.samples,
                    job.spacing,
                    params,
                ),
            }
        })
        .collect()
}

/// All patches on one thread: the thesis's CPU baseline (9.2).
pub fn compute_patches(jobs: &[PatchJob], n: u32, params: &KernelParams) -> Vec<Vec<RiverTexel>> {
    jobs.iter()
        .map(|job| compute_patch(job, n, params))
        .collect()
}

/// All patches with rayon, parallel over patches and rows.
pub fn compute_patches_rayon(
    jobs: &[PatchJob],
    n: u32,
    params: &KernelParams,
) -> Vec<Vec<RiverTexel>> {
    jobs.par_iter()
        .map(|job| {
            let mut out = vec![RiverTexel::default(); (n * n) as usize];
            out.par_chunks_mut(n as usize)
                .enumerate()
                .for_each(|(j, row)| {
                    for (i, texel) in row.iter_mut().enumerate() {
                        *texel = calculate_height(
                            vertex_position(i as u32, j as u32, job.spacing),
                            job.samples,
                            job.spacing,
                            params,
                        );
                    }
                });
            out
        })
        .collect()
}
