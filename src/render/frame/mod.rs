//! One frame (docs/rendering.md): the streaming plan (level of detail, culling, which patches get data:
//! `plan`), the new patches' data (base heights uploaded or refined, river data from one kernel dispatch:
//! `upload`), then the terrain and water passes (`draw`), each timed; submitted without waiting, and what it leaves
//! to read back taken in once the GPU has finished it (`inflight`).

mod draw;
mod inflight;
mod lake_map;
mod modes;
mod plan;
mod resident;
mod shader_data;
mod sky;
mod stats;
mod upload;
mod vertex_cache;

use std::{collections::BTreeMap, sync::Arc, time::Instant};

use glam::DVec3;

pub use self::draw::{DrawnVertex, VertexCapture};
pub use self::inflight::GpuTimes;
use self::inflight::{InFlight, TIMESTAMP_SCOPES};
pub use self::modes::{ViewMode, WaterMode};
use self::resident::{PatchData, PatchTextures, TextureKind};
pub use self::stats::FrameStats;
use super::mesh::{index_buffer, patch_mesh, PatchMesh, QuadrantMesh};
use crate::shader_types::FramePush;
use crate::{
    config::{Config, LodRule, TerrainColours},
    gpu::{
        bindless::{Bindless, SlotLayer},
        frames::{FrameRing, FRAMES_IN_FLIGHT},
        pipeline::{Blend, BufferSetLayout, GraphicsDesc, GraphicsPipeline, RenderTarget},
        Access, Buffer, BufferDesc, Context, Extent2D, Format, GpuError, MemoryLocation, Semaphore,
    },
    kernel::{
        gpu::{autotune, KernelVariant, RiverKernel},
        KernelParams, PatchJob,
    },
    planet::{atmosphere::Atmosphere, Planet},
    refine::HeightRefiner,
    river::network::RiverNetwork,
    runtime::{
        cache::PatchCache,
        camera::Camera,
        cull::HeightRange,
        error_field::ErrorField,
        lod::{LodParams, Selected},
    },
    shaders,
};

/// Called with a frame's kernel input (the new patches with rivers: vertex spacing and samples) before the kernel
/// is recorded: for benchmarks that rerun it through every kernel variant.
pub type KernelObserver<'w> = Box<dyn FnMut(&[PatchJob]) + 'w>;

/// Draws recorded into a frame's rendering after its own passes (the viewer's overlay).
pub type Overlay<'a> = &'a mut dyn FnMut(&mut crate::gpu::Recorder, Extent2D);

/// The mountain height the fragment shader's colour bands are drawn for (Appendix A's `max-mountain-height`);
/// other planets scale the bands by their own mountain height.
const COLOUR_BAND_MOUNTAIN_HEIGHT: f32 = 16.0;

/// Textures of each kind beyond the resident patches': the frame's new patches before the cache evicts.
const SPARE_TEXTURES: usize = 64;

/// Bytes of the largest resident patch: its base-height texture and a river texture.
fn max_patch_bytes(n: u32) -> usize {
    let side = crate::planet::detail::PatchHeights::side(n);
    side * side * 4 + (n * n) as usize * 16 * crate::kernel::gpu::RIVER_TEXTURE_LAYERS as usize
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// The pipelines that draw the surface with terrain.frag.
#[derive(Clone, Copy, PartialEq, Eq)]
enum SurfacePipeline {
    /// Terrain, back faces culled.
    Culled,
    /// Terrain that can show its back faces (patches reaching their switch distance).
    Unculled,
    Wireframe,
    /// Water, blended.
    Water,
}

/// The renderer of one planet.
pub struct Renderer<'w> {
    ctx: &'w Context,
    planet: &'w Planet,
    network: &'w RiverNetwork,
    config: Config,
    bindless: Bindless,
    /// The resident patches' textures, layers of a few array images per kind.
    textures: PatchTextures,
    kernel: RiverKernel,
    refiner: HeightRefiner,
    terrain: GraphicsPipeline,
    /// The terrain without back-face culling, for patches that reach their switch distance (draw.rs,
    /// `reaches_switch_distance`).
    terrain_unculled: GraphicsPipeline,
    /// The terrain's two pipelines (back faces culled, not culled) with the lake map's code compiled in, for the
    /// patches a lake of the map reaches (`LAKE_MAP` in terrain.frag); `None` without a lake map.
    terrain_lakes: Option<[GraphicsPipeline; 2]>,
    water: GraphicsPipeline,
    /// The water of patches in the vertex cache, from the triangles its passes list (no geometry shader).
    cached_water: GraphicsPipeline,
    wireframe: GraphicsPipeline,
    /// The atmosphere's table and sky pass; `None` for a planet without air (`atmosphere-height` 0).
    sky: Option<sky::Sky>,
    /// How far below its lake each precomputed lattice point lies, for the coarse patches; `None` without lakes.
    lake_map: Option<lake_map::LakeMap>,
    instance_layout: BufferSetLayout,
    /// Bound in place of the vertex capture when vertices are not captured, of the water pass's draws and
    /// indices when the terrain mesh carries the water, and of the sky dome's vertices when no sky is drawn.
    placeholder: Buffer,
    vertex_cache: vertex_cache::VertexCache,
    indices: Buffer,
    quadrants: [QuadrantMesh; 4],
    cache: PatchCache<PatchData>,
    frames: FrameRing<InFlight>,
    /// GPU times of finished frames not yet taken (`take_gpu_times`), the newest 1024 at most.
    gpu_times: std::collections::VecDeque<GpuTimes>,
    /// The newest finished frame's GPU times, what `FrameStats::gpu_ms` reports.
    latest_gpu_times: Option<GpuTimes>,
    /// The newest frame collected after the GPU finished it.
    synchronized_frame: u64,
    params: KernelParams,
    heights: HeightRange,
    frame: u64,
    frozen: Option<Vec<Selected>>,
    /// This frame's switch distances (`lod_rule`, the camera and the viewport).
    lod: LodParams,
    /// The errors the screen-space rule projects, patch by patch: the terrain's (`Planet::quadrant_error`) or
    /// what the parent level's river data can miss (`lod::river_error`), whichever is larger.
    errors: Arc<ErrorField>,
    /// GPU milliseconds per new patch (base heights and river data), averaged over recent frames: what the
    /// generation budget divides by.
    generation_ms_per_patch: Option<f64>,
    /// The kernel variant that computes new patches' river data.
    pub variant: KernelVariant,
    /// How water is drawn: from the mesh where it carves, painted, or as geometry (Section 8.4).
    pub water_mode: WaterMode,
    /// What the terrain shows: shading, the patches' levels, painted rivers in red.
    pub view_mode: ViewMode,
    /// The terrain drawn as lines, without the water pass.
    pub wireframe_on: bool,
    /// Keep drawing the patches selected when it was set (to look at a selection from elsewhere).
    pub freeze_lod: bool,
    /// Beyond the thesis: the atmosphere (scattering in the shell of `atmosphere-height`); `false`: a constant
    /// haze and the clear colour behind the planet, as before it.
    pub atmosphere_on: bool,
    /// Beyond the thesis: rippled water carried by the rivers' flow, foam at banks and shores; `false`: still,
    /// flat water as the thesis draws it (Section 8.4).
    pub flowing_water: bool,
    /// Beyond the thesis (docs/rendering.md, "Water in the terrain mesh"): the terrain pass draws the water, its
    /// vertices under the sea or in a river basin the mesh shows raised to the water's surface, and no water pass
    /// runs; `false`: the thesis's water pass (Section 8.4), transparent triangles over the terrain. From a camera
    /// under the sea the water pass draws it either way (the raised surface faces away from it).
    pub water_in_mesh: bool,
    /// Beyond the thesis: the drawn patches' vertices computed once a frame in a compute pass and read by both
    /// passes (render/frame/vertex_cache.rs); `false`: computed in the vertex shaders, as the thesis.
    pub cache_vertices: bool,
    /// Seconds of animation: how far the water has flowed.
    pub time: f32,
    /// Beyond the thesis: patches selected by their nearest point and morphed towards their parent before a
    /// switch (CDLOD); `false`: the thesis's Eq. 6.1 on patch centres and instant switching.
    pub morphing: bool,
    /// Beyond the thesis (its future work, 10.2): a patch whose parent has the rivers' final detail copies the
    /// parent's river data at their shared vertices and computes only the rest; `false`: every patch from
    /// scratch, as the thesis.
    pub parent_reuse: bool,
    /// How patches are refined (from `level-of-detail-rule`; `Distance` is the thesis's Eq. 6.1).
    pub lod_rule: LodRule,
    /// Unit direction towards the sun; `None`: over the camera's shoulder.
    pub sun: Option<DVec3>,
    /// Handed each frame's kernel input before it is recorded (`observe_kernel_input`).
    kernel_observer: Option<KernelObserver<'w>>,
    /// Record where the terrain pass put every vertex in `last_capture` (tests of precision and morphing).
    pub capture_vertices: bool,
    /// The last frame's capture, where `capture_vertices` is set.
    pub last_capture: Option<VertexCapture>,
}

impl<'w> Renderer<'w> {
    /// A renderer of `planet` and its rivers for targets of `color_format` and `depth_format`: its pipelines,
    /// the bindless set and the patch cache sized to the configuration's budgets.
    pub fn new(
        ctx: &'w Context,
        planet: &'w Planet,
        network: &'w RiverNetwork,
        config: &Config,
        color_format: Format,
        depth_format: Format,
    ) -> Result<Self, GpuError> {
        let n = config.rendering.vertices;
        // Resident patches: as many as the memory budget holds at the largest patch (base heights and river data),
        // at most max-resident-patches.
        let memory = config.rendering.resident_memory_mb as usize * 1024 * 1024;
        let capacity =
            (config.rendering.max_resident_patches as usize).min(memory / max_patch_bytes(n));
        // Room for the resident patches and the new ones of a frame; a few more slots for the atmosphere's
        // table and the lake map.
        let textures = PatchTextures::new(n, capacity + SPARE_TEXTURES)?;
        let mut bindless = Bindless::new(
            ctx,
            (PatchTextures::slots_for(capacity + SPARE_TEXTURES) + 16) as u32,
        )?;
        // The shape and variant measured on this device at first use (cached per device and driver).
        let tuned = autotune::tuned(ctx, n)?;
        let kernel = RiverKernel::new(ctx, &bindless, n, tuned.tuning)?;
        let refiner = HeightRefiner::new(ctx, &bindless, n)?;
        let instance_layout = BufferSetLayout::new(
            ctx,
            7,
            "patch instances, vertex capture, vertex cache, water draws, mesh indices, water indices, sky dome",
        )?;
        let placeholder = ctx.create_buffer(&BufferDesc {
            name: "placeholder",
            size: 64,
            uses: &[Access::VertexShaderWrite],
            location: MemoryLocation::GpuOnly,
        })?;
        let layouts = [bindless.layout, instance_layout.layout];
        let vertex_cache = vertex_cache::VertexCache::new(ctx, &layouts)?;
        // The terrain is drawn per quadrant without a geometry shader, back faces culled where nothing can show
        // through them (docs/rendering.md, "Back faces and morphing"); the water pass has the geometry shader that
        // spawns water triangles, except for the cached patches, whose water triangles the vertex cache's passes
        // list (docs/rendering.md). Water is blended over the terrain, writes no depth and comes in either winding.
        let climate = config.rendering.terrain_colours == TerrainColours::Climate;
        let pipeline = |name: &str, vertex, geometry, kind: SurfacePipeline, lakes: bool| {
            let water = kind == SurfacePipeline::Water;
            GraphicsPipeline::new(
                ctx,
                &GraphicsDesc {
                    name,
                    vertex,
                    geometry,
                    fragment: shaders::TERRAIN_FRAG,
                    set_layouts: &layouts,
                    push_constant_bytes: std::mem::size_of::<FramePush>() as u32,
                    specialization: bytemuck::bytes_of(&[
                        water as u32,
                        lakes as u32,
                        climate as u32,
                    ]),
                    color_format,
                    depth_format,
                    depth_write: !water,
                    depth_test: true,
                    blend: if water { Blend::Alpha } else { Blend::None },
                    wireframe: kind == SurfacePipeline::Wireframe,
                    cull_back_faces: matches!(
                        kind,
                        SurfacePipeline::Culled | SurfacePipeline::Wireframe
                    ),
                },
            )
        };
        use SurfacePipeline::{Culled, Unculled, Water, Wireframe};
        let terrain = pipeline("terrain", shaders::TERRAIN_VERT, None, Culled, false)?;
        let terrain_unculled = pipeline(
            "terrain, not culled",
            shaders::TERRAIN_VERT,
            None,
            Unculled,
            false,
        )?;
        let water = pipeline(
            "water",
            shaders::WATER_VERT,
            Some(shaders::TERRAIN_GEOM),
            Water,
            false,
        )?;
        let cached_water = pipeline(
            "cached water",
            shaders::WATER_SURFACE_VERT,
            None,
            Water,
            false,
        )?;
        let wireframe = pipeline(
            "terrain wireframe",
            shaders::TERRAIN_VERT,
            None,
            Wireframe,
            false,
        )?;
        let air = Atmosphere::new(
            planet.radius,
            planet.sea_level as f64,
            config.planet.atmosphere_height as f64,
        );
        let sky = air
            .map(|a| {
                sky::Sky::new(
                    ctx,
                    &mut bindless,
                    &a,
                    &layouts,
                    (color_format, depth_format),
                )
            })
            .transpose()?;
        let lakes = planet.drainage.as_ref().map_or(&[][..], |d| &d.lakes[..]);
        let lake_map = lake_map::LakeMap::new(
            ctx,
            &mut bindless,
            &planet.lattice,
            lakes,
            planet.radius,
            (planet.stats.max_height - planet.stats.min_height).max(f32::MIN_POSITIVE),
            planet.precomputed_level,
        )?;
        let terrain_lakes = match lake_map {
            Some(_) => Some([
                pipeline("terrain, lakes", shaders::TERRAIN_VERT, None, Culled, true)?,
                pipeline(
                    "terrain, lakes, not culled",
                    shaders::TERRAIN_VERT,
                    None,
                    Unculled,
                    true,
                )?,
            ]),
            None => None,
        };
        let PatchMesh {
            indices: mesh,
            quadrants,
        } = patch_mesh(n);
        let indices = index_buffer(ctx, "patch mesh indices", &mesh)?;
        let frames = FrameRing::new(ctx, FRAMES_IN_FLIGHT, TIMESTAMP_SCOPES, "frame")?;
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
            textures,
            kernel,
            refiner,
            terrain,
            terrain_unculled,
            terrain_lakes,
            water,
            cached_water,
            wireframe,
            sky,
            lake_map,
            instance_layout,
            placeholder,
            vertex_cache,
            indices,
            quadrants,
            cache: PatchCache::new(capacity),
            frames,
            gpu_times: Default::default(),
            latest_gpu_times: None,
            synchronized_frame: 0,
            params: KernelParams::from_config(config),
            heights,
            frame: 0,
            frozen: None,
            lod: LodParams::distance(
                planet.radius,
                config.rendering.level_of_detail_switch_factor as f64,
                config.rendering.max_level_of_detail,
            ),
            errors: Arc::new(plan::error_field(planet, network, config)),
            lod_rule: config.rendering.level_of_detail_rule,
            generation_ms_per_patch: None,
            variant: tuned.variant,
            water_mode: WaterMode::Auto,
            view_mode: ViewMode::Shaded,
            wireframe_on: false,
            freeze_lod: false,
            atmosphere_on: true,
            flowing_water: true,
            water_in_mesh: true,
            cache_vertices: true,
            time: 0.0,
            morphing: true,
            parent_reuse: true,
            sun: None,
            kernel_observer: None,
            capture_vertices: false,
            last_capture: None,
        })
    }

    /// Renders frames of `camera` into `target` until every visible patch has its own data (or `max_frames` were
    /// rendered): what a still image needs. The colour image is in `*layout` and is left in
    /// COLOR_ATTACHMENT_OPTIMAL (`*layout` says so afterwards). Waits for every frame; returns the last frame's
    /// statistics (its GPU times, and its time until the GPU finished it) and the number of frames.
    pub fn render_until_streamed(
        &mut self,
        camera: &Camera,
        target: &RenderTarget,
        max_frames: u32,
    ) -> Result<(FrameStats, u32), GpuError> {
        let mut frames = 0;
        loop {
            let start = Instant::now();
            let stats = self.render(camera, target, Access::ColorAttachment, &[], &[])?;
            frames += 1;
            if stats.streamed() || frames >= max_frames {
                let mut stats = stats;
                self.finish()?;
                // The last frame's time to its completion on the GPU.
                stats.frame_ms = ms_since(start);
                self.report_latest_gpu_times(&mut stats);
                stats.frames_in_flight = 0;
                return Ok((stats, frames));
            }
        }
    }

    /// Renders one frame into `target`, whose colour image is cleared and left ready for the use `after` (more
    /// drawing or a read-back: `Access::ColorAttachment`; `Access::Present`). `waits` and `signals` are binary semaphores (swapchain). Does not wait for this frame:
    /// it waits only for the frame that last used the same frame context (`FRAMES_IN_FLIGHT` back), and collects
    /// what finished frames left (height ranges, vertex capture, GPU times). `finish` waits for all of them.
    pub fn render(
        &mut self,
        camera: &Camera,
        target: &RenderTarget,
        after: Access,
        waits: &[(Semaphore, Access)],
        signals: &[Semaphore],
    ) -> Result<FrameStats, GpuError> {
        self.render_with_overlay(camera, target, after, (waits, signals), None)
    }

    /// As [`Renderer::render`], with `overlay` recording its draws into the frame's rendering after the sky (the
    /// viewer's on-screen overlay).
    pub fn render_with_overlay(
        &mut self,
        camera: &Camera,
        target: &RenderTarget,
        after: Access,
        (waits, signals): (&[(Semaphore, Access)], &[Semaphore]),
        overlay: Option<Overlay<'_>>,
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

        self.lod = self.lod_params(camera, target.extent().height);
        let visible = self.visible_patches(camera, &mut stats, &mut cpu);
        let plan = self.plan_streaming(camera, &visible, &mut stats)?;

        let t = Instant::now();
        let prepared = self.prepare(&plan);
        cpu.insert("influence+samples".to_string(), ms_since(t));
        stats.samples = prepared.iter().map(|p| p.samples.len()).sum();

        let t = Instant::now();
        let (mut rec, finished) = self.frames.begin(ctx, "frame")?;
        cpu.insert("frame wait".to_string(), ms_since(t));
        self.collect(finished.into_iter().collect())?;

        // The new patches' textures made and their work recorded, apart from the drawing: where a frame that
        // makes many patches spends its CPU time.
        let t = Instant::now();
        let uploaded = self.upload_new_patches(&mut rec, &prepared)?;
        stats.temporary_sample_bytes = uploaded.bytes;
        stats.river_patches = uploaded.river_patches;
        stats.river_patches_from_parent = uploaded.river_patches_from_parent;
        cpu.insert("upload".to_string(), ms_since(t));
        let t = Instant::now();
        let drawn = self.record_draw(
            &mut rec,
            camera,
            &visible,
            (target, after),
            &mut stats,
            overlay,
        )?;
        cpu.insert("record".to_string(), ms_since(t));

        let t = Instant::now();
        let in_flight = InFlight {
            frame: self.frame,
            new_patches: stats.new_patches,
            ranges: uploaded.ranges,
            drawn,
            camera: camera.position,
        };
        stats.synchronized_frame = self.synchronized_frame;
        self.frames.submit(rec, waits, signals, in_flight)?;
        cpu.insert("submit".to_string(), ms_since(t));
        stats.frames_in_flight = self.frames.in_flight(ctx)?;
        self.report_latest_gpu_times(&mut stats);
        stats.resident_patches = self.cache.len();
        stats.patch_texture_bytes = self
            .cache
            .values()
            .map(|data| data.bytes(&self.textures))
            .sum();
        stats.patch_texture_images =
            self.textures.heights.image_count() + self.textures.rivers.image_count();
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

    /// The screen-space-error rule's pixel error and Eq. 6.1's switch factor, changeable between frames (the
    /// viewer's overlay).
    pub fn level_of_detail_settings(&mut self) -> (&mut f32, &mut f32) {
        let r = &mut self.config.rendering;
        (&mut r.pixel_error, &mut r.level_of_detail_switch_factor)
    }

    /// Hands every later frame's kernel input to `observer` (none for frames that compute no river data).
    pub fn observe_kernel_input(&mut self, observer: KernelObserver<'w>) {
        self.kernel_observer = Some(observer);
    }

    /// Evicts the least recently used patches beyond `target` (`PatchCache::evict_to`) and frees their
    /// textures' layers; returns how many.
    fn evict_patches(&mut self, target: usize) -> usize {
        let evicted = self.cache.evict_to(target);
        let count = evicted.len();
        for data in evicted {
            data.release(self.ctx, &mut self.textures);
        }
        count
    }

    /// A free place for a texture of `kind`, evicting the least recently used patches if none is left, and
    /// waiting for the frames in flight when the evicted places are still theirs (only when the cache is full).
    fn texture_place(&mut self, kind: TextureKind) -> Result<SlotLayer, GpuError> {
        let ctx = self.ctx;
        if let Some(place) = self.textures.allocate(ctx, &mut self.bindless, kind)? {
            return Ok(place);
        }
        self.evict_patches(self.cache.capacity);
        if let Some(place) = self.textures.allocate(ctx, &mut self.bindless, kind)? {
            return Ok(place);
        }
        if self.textures.pending_release() > 0 {
            let finished = self.frames.drain(ctx)?;
            self.collect(finished)?;
        }
        self.textures
            .allocate(ctx, &mut self.bindless, kind)?
            .ok_or_else(|| {
                GpuError::Invalid(format!(
                    "all {} patch textures are in use; raise max-resident-patches or lower new-patches-per-frame",
                    self.cache.capacity + SPARE_TEXTURES
                ))
            })
    }
}
