//! One frame (docs/rendering.md): level of detail, culling, river data for new patches (one kernel dispatch),
//! then one instanced draw of all visible patches for the terrain and one for the water, each timed.

use std::{
    collections::{BTreeMap, HashMap},
    time::Instant,
};

use bytemuck::{Pod, Zeroable};
use glam::{DMat4, DVec3};
use rayon::prelude::*;
use serde::Serialize;

use super::mesh::{patch_mesh, PatchMesh};
use crate::{
    config::Config,
    gpu::{
        bindless::{Bindless, Slot},
        pipeline::{BufferSetLayout, GraphicsDesc, GraphicsPipeline, RenderTarget},
        vk, Buffer, BufferDesc, Context, GpuError, Image, MemoryLocation, Profiler, Recorder,
    },
    kernel::{
        gpu::{create_river_texture, KernelBatch, KernelTuning, KernelVariant, RiverKernel},
        KernelParams, PatchJob, RiverSample,
    },
    planet::{
        cube::{cube_point, PatchId, FACE_AXES},
        detail::PatchHeights,
        Planet,
    },
    refine::{
        create_height_texture, prepare_height_textures, with_ancestors, HeightRefiner, RefineJob,
        RefinedRanges,
    },
    river::{
        network::RiverNetwork,
        samples::{patch_samples, PatchFrame},
    },
    runtime::{
        cache::{PatchCache, PatchData},
        camera::Camera,
        cull::{beyond_horizon, bounding_sphere, Frustum, HeightRange},
        lod::{select, select_nearest, surface_bounds, threshold, LodParams, Selected},
    },
    shaders,
};

/// How rivers are drawn (Section 8.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum WaterMode {
    /// The thesis's rule: water geometry where the mesh resolves the river, painted elsewhere.
    Auto,
    /// Always emit water triangles in river basins.
    Geometry,
    /// Always paint rivers in the fragment shader (sea water stays geometry).
    Painted,
}

impl WaterMode {
    pub fn next(self) -> Self {
        match self {
            WaterMode::Auto => WaterMode::Geometry,
            WaterMode::Geometry => WaterMode::Painted,
            WaterMode::Painted => WaterMode::Auto,
        }
    }
}

/// The mountain height the fragment shader's colour bands are drawn for (Appendix A's `max-mountain-height`);
/// other planets scale the bands by their own mountain height.
const COLOUR_BAND_MOUNTAIN_HEIGHT: f32 = 16.0;

/// What the fragment shader shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum ViewMode {
    Shaded,
    /// Patches tinted by level of detail.
    Lod,
    /// Painted rivers in red (as in the thesis's Fig. 9.9).
    PaintedRed,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct FramePush {
    view_projection: [[f32; 4]; 4],
    sun: [f32; 4],
    planet: [f32; 4],
    extra: [f32; 4],
}

/// std430 mirror of `PatchInstance` in glsl/terrain_common.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PatchInstance {
    centre_rel: [f32; 4],
    centre_dir: [f32; 4],
    cube_centre: [f32; 4],
    axis_u: [f32; 4],
    axis_v: [f32; 4],
    tex_rect: [f32; 4],
    slots: [i32; 4],
    morph: [f32; 4],
}

/// What one frame did, for the viewer, the benchmarks and the plots (Chapter 9).
#[derive(Clone, Debug, Default, Serialize)]
pub struct FrameStats {
    pub frame: u64,
    /// Patches selected by the level of detail (before culling).
    pub selected_patches: usize,
    pub visible_patches: usize,
    pub new_patches: usize,
    /// New patches influenced by rivers (computed by the kernel this frame).
    pub river_patches: usize,
    /// Visible patches drawn with an ancestor's data because theirs has not arrived yet.
    pub fallback_patches: usize,
    /// Patches still waiting for data after this frame.
    pub pending_patches: usize,
    /// The finest level drawn with its own data.
    pub deepest_level: u32,
    pub samples: usize,
    pub resident_patches: usize,
    pub evicted_patches: usize,
    pub patch_texture_bytes: u64,
    pub temporary_sample_bytes: u64,
    pub precomputed_height_bytes: u64,
    pub memory_bytes: u64,
    pub cpu_ms: BTreeMap<String, f64>,
    pub gpu_ms: BTreeMap<String, f64>,
    pub frame_ms: f64,
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn to_f32(m: DMat4) -> [[f32; 4]; 4] {
    m.as_mat4().to_cols_array_2d()
}

/// The renderer of one planet.
pub struct Renderer<'w> {
    ctx: &'w Context,
    planet: &'w Planet,
    network: &'w RiverNetwork,
    config: Config,
    bindless: Bindless,
    kernel: RiverKernel,
    refiner: HeightRefiner,
    terrain: GraphicsPipeline,
    water: GraphicsPipeline,
    wireframe: GraphicsPipeline,
    instance_layout: BufferSetLayout,
    /// Bound in place of a capture buffer when vertices are not captured.
    no_capture: Buffer,
    indices: Buffer,
    quadrant_ranges: [std::ops::Range<u32>; 4],
    all_indices: std::ops::Range<u32>,
    cache: PatchCache,
    profiler: Profiler,
    params: KernelParams,
    heights: HeightRange,
    frame: u64,
    frozen: Option<Vec<Selected>>,
    pub variant: KernelVariant,
    pub water_mode: WaterMode,
    pub view_mode: ViewMode,
    pub wireframe_on: bool,
    pub freeze_lod: bool,
    /// Beyond the thesis: patches selected by their nearest point and morphed towards their parent before a
    /// switch (CDLOD); `false`: the thesis's Eq. 6.1 on patch centres and instant switching.
    pub morphing: bool,
    /// Unit direction towards the sun; `None`: over the camera's shoulder.
    pub sun: Option<DVec3>,
    /// Keep each frame's kernel input in `last_batch` (for benchmarks that rerun it through every variant).
    pub capture_batches: bool,
    /// The last frame's new river patches: (vertex spacing, samples).
    pub last_batch: Vec<(f32, Vec<RiverSample>)>,
    /// Record where the terrain pass put every vertex in `last_capture` (tests of precision and morphing).
    pub capture_vertices: bool,
    pub last_capture: Option<VertexCapture>,
}

/// Every drawn terrain vertex of one frame, as the vertex shader placed it.
#[derive(Clone, Debug)]
pub struct VertexCapture {
    /// The camera position the positions are relative to.
    pub camera: DVec3,
    /// Vertices per patch edge.
    pub vertices: u32,
    /// Per terrain instance: the patch drawn, and for every mesh vertex its camera-relative position and `1 +
    /// morph factor` (0 for vertices of quadrants not drawn). Grid vertex (i, j) is at `j * vertices + i`.
    pub patches: Vec<(PatchId, Vec<[f32; 4]>)>,
}

impl<'w> Renderer<'w> {
    pub fn new(
        ctx: &'w Context,
        planet: &'w Planet,
        network: &'w RiverNetwork,
        config: &Config,
        color_format: vk::Format,
        depth_format: vk::Format,
    ) -> Result<Self, GpuError> {
        let n = config.rendering.vertices;
        let capacity = config.rendering.max_resident_patches as usize;
        let bindless = Bindless::new(ctx, (2 * capacity + 64) as u32)?;
        // Two slots per patch at most; keep the cache within what the bindless arrays hold.
        let capacity = capacity.min((bindless.capacity as usize - 64) / 2);
        let kernel = RiverKernel::new(ctx, &bindless, n, KernelTuning::for_device(ctx))?;
        let refiner = HeightRefiner::new(ctx, &bindless, n)?;
        let instance_layout = BufferSetLayout::new(ctx, 2, "patch instances and vertex capture")?;
        let no_capture = ctx.create_buffer(&BufferDesc {
            name: "no vertex capture",
            size: 16,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuOnly,
        })?;
        let layouts = [bindless.layout, instance_layout.layout];
        // The terrain is drawn per quadrant without a geometry shader; the water pass has the geometry shader that
        // spawns water triangles (docs/rendering.md).
        let pipeline = |name: &str, water: bool, wireframe: bool| {
            GraphicsPipeline::new(
                ctx,
                &GraphicsDesc {
                    name,
                    vertex: shaders::TERRAIN_VERT,
                    geometry: water.then_some(shaders::TERRAIN_GEOM),
                    fragment: shaders::TERRAIN_FRAG,
                    set_layouts: &layouts,
                    push_constant_bytes: std::mem::size_of::<FramePush>() as u32,
                    specialization: &[water as u32],
                    color_format,
                    depth_format,
                    depth_write: !water,
                    depth_test: true,
                    alpha_blend: water,
                    wireframe,
                },
            )
        };
        let terrain = pipeline("terrain", false, false)?;
        let water = pipeline("water", true, false)?;
        let wireframe = pipeline("terrain wireframe", false, true)?;
        let PatchMesh {
            indices: mesh,
            quadrants,
        } = patch_mesh(n);
        let indices = ctx.create_buffer(&BufferDesc {
            name: "patch mesh indices",
            size: (mesh.len() * 4) as u64,
            usage: vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            location: MemoryLocation::GpuOnly,
        })?;
        ctx.run_and_wait("upload patch mesh", |rec| {
            rec.upload_buffer(&indices, 0, bytemuck::cast_slice(&mesh))
        })?;
        let profiler = Profiler::new(ctx, 8, "frame timestamps")?;
        // Culling bounds: every height any level can reach (finer levels add at most a bound to the precomputed
        // range), with a river basin's depth and a unit of margin either way.
        let (lowest, highest) = planet.height_bounds();
        let margin = config.river.basin_depth as f64 + 1.0;
        let heights = HeightRange {
            min: lowest as f64 - margin,
            max: highest as f64 + margin,
        };
        Ok(Self {
            ctx,
            planet,
            network,
            config: config.clone(),
            bindless,
            kernel,
            refiner,
            terrain,
            water,
            wireframe,
            instance_layout,
            no_capture,
            indices,
            quadrant_ranges: quadrants,
            all_indices: 0..mesh.len() as u32,
            cache: PatchCache::new(capacity),
            profiler,
            params: KernelParams::from_config(config),
            heights,
            frame: 0,
            frozen: None,
            variant: KernelVariant::Tiled,
            water_mode: WaterMode::Auto,
            view_mode: ViewMode::Shaded,
            wireframe_on: false,
            freeze_lod: false,
            morphing: true,
            sun: None,
            capture_batches: false,
            last_batch: Vec::new(),
            capture_vertices: false,
            last_capture: None,
        })
    }

    /// A patch's morph parameters (std430 `morph` of the instance): where its vertices start morphing, one over
    /// the morph band's length, and its texel offset in its parent's river texture. A patch is selected only
    /// while its nearest point is within its level's switch distance, so every vertex of one that is about to
    /// appear or disappear is at least that far away: fully morphed, it looks like its parent.
    fn morph(&self, patch: PatchId) -> [f32; 4] {
        if !self.morphing || patch.level == 0 {
            return NO_MORPH;
        }
        let p = self.lod_params();
        let end = threshold(p.radius, p.switch_factor, patch.level as u32);
        let half = (self.config.rendering.vertices - 1) / 2;
        [
            (end * (1.0 - MORPH_BAND)) as f32,
            (1.0 / (end * MORPH_BAND)) as f32,
            ((patch.x & 1) * half) as f32,
            ((patch.y & 1) * half) as f32,
        ]
    }

    fn lod_params(&self) -> LodParams {
        LodParams {
            radius: self.planet.radius,
            switch_factor: self.config.rendering.level_of_detail_switch_factor as f64,
            max_level: self.config.rendering.max_level_of_detail,
        }
    }

    /// Renders one frame into `target`, whose colour image is in `color_layouts.0` and is left in
    /// `color_layouts.1`. `waits` and `signals` are binary semaphores (swapchain). Blocks until the frame is done.
    pub fn render(
        &mut self,
        camera: &Camera,
        target: &RenderTarget,
        color_layouts: (vk::ImageLayout, vk::ImageLayout),
        waits: &[(vk::Semaphore, vk::PipelineStageFlags2)],
        signals: &[vk::Semaphore],
    ) -> Result<FrameStats, GpuError> {
        let start = Instant::now();
        let ctx = self.ctx;
        self.frame += 1;
        self.cache.next_frame();
        let mut stats = FrameStats {
            frame: self.frame,
            ..Default::default()
        };
        let mut cpu = BTreeMap::new();
        let radius = self.planet.radius;
        let n = self.config.rendering.vertices;

        // Section 6.2.1: level of detail (or the frozen selection).
        let t = Instant::now();
        let selected = match (&self.frozen, self.freeze_lod) {
            (Some(frozen), true) => frozen.clone(),
            _ if self.morphing => {
                let depth = self.config.river.basin_depth as f64;
                let cache = &self.cache;
                select_nearest(camera.position, &self.lod_params(), &|p| {
                    let nearest = cache
                        .nearest_resident(p)
                        .map(|(q, data)| (q.level, data.surface_range()));
                    surface_bounds(self.planet, depth, p, nearest)
                })
            }
            _ => select(camera.position, &self.lod_params()),
        };
        self.frozen = Some(selected.clone());
        cpu.insert("lod".to_string(), ms_since(t));

        // Section 6.2.2: horizon and frustum culling.
        let t = Instant::now();
        let frustum = Frustum::from_matrix(camera.clip());
        let visible: Vec<Selected> = selected
            .iter()
            .filter(|s| {
                let (centre, r) = bounding_sphere(s.patch, radius, self.heights);
                !beyond_horizon(s.patch, camera.position, radius, self.heights)
                    && frustum.touches_sphere(centre, r)
            })
            .copied()
            .collect();
        cpu.insert("cull".to_string(), ms_since(t));
        stats.selected_patches = selected.len();
        stats.visible_patches = visible.len();

        // Patches without data: roots first (they stand in for everything), then coarse before fine and nearest
        // first, each after the ancestors it is refined from, within the per-frame budget; the rest draw an
        // ancestor until their turn.
        let roots: Vec<PatchId> = (0..6).map(PatchId::root).collect();
        let mut wanted: Vec<PatchId> = visible
            .iter()
            .map(|s| s.patch)
            .filter(|p| p.level > 0 && !self.cache.contains(p))
            .collect();
        wanted.sort_by(|a, b| {
            let distance = |p: &PatchId| camera.position.distance_squared(p.center() * radius);
            (a.level, distance(a))
                .partial_cmp(&(b.level, distance(b)))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        wanted.dedup();
        let precomputed = self.planet.precomputed_level;
        let forced = with_ancestors(&roots, precomputed, |p| self.cache.contains(p)).len();
        let mut missing = with_ancestors(
            &roots.iter().chain(&wanted).copied().collect::<Vec<_>>(),
            precomputed,
            |p| self.cache.contains(p),
        );
        // Mark what this frame draws from (its own data or a stand-in), and the resident parents that new patches
        // are refined from, so that eviction leaves them; then make room: the cache never holds more than its
        // budget, so at most that many patches get data.
        for s in &visible {
            let source = if self.cache.contains(&s.patch) {
                Some(s.patch)
            } else {
                self.cache.resident_ancestor(s.patch)
            };
            if let Some(source) = source {
                self.cache.touch(&source);
            }
        }
        let budget = self.config.rendering.new_patches_per_frame as usize;
        missing.truncate((forced + budget).min(self.cache.capacity));
        for p in &missing {
            if let Some(parent) = p.parent() {
                self.cache.touch(&parent);
            }
        }
        let requested = wanted.len();
        stats.evicted_patches =
            self.cache
                .evict_to(self.cache.capacity - missing.len(), ctx, &mut self.bindless);
        let room = self.cache.capacity.saturating_sub(self.cache.len());
        missing.truncate(room.max(forced));
        stats.new_patches = missing.len().saturating_sub(forced);
        stats.pending_patches =
            requested.saturating_sub(missing.iter().filter(|p| wanted.contains(p)).count());

        // Sections 6.3-6.4: base heights of precomputed levels (finer ones are refined on the GPU) and river
        // samples of the new patches, in parallel.
        let t = Instant::now();
        let planet = self.planet;
        let network = self.network;
        let prepared: Vec<NewPatch> = missing
            .par_iter()
            .map(|&p| NewPatch {
                patch: p,
                heights: (p.level as u32 <= precomputed)
                    .then(|| planet.lattice.patch_heights(p, n)),
                samples: patch_samples(network, &PatchFrame::new(p, radius, n)),
            })
            .collect();
        cpu.insert("influence+samples".to_string(), ms_since(t));
        stats.samples = prepared.iter().map(|p| p.samples.len()).sum();

        let t = Instant::now();
        let mut rec = Recorder::begin(ctx, "frame")?;
        self.profiler.reset(ctx);
        let (bytes, river_patches, refined_ranges) =
            self.upload_new_patches(&mut rec, &prepared)?;
        stats.temporary_sample_bytes = bytes;
        stats.river_patches = river_patches;

        // Instances: every visible patch, with its own data or the part of its nearest resident ancestor. One list
        // per quadrant for the terrain (the instances that draw it), then one for the water (patches with a river
        // or below sea level), all in one buffer.
        let mut drawn: Vec<(PatchInstance, bool, PatchId)> = Vec::with_capacity(visible.len());
        for s in &visible {
            let source = if self.cache.contains(&s.patch) {
                stats.deepest_level = stats.deepest_level.max(s.patch.level as u32);
                s.patch
            } else {
                stats.fallback_patches += 1;
                match self.cache.resident_ancestor(s.patch) {
                    Some(a) => a,
                    None => continue,
                }
            };
            // Morphing towards the parent, whose river data the vertices blend into (its base heights are the
            // patch's own at the points that remain).
            let morph = self.morph(s.patch);
            let parent_river = match (source == s.patch, s.patch.parent()) {
                (true, Some(parent)) if self.morphing => self
                    .cache
                    .touch(&parent)
                    .and_then(|d| d.river.as_ref())
                    .map_or(-1, |(_, slot)| slot.0 as i32),
                _ => -1,
            };
            let Some(data) = self.cache.touch(&source) else {
                continue;
            };
            let wet = data.river.is_some() || data.height_range.0 < self.planet.sea_level;
            let mut instance = instance(s, source, data, camera.position, radius, n);
            instance.morph = morph;
            instance.slots[3] = parent_river;
            drawn.push((instance, wet, s.patch));
        }
        let mut instances: Vec<PatchInstance> = Vec::with_capacity(drawn.len() * 3);
        let mut instance_patches: Vec<PatchId> = Vec::with_capacity(drawn.len() * 2);
        let mut quadrant_instances: [std::ops::Range<u32>; 4] = Default::default();
        for (q, range) in quadrant_instances.iter_mut().enumerate() {
            let first = instances.len() as u32;
            for (instance, _, patch) in drawn.iter().filter(|(i, _, _)| i.slots[2] & (1 << q) != 0)
            {
                instances.push(*instance);
                instance_patches.push(*patch);
            }
            *range = first..instances.len() as u32;
        }
        let first = instances.len() as u32;
        instances.extend(drawn.iter().filter(|(_, wet, _)| *wet).map(|(i, _, _)| *i));
        let water_instances = first..instances.len() as u32;
        let instance_buffer = {
            let mut buffer = ctx.create_buffer(&BufferDesc {
                name: "patch instances",
                size: (instances.len().max(1) * std::mem::size_of::<PatchInstance>()) as u64,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::CpuToGpu,
            })?;
            buffer.write(0, &instances)?;
            buffer
        };
        // Vertex capture (tests): one slot per terrain instance and mesh vertex, zero where nothing was drawn.
        let capture = if self.capture_vertices {
            let size = (instance_patches.len().max(1) * mesh_vertices(n) as usize * 16) as u64;
            let buffer = ctx.create_buffer(&BufferDesc {
                name: "vertex capture",
                size,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuToCpu,
            })?;
            rec.fill_buffer(&buffer, 0);
            rec.buffer_barrier(
                &buffer,
                vk::PipelineStageFlags2::CLEAR,
                vk::AccessFlags2::TRANSFER_WRITE,
                vk::PipelineStageFlags2::VERTEX_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
            );
            Some(buffer)
        } else {
            None
        };
        let instance_set = rec.buffer_set(
            &self.instance_layout,
            &[
                &instance_buffer,
                capture.as_ref().unwrap_or(&self.no_capture),
            ],
        )?;
        rec.free_after_completion(instance_buffer);

        // Section 8: terrain, then water.
        let sun = self.sun.unwrap_or_else(|| {
            (camera.position.normalize() * 0.8
                + camera.up.cross(camera.forward).normalize() * 0.5
                + camera.up * 0.3)
                .normalize()
        });
        let push = FramePush {
            view_projection: to_f32(camera.projection() * camera.rotation()),
            sun: [
                sun.x as f32,
                sun.y as f32,
                sun.z as f32,
                self.planet.sea_level,
            ],
            planet: [
                radius as f32,
                n as f32,
                self.water_mode as u32 as f32,
                match self.view_mode {
                    ViewMode::Shaded => 0.0,
                    ViewMode::Lod => 1.0,
                    ViewMode::PaintedRed => 2.0,
                },
            ],
            extra: [
                2.0,
                0.0,
                self.config.planet.max_mountain_height / COLOUR_BAND_MOUNTAIN_HEIGHT,
                self.capture_vertices as u32 as f32,
            ],
        };
        rec.raw_image_transition(
            target.color_image,
            vk::ImageAspectFlags::COLOR,
            color_layouts.0,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            (
                vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
                vk::AccessFlags2::NONE,
            ),
            (
                vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
                vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
            ),
        );
        rec.raw_image_transition(
            target.depth_image,
            vk::ImageAspectFlags::DEPTH,
            vk::ImageLayout::UNDEFINED,
            vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
            (
                vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
                vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
            ),
            (
                vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
                    | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
                vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE
                    | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ,
            ),
        );
        rec.begin_rendering(target, true);
        let sets = [self.bindless.set, instance_set];
        let push = bytemuck::bytes_of(&push);
        let scope = self.profiler.begin(&mut rec, "terrain")?;
        let terrain = if self.wireframe_on {
            &self.wireframe
        } else {
            &self.terrain
        };
        for (indices, instances) in self.quadrant_ranges.iter().zip(&quadrant_instances) {
            rec.draw_indexed(
                terrain,
                &sets,
                push,
                &self.indices,
                indices.clone(),
                instances.clone(),
            );
        }
        self.profiler.end(&mut rec, scope);
        let scope = self.profiler.begin(&mut rec, "water")?;
        if !self.wireframe_on {
            rec.draw_indexed(
                &self.water,
                &sets,
                push,
                &self.indices,
                self.all_indices.clone(),
                water_instances,
            );
        }
        self.profiler.end(&mut rec, scope);
        rec.end_rendering();
        if color_layouts.1 != vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL {
            rec.raw_image_transition(
                target.color_image,
                vk::ImageAspectFlags::COLOR,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                color_layouts.1,
                (
                    vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
                    vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
                ),
                (
                    vk::PipelineStageFlags2::BOTTOM_OF_PIPE,
                    vk::AccessFlags2::NONE,
                ),
            );
        }
        cpu.insert("record".to_string(), ms_since(t));

        let t = Instant::now();
        let id = rec.submit_with(waits, signals)?;
        ctx.wait(id)?;
        cpu.insert("gpu wait".to_string(), ms_since(t));
        self.last_capture = match capture {
            Some(buffer) => {
                let positions: Option<Vec<[f32; 4]>> = buffer
                    .mapped()
                    .map(|bytes| bytemuck::cast_slice(bytes).to_vec());
                ctx.retire_buffer(buffer);
                let per = mesh_vertices(n) as usize;
                positions.map(|p| VertexCapture {
                    camera: camera.position,
                    vertices: n,
                    patches: instance_patches
                        .iter()
                        .zip(p.chunks(per))
                        .map(|(patch, v)| (*patch, v.to_vec()))
                        .collect(),
                })
            }
            None => None,
        };
        if let Some(ranges) = refined_ranges {
            for (patch, range) in ranges.read(ctx)? {
                self.cache.set_height_range(&patch, range);
            }
        }
        for scope in self.profiler.read(ctx)? {
            *stats.gpu_ms.entry(scope.name).or_default() += scope.ms;
        }

        stats.resident_patches = self.cache.len();
        stats.patch_texture_bytes = self.cache.bytes();
        stats.precomputed_height_bytes = self.planet.lattice.bytes();
        stats.memory_bytes = stats.patch_texture_bytes
            + stats.temporary_sample_bytes
            + stats.precomputed_height_bytes;
        stats.cpu_ms = cpu;
        stats.frame_ms = ms_since(start);
        log::debug!(
            "frame {}: {} selected, {} visible, {} new, {} pending, {} resident, deepest level {}, {:.1} ms",
            stats.frame,
            stats.selected_patches,
            stats.visible_patches,
            stats.new_patches,
            stats.pending_patches,
            stats.resident_patches,
            stats.deepest_level,
            stats.frame_ms
        );
        Ok(stats)
    }

    /// Creates the textures of new patches; uploads the base heights of precomputed levels and refines the rest
    /// from their parents on the GPU (parents first, one dispatch per level); then computes all river textures in
    /// one kernel dispatch. Returns the temporary bytes (samples, job tables), how many patches have rivers, and
    /// where the refined patches' height ranges arrive.
    fn upload_new_patches(
        &mut self,
        rec: &mut Recorder,
        prepared: &[NewPatch],
    ) -> Result<(u64, usize, Option<RefinedRanges>), GpuError> {
        self.last_batch.clear();
        if prepared.is_empty() {
            return Ok((0, 0, None));
        }
        let ctx = self.ctx;
        let n = self.config.rendering.vertices;
        if self.capture_batches {
            self.last_batch = prepared
                .iter()
                .filter(|p| !p.samples.is_empty())
                .map(|p| {
                    (
                        PatchFrame::new(p.patch, self.planet.radius, n).spacing() as f32,
                        p.samples.clone(),
                    )
                })
                .collect();
        }
        let mut bases: Vec<(Image, Slot)> = Vec::with_capacity(prepared.len());
        for p in prepared {
            let image = create_height_texture(ctx, n, &format!("base heights {:?}", p.patch))?;
            let slot = self.slot()?;
            self.bindless
                .write(ctx, slot, &image, true, vk::ImageLayout::GENERAL);
            bases.push((image, slot));
        }
        let base_refs: Vec<&Image> = bases.iter().map(|(i, _)| i).collect();
        prepare_height_textures(rec, &base_refs);
        // Slot and height range (border included) of each new patch: exact for uploaded ones, a bound for
        // refined ones until the shader's own range is read back after the frame.
        let mut made: HashMap<PatchId, (Slot, (f32, f32))> = HashMap::new();
        let mut jobs: Vec<RefineJob> = Vec::new();
        for (p, (image, slot)) in prepared.iter().zip(&bases) {
            let range = match &p.heights {
                Some(heights) => {
                    rec.upload_image_layer(
                        image,
                        vk::ImageLayout::GENERAL,
                        0,
                        bytemuck::cast_slice(&heights.data),
                    )?;
                    heights.range()
                }
                None => {
                    let parent = p.patch.parent().expect("refined patches have parents");
                    let (parent_slot, (lo, hi)) = match made.get(&parent) {
                        Some(&made) => made,
                        None => {
                            let data = self.cache.touch(&parent).ok_or_else(|| {
                                GpuError::Invalid(format!("{:?} has no resident parent", p.patch))
                            })?;
                            (data.base_slot, data.height_range)
                        }
                    };
                    jobs.push(RefineJob {
                        patch: p.patch,
                        slot: *slot,
                        parent_slot,
                    });
                    let extra = self.planet.rule.remaining_range(p.patch.level as u32 - 1);
                    (lo - extra, hi + extra)
                }
            };
            made.insert(p.patch, (*slot, range));
        }
        rec.memory_barrier(
            vk::PipelineStageFlags2::COPY,
            vk::AccessFlags2::TRANSFER_WRITE,
            vk::PipelineStageFlags2::COMPUTE_SHADER,
            vk::AccessFlags2::SHADER_SAMPLED_READ,
        );
        let mut bytes = 0;
        let mut ranges = None;
        if !jobs.is_empty() {
            let scope = self.profiler.begin(rec, "heights")?;
            ranges = self
                .refiner
                .record(rec, &self.bindless, self.planet, &jobs)?;
            self.profiler.end(rec, scope);
            bytes += ranges.as_ref().map_or(0, |r| r.bytes);
        }
        rec.memory_barrier(
            vk::PipelineStageFlags2::COMPUTE_SHADER | vk::PipelineStageFlags2::COPY,
            vk::AccessFlags2::SHADER_STORAGE_WRITE | vk::AccessFlags2::TRANSFER_WRITE,
            vk::PipelineStageFlags2::VERTEX_SHADER
                | vk::PipelineStageFlags2::GEOMETRY_SHADER
                | vk::PipelineStageFlags2::FRAGMENT_SHADER,
            vk::AccessFlags2::SHADER_SAMPLED_READ,
        );

        let mut rivers: Vec<(Image, Slot)> = Vec::new();
        let mut patch_jobs: Vec<PatchJob> = Vec::new();
        let mut river_of: Vec<Option<usize>> = Vec::with_capacity(prepared.len());
        for p in prepared {
            if p.samples.is_empty() {
                river_of.push(None);
                continue;
            }
            let slot = self.slot()?;
            let image = create_river_texture(ctx, n, &format!("river data {:?}", p.patch))?;
            self.bindless
                .write(ctx, slot, &image, true, vk::ImageLayout::GENERAL);
            patch_jobs.push(PatchJob {
                spacing: PatchFrame::new(p.patch, self.planet.radius, n).spacing() as f32,
                samples: &p.samples,
            });
            river_of.push(Some(rivers.len()));
            rivers.push((image, slot));
        }
        let slots: Vec<Slot> = rivers.iter().map(|(_, s)| *s).collect();
        if !rivers.is_empty() {
            let textures: Vec<&Image> = rivers.iter().map(|(i, _)| i).collect();
            let batch = KernelBatch {
                textures: &textures,
                slots: &slots,
                jobs: &patch_jobs,
            };
            let scope = self.profiler.begin(rec, "kernel")?;
            bytes += self
                .kernel
                .record(rec, &self.bindless, self.variant, &batch, &self.params)?;
            self.profiler.end(rec, scope);
            rec.memory_barrier(
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
                vk::PipelineStageFlags2::VERTEX_SHADER
                    | vk::PipelineStageFlags2::GEOMETRY_SHADER
                    | vk::PipelineStageFlags2::FRAGMENT_SHADER,
                vk::AccessFlags2::SHADER_SAMPLED_READ,
            );
        }
        let river_count = rivers.len();
        let mut rivers: Vec<Option<(Image, Slot)>> = rivers.into_iter().map(Some).collect();
        for ((p, (base, slot)), river) in prepared.iter().zip(bases).zip(river_of) {
            let river = river.and_then(|k| rivers[k].take());
            self.cache.insert(
                p.patch,
                PatchData::new(
                    (base, slot),
                    river,
                    p.samples.len(),
                    made[&p.patch].1,
                    river_range(&p.samples, self.config.river.basin_depth),
                ),
            );
        }
        Ok((bytes, river_count, ranges))
    }

    /// A free bindless slot, evicting the least recently used patches if none is left.
    fn slot(&mut self) -> Result<Slot, GpuError> {
        if let Some(s) = self.bindless.allocate() {
            return Ok(s);
        }
        let capacity = self.cache.capacity;
        self.cache.evict_to(capacity, self.ctx, &mut self.bindless);
        self.bindless.allocate().ok_or_else(|| {
            GpuError::Invalid(format!(
                "all {} bindless slots are in use; raise max-resident-patches or lower new-patches-per-frame",
                self.bindless.capacity
            ))
        })
    }

    /// Frees every GPU object of the renderer (after the device is idle).
    pub fn destroy(mut self) {
        let ctx = self.ctx;
        let _ = ctx.wait_idle();
        self.cache.clear(ctx, &mut self.bindless);
        ctx.retire_buffer(self.indices);
        self.profiler.destroy(ctx);
        self.kernel.destroy(ctx);
        self.refiner.destroy(ctx);
        self.terrain.destroy(ctx);
        self.water.destroy(ctx);
        self.wireframe.destroy(ctx);
        self.instance_layout.destroy(ctx);
        ctx.retire_buffer(self.no_capture);
        let _ = ctx.wait_idle();
        self.bindless.destroy(ctx);
    }
}

/// The heights river beds and water can take near `samples`: their heights widened by the basin depth.
fn river_range(samples: &[RiverSample], basin_depth: f32) -> Option<(f32, f32)> {
    samples
        .iter()
        .map(|s| s.height)
        .fold(None, |range: Option<(f32, f32)>, h| {
            Some(range.map_or((h, h), |(lo, hi)| (lo.min(h), hi.max(h))))
        })
        .map(|(lo, hi)| (lo - basin_depth, hi + basin_depth))
}

/// Vertices of the patch mesh: the grid and six skirts (render/mesh.rs).
fn mesh_vertices(n: u32) -> u32 {
    n * n + 6 * n
}

/// A patch that gets its data this frame: base heights from the precomputed lattice (`None`: refined on the GPU
/// from its parent's), and its river samples.
struct NewPatch {
    patch: PatchId,
    heights: Option<PatchHeights>,
    samples: Vec<RiverSample>,
}

/// The instance that draws `selected` from `source`'s textures (itself, or an ancestor standing in).
fn instance(
    selected: &Selected,
    source: PatchId,
    data: &PatchData,
    camera: DVec3,
    radius: f64,
    n: u32,
) -> PatchInstance {
    let p = selected.patch;
    let centre = p.center();
    let rel = centre * radius - camera;
    // The patch's frame on the cube, in f64: its centre and the steps across it (docs/rendering.md, "Precision").
    let (_, a, b) = FACE_AXES[p.face as usize];
    let (uc, vc) = p.uv(0.5, 0.5);
    let cube_centre = cube_point(p.face as usize, uc, vc);
    let (axis_u, axis_v) = (a * p.size(), b * p.size());
    let with = |v: DVec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
    let depth = (p.level - source.level) as u32;
    let scale = 1.0 / (1u32 << depth) as f32;
    let offset_x = (p.x - (source.x << depth)) as f32 * scale * (n - 1) as f32;
    let offset_y = (p.y - (source.y << depth)) as f32 * scale * (n - 1) as f32;
    let spacing = PatchFrame::new(p, radius, n).spacing();
    PatchInstance {
        centre_rel: [rel.x as f32, rel.y as f32, rel.z as f32, p.level as f32],
        centre_dir: [
            centre.x as f32,
            centre.y as f32,
            centre.z as f32,
            spacing as f32,
        ],
        cube_centre: with(cube_centre, cube_centre.length()),
        axis_u: with(axis_u, 2.0 * cube_centre.dot(axis_u)),
        axis_v: with(axis_v, 2.0 * cube_centre.dot(axis_v)),
        tex_rect: [offset_x, offset_y, scale, 0.0],
        slots: [
            data.base_slot.0 as i32,
            data.river.as_ref().map_or(-1, |(_, s)| s.0 as i32),
            selected.quadrants as i32,
            -1,
        ],
        morph: NO_MORPH,
    }
}

/// Morph distances that never morph (the level-0 patches, and the thesis's instant switching).
const NO_MORPH: [f32; 4] = [f32::MAX, 1.0, 0.0, 0.0];

/// Share of a level's switch distance over which its patches morph into their parent's shape (CDLOD's morph
/// region): from 70 % of the distance on, fully at it.
const MORPH_BAND: f64 = 0.3;
