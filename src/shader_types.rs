//! Every struct that crosses to the shaders, in one place, at the bottom of the layers (it depends on nothing of
//! the project): std430 rows of storage buffers, push constants and specialization constants, each the mirror of
//! a GLSL declaration named in its doc comment, its size and field offsets checked at compile time. The layers
//! that fill them (model, kernel, refine, render) import them from here, so a producer never depends on its
//! consumer for a type.

use std::mem::{offset_of, size_of};

use bytemuck::{Pod, Zeroable};

/// One river sample (6.4): position and first derivative in the patch frame, river height and full width.
/// Two vec4s in std430 (32 bytes), which lets the shaders load it with two aligned 16-byte reads
/// (`RiverSample` in glsl/river_kernel.glsl). Beyond the thesis, a negative width marks a lake's sample: its
/// height is the lake's water level, which it gives the vertices within half its (absolute) width.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct RiverSample {
    /// Position in the patch frame.
    pub position: [f32; 2],
    /// The curve's first derivative there (its direction downstream).
    pub derivative: [f32; 2],
    /// The river-bed height (a lake's water level).
    pub height: f32,
    /// The full width (negative for a lake's sample).
    pub width: f32,
    /// Beyond the thesis: the sample's own influence distance (0: the kernel's `influence-distance`, which bounds
    /// it). The streams of finer levels reach less far, so the thousands of them do not flatten the hills between.
    pub reach: f32,
    /// Beyond the thesis: which river the sample lies on, a whole number below 2^24 (exact in f32): a river runs
    /// from its source to where it ends, a main stem keeping its number through the confluences where others join
    /// it. The kernel keeps the nearest two rivers apart by it, for painted confluences (docs/rendering.md).
    pub river: f32,
}

const _: () = assert!(size_of::<RiverSample>() == 32);
const _: () = assert!(offset_of!(RiverSample, height) == 16);

impl RiverSample {
    /// A sample reaching as far as the kernel's influence distance.
    pub fn new(position: [f32; 2], derivative: [f32; 2], height: f32, width: f32) -> Self {
        Self {
            position,
            derivative,
            height,
            width,
            reach: 0.0,
            river: 0.0,
        }
    }

    /// The sample with its own influence distance (0: the kernel's).
    pub fn with_reach(self, reach: f32) -> Self {
        Self { reach, ..self }
    }

    /// The sample on the river whose key is `river` (see [`RiverSample::river`]).
    pub fn on_river(self, river: u64) -> Self {
        Self {
            river: river_number(river),
            ..self
        }
    }
}

/// The number a river's samples carry for its key: 24 bits of it, so that it is exact in f32 (two rivers near
/// one vertex share one with a chance of 1 in 2^24).
pub fn river_number(key: u64) -> f32 {
    (key & 0xff_ffff) as f32
}

/// One row of the river kernel's range table (`PatchJob` in glsl/river_kernel.glsl): a patch, or for a patch
/// that takes river data from its parent, one of its four vertex lattices (kernel/gpu/jobs.rs builds them).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuPatchJob {
    /// World units between neighbouring vertices.
    pub spacing: f32,
    /// The patch's first sample in the sample buffer.
    pub sample_offset: u32,
    /// Its samples.
    pub sample_count: u32,
    /// The place of the patch's river texture (`SlotLayer::shader_index`).
    pub place: u32,
    /// Mask words of the rows before this one: the tiled kernel's reach masks of this row start there.
    pub mask_offset: u32,
    /// Stride (bits 0-7) and parity along x (bits 8-15) and y (bits 16-23) of the vertices this row covers.
    pub lattice: u32,
    /// The place of the parent's river texture to copy the row's vertices from, or
    /// `kernel::gpu::jobs::NO_PARENT`.
    pub parent_place: u32,
    /// The parent vertex of the row's first vertex: x (bits 0-15), y (bits 16-31).
    pub parent_offset: u32,
}

const _: () = assert!(size_of::<GpuPatchJob>() == 32);
const _: () = assert!(offset_of!(GpuPatchJob, mask_offset) == 16);
const _: () = assert!(offset_of!(GpuPatchJob, parent_offset) == 28);

/// The river kernel's push constants (`KernelParams` in glsl/river_kernel.glsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct KernelPush {
    /// [`crate::kernel::KernelParams::influence_distance`].
    pub influence_distance: f32,
    /// [`crate::kernel::KernelParams::basin_depth`].
    pub basin_depth: f32,
    /// [`crate::kernel::KernelParams::sea_level`].
    pub sea_level: f32,
    /// [`crate::kernel::KernelParams::basin_water_offset`].
    pub basin_water_offset: f32,
    /// Vertices per patch edge.
    pub grid_size: u32,
    /// The job-table row that workgroup index 0 computes (rows are dispatched in groups of one lattice).
    pub first_job: u32,
    /// [`crate::kernel::KernelParams::sample_floor`].
    pub sample_floor: f32,
}

const _: () = assert!(size_of::<KernelPush>() == 28);
const _: () = assert!(offset_of!(KernelPush, grid_size) == 16);

/// The tiled kernel's specialization constants (glsl/kernel_tiled.comp, constant_id 0 to 4 in field order).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TiledConstants {
    /// Invocations per workgroup: `block_x` x `block_y`, a multiple of the subgroup size.
    pub invocations: u32,
    /// The vertex block's width (a power of two).
    pub block_x: u32,
    /// The vertex block's height (a power of two, `block_x` or half of it).
    pub block_y: u32,
    /// Samples per tile: a multiple of 32, at most 32 x the invocations.
    pub tile_size: u32,
    /// The subgroup size the pipeline requires.
    pub subgroup_size: u32,
}

const _: () = assert!(size_of::<TiledConstants>() == 20);

/// One row of the height refiner's job table (`RefineJob` in glsl/heights_refine.comp).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuRefineJob {
    /// The place the child's heights go to (`SlotLayer::shader_index`).
    pub child_place: i32,
    /// The place of the parent's heights.
    pub parent_place: i32,
    /// The cube face.
    pub face: i32,
    /// The child's level.
    pub level: i32,
    /// The child's position in its level's grid.
    pub x: i32,
    /// See `x`.
    pub y: i32,
    /// Where the child's lowest and highest height go in the ranges buffer.
    pub range_index: i32,
    /// Padding to 32 bytes.
    pub unused: i32,
}

const _: () = assert!(size_of::<GpuRefineJob>() == 32);
const _: () = assert!(offset_of!(GpuRefineJob, x) == 16);

/// The height refiner's push constants (`Push` in glsl/heights_refine.comp).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct RefinePush {
    /// The master seed: every displacement derives from it and the point's key.
    pub seed: u32,
    /// detail-amplitude: the displacement of level 0.
    pub amplitude: f32,
    /// flat-detail: the displacement's share on level ground (`DetailRule::flat_share`).
    pub flat_share: f32,
    /// `DetailRule::spread_gain()`.
    pub spread_gain: f32,
}

const _: () = assert!(size_of::<RefinePush>() == 16);

/// The push constants of every pass of a frame (`FramePush` in glsl/terrain_common.glsl, whose comments say
/// what each component holds); 128 bytes, what every Vulkan device holds.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FramePush {
    /// Camera-relative world to clip space (the camera at the origin).
    pub view_projection: [[f32; 4]; 4],
    /// xyz: towards the sun; w: sea level.
    pub sun: [f32; 4],
    /// x: radius; y: vertices per patch edge; z: the packed water and view modes; w: the lowest terrain height.
    pub planet: [f32; 4],
    /// x: the transmittance table's slot; y: time; z: the colour bands' height unit; w: vertex capture.
    pub extra: [f32; 4],
    /// xyz: the camera from the planet's centre; w: atmosphere-height.
    pub camera: [f32; 4],
}

const _: () = assert!(size_of::<FramePush>() == 128);
const _: () = assert!(offset_of!(FramePush, sun) == 64);
const _: () = assert!(offset_of!(FramePush, camera) == 112);

/// One drawn patch (`PatchInstance` in glsl/terrain_common.glsl, whose comments say what each component holds).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PatchInstance {
    /// xyz: radius x centre direction - camera (from f64); w: level.
    pub centre_rel: [f32; 4],
    /// xyz: the unit centre direction; w: world distance between neighbouring vertices.
    pub centre_dir: [f32; 4],
    /// xyz: the patch centre on the cube; w: its length.
    pub cube_centre: [f32; 4],
    /// xyz: the cube-space step across the patch along i; w: 2 cube_centre . axis_u.
    pub axis_u: [f32; 4],
    /// The same along j.
    pub axis_v: [f32; 4],
    /// xy: the source texel of vertex (0, 0); z: source texels per vertex; w: skirt length.
    pub tex_rect: [f32; 4],
    /// Places (`SlotLayer::shader_index`) x: of the base heights; y: of the river data or -1; z: the drawn
    /// quadrants (not a place); w: of the parent's river data or -1.
    pub slots: [i32; 4],
    /// x: where morphing starts (share of the switch distance); y: 1 / the morph band; zw: vertex (0, 0) in the
    /// parent's river texture.
    pub morph: [f32; 4],
    /// The switch distances at the patch's corners (0,0), (1,0), (0,1), (1,1) (`LodParams::switch_distances`).
    pub switch_distances: [f32; 4],
    /// xyz: the patch centre's world position reduced modulo DETAIL_PERIOD (render/frame/shader_data.rs); w: its
    /// vertex cache entry, or -1.
    pub detail: [f32; 4],
}

const _: () = assert!(size_of::<PatchInstance>() == 10 * 16);
const _: () = assert!(offset_of!(PatchInstance, slots) == 6 * 16);
const _: () = assert!(offset_of!(PatchInstance, switch_distances) == 8 * 16);
const _: () = assert!(offset_of!(PatchInstance, detail) == 9 * 16);
