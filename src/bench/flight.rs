//! `riverplanet bench flight`: the scripted flight, rendered headless, with per-frame patches, samples, stage
//! times, GPU pass times and memory (Figures 9.1-9.8); every frame's new river patches also run through all four
//! kernel variants so they compare like for like; and the same flight in each water mode.

use std::{cell::RefCell, collections::BTreeMap, rc::Rc};

use serde::Serialize;

use super::{
    holes::{hole_check_clear, Holes},
    kernel::VariantRunner,
    path::Flight,
    Threads,
};
use crate::{
    config::Config,
    gpu::{Access, Context, GpuError},
    kernel::{gpu::autotune, KernelParams, PatchJob, RiverSample},
    render::{
        target::{Offscreen, COLOR_FORMAT, DEPTH_FORMAT},
        FrameStats, GpuTimes, Renderer, WaterMode,
    },
    world::World,
};

/// One frame's kernel input, owned: (vertex spacing, samples) per new patch with rivers.
type KernelInput = Vec<(f32, Vec<RiverSample>)>;

/// The four kernel variants on one frame's new river patches (ms).
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct FrameKernels {
    /// The CPU reference on one thread.
    pub cpu_single_ms: f64,
    /// The CPU reference on rayon's threads.
    pub cpu_rayon_ms: f64,
    /// The simple GPU kernel's dispatches (timestamp queries).
    pub gpu_simple_ms: f64,
    /// The tiled GPU kernel's dispatches (timestamp queries).
    pub gpu_tiled_ms: f64,
    /// The simple kernel with the upload, the read-back and its decoding (docs/kernel.md).
    pub gpu_simple_end_to_end_ms: f64,
    /// The tiled kernel with the upload, the read-back and its decoding.
    pub gpu_tiled_end_to_end_ms: f64,
}

/// One frame of a flight.
#[derive(Clone, Debug, Serialize)]
pub struct FlightFrame {
    /// The camera's height above the sphere (not the ground).
    pub altitude: f64,
    /// What the renderer reports of the frame.
    #[serde(flatten)]
    pub stats: FrameStats,
    /// The kernel variants on the frame's new river patches, where compared.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kernels: Option<FrameKernels>,
    /// Pixels inside the planet's disc that no surface covered (the descent checks every tenth frame).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hole_pixels: Option<usize>,
    /// Whether the frame's time is the renderer's alone. Not for a frame at which the benchmark waited for the GPU
    /// (a kernel comparison, a hole check, the end of the flight): its time holds the frames in flight before it;
    /// nor for the frames in flight after it, which start with an empty queue and then wait for each other.
    pub paced: bool,
}

/// Averages and maxima over a flight.
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct FlightSummary {
    /// Frames flown.
    pub frames: usize,
    /// Mean frame time, every frame.
    pub frame_ms_mean: f64,
    /// Triangles the terrain pass drew per frame, on average.
    pub triangles_mean: f64,
    /// Median of the paced frames ([`FlightFrame::paced`]), warm-up included.
    pub frame_ms_median: f64,
    /// Slowest frame of all, paced or not.
    pub frame_ms_max: f64,
    /// 1000 over `frame_ms_mean`.
    pub average_fps: f64,
    /// Patches drawn per frame, on average and at most.
    pub average_visible_patches: f64,
    /// See `average_visible_patches`.
    pub max_visible_patches: usize,
    /// Patches given river data per frame, on average and at most.
    pub average_new_patches: f64,
    /// See `average_new_patches`.
    pub max_new_patches: usize,
    /// River samples given to the kernel per frame (6.4), on average and at most.
    pub average_samples: f64,
    /// See `average_samples`.
    pub max_samples: usize,
    /// Largest memory of any frame: patch textures, temporary sample data and the precomputed heights.
    pub max_memory_bytes: u64,
    /// Largest bytes of resident patch textures.
    pub max_patch_texture_bytes: u64,
    /// Largest bytes of one frame's sample buffers.
    pub max_temporary_sample_bytes: u64,
    /// Most patches resident at once, and the budget they are held to (`max-resident-patches`,
    /// `resident-memory-mb`).
    pub max_resident_patches: usize,
    /// See `max_resident_patches`.
    pub resident_patch_budget: usize,
    /// GPU time per pass (timestamp queries) and CPU time per stage, averaged over the frames, ms.
    pub average_gpu_ms: BTreeMap<String, f64>,
    /// See `average_gpu_ms`.
    pub average_cpu_ms: BTreeMap<String, f64>,
    /// Fragment shader invocations per pixel of the target, per pass, averaged over the frames that counted
    /// them (pipeline statistics queries; empty where the device has none): how often a pass shades a pixel,
    /// its overdraw and the helper invocations of partly covered quads together.
    pub fragments_per_pixel: BTreeMap<String, f64>,
    /// Frames with new river patches whose kernels were compared.
    pub kernel_frames: usize,
    /// Over those frames: average time of each kernel variant (ms), as Tables 9.1 and 9.2.
    pub kernel_average_ms: BTreeMap<String, f64>,
    /// Ratios of those averages, named `A_over_B`.
    pub kernel_ratios: BTreeMap<String, f64>,
    /// Average frame time of the same flight in each water mode.
    pub water_mode_frame_ms: BTreeMap<String, f64>,
    /// The finest level drawn with its own data in any frame.
    #[serde(default)]
    pub deepest_level: u32,
    /// Largest memory of any frame (patch textures, temporary data, precomputed heights), as `max_memory_bytes`.
    #[serde(default)]
    pub peak_memory_bytes: u64,
    /// Slowest paced frame after the first [`WARMUP_FRAMES`] (start-up: pipelines, the first patches).
    #[serde(default)]
    pub frame_ms_max_after_warmup: f64,
    /// Frames whose time is the renderer's alone: what the median and the slowest frame after warm-up cover.
    #[serde(default)]
    pub paced_frames: usize,
    /// Patches made per frame (base heights refined or cut, river data computed), at most.
    #[serde(default)]
    pub max_generated_patches: usize,
    /// Frames checked for holes, and hole pixels found in all of them.
    #[serde(default)]
    pub hole_checked_frames: usize,
    /// See `hole_checked_frames`.
    #[serde(default)]
    pub hole_pixels: usize,
}

/// The descent checks every this many frames for holes.
pub const HOLE_CHECK_EVERY: u32 = 10;

/// Frames not counted in `frame_ms_max_after_warmup`.
pub const WARMUP_FRAMES: usize = 10;

/// What `bench flight` writes: the setup, every frame, and the summary.
#[derive(Clone, Debug, Serialize)]
pub struct FlightReport {
    /// The Vulkan device's name and its driver's name and version.
    pub device: String,
    /// See `device`.
    pub driver: String,
    /// The thread counts the flight ran with (lavapipe's and rayon's).
    pub threads: Threads,
    /// The thesis's stress test ([`FlightOptions::stress`]).
    pub stress: bool,
    /// The descent to the ground ([`FlightOptions::descent`]).
    pub descent: bool,
    /// Whether the flight replayed a recorded camera path.
    pub recorded_path: bool,
    /// The renderer's switches the flight ran with (each can be turned off for comparison).
    pub morphing: bool,
    /// See `morphing`.
    pub parent_reuse: bool,
    /// Frames the CPU may record ahead of the GPU.
    pub frames_in_flight: usize,
    /// See `morphing`.
    pub atmosphere: bool,
    /// See `morphing`.
    pub vertex_cache: bool,
    /// See `morphing`.
    pub water_in_mesh: bool,
    /// The level-of-detail rule.
    pub lod_rule: crate::config::LodRule,
    /// The river model of the planet flown over.
    pub river_model: crate::config::RiverModel,
    /// The planet's radius and seed.
    pub radius: f64,
    /// See `radius`.
    pub seed: u32,
    /// Width and height of the frames, pixels.
    pub resolution: [u32; 2],
    /// Eq. 6.1's switch factor used.
    pub switch_factor: f32,
    /// Every frame.
    pub frames: Vec<FlightFrame>,
    /// Frame time per frame of the flights in the other water modes.
    pub water_mode_frames: BTreeMap<String, Vec<f64>>,
    /// Averages and maxima over the frames.
    pub summary: FlightSummary,
}

/// Options of a flight.
#[derive(Clone, Debug)]
pub struct FlightOptions {
    /// Frames to fly.
    pub frames: u32,
    /// The thesis's stress test: switch factor x10 and camera x25 (overrides `speed`).
    pub stress: bool,
    /// Camera speed factor.
    pub speed: f64,
    /// Width and height of the frames, pixels.
    pub size: [u32; 2],
    /// Run every frame's new river patches through all four kernel variants.
    pub compare_kernels: bool,
    /// Fly again in the geometry and painted water modes.
    pub compare_water_modes: bool,
    /// Fly the descent to the ground instead of the thesis's path.
    pub descent: bool,
    /// Replay a recorded camera path instead (`frames` of it).
    pub path: Option<crate::runtime::camera_path::CameraPath>,
    /// Where to write the images of frames the hole check fails on (`holes-FRAME.png`).
    pub hole_images: Option<std::path::PathBuf>,
    /// Nearest-point selection with morphing (`false`: the thesis's Eq. 6.1 and instant switching).
    pub morphing: bool,
    /// River data from the parent patch where it has the final detail (`false`: from scratch, as the thesis).
    pub parent_reuse: bool,
    /// Where to write every checked frame of the descent (`frame-FRAME.png`, with its altitude in the report).
    pub frame_images: Option<std::path::PathBuf>,
    /// Frames the CPU may record ahead of the GPU (1: the thesis's wait for every frame).
    pub frames_in_flight: usize,
    /// The level-of-detail rule instead of the configuration's.
    pub lod_rule: Option<crate::config::LodRule>,
    /// The atmosphere (`false`: the constant haze).
    pub atmosphere: bool,
    /// The vertex cache (`false`: vertices computed in the vertex shaders, as the thesis).
    pub vertex_cache: bool,
    /// The water drawn by the terrain pass (`false`: the thesis's water pass).
    pub water_in_mesh: bool,
}

impl FlightOptions {
    /// The level-of-detail rule of the flight (`LodRule::for_run`).
    fn rule(&self, config: &Config) -> crate::config::LodRule {
        crate::config::LodRule::for_run(
            self.lod_rule,
            self.morphing,
            config.rendering.level_of_detail_rule,
        )
    }
}

/// The configuration of a flight: the thesis's stress test multiplies the switch factor by ten.
pub fn flight_config(config: &Config, stress: bool) -> Config {
    let mut c = config.clone();
    if stress {
        c.rendering.level_of_detail_switch_factor *= 10.0;
    }
    c
}

fn fly(
    ctx: &Context,
    world: &World,
    config: &Config,
    options: &FlightOptions,
    water: WaterMode,
    mut runner: Option<&mut VariantRunner>,
    mut progress: impl FnMut(u32),
) -> Result<Vec<FlightFrame>, GpuError> {
    let [w, h] = options.size;
    let target = Offscreen::new(ctx, w, h)?;
    let mut renderer = Renderer::new(
        ctx,
        &world.planet,
        &world.network,
        config,
        COLOR_FORMAT,
        DEPTH_FORMAT,
    )?;
    renderer.water_mode = water;
    renderer.morphing = options.morphing;
    renderer.parent_reuse = options.parent_reuse;
    renderer.atmosphere_on = options.atmosphere;
    renderer.cache_vertices = options.vertex_cache;
    renderer.water_in_mesh = options.water_in_mesh;
    renderer.set_frames_in_flight(options.frames_in_flight)?;
    renderer.lod_rule = options.rule(config);
    // Each frame's kernel input, to rerun through every variant.
    let kernel_input: Rc<RefCell<KernelInput>> = Rc::default();
    if runner.is_some() {
        let sink = Rc::clone(&kernel_input);
        renderer.observe_kernel_input(Box::new(move |jobs| {
            *sink.borrow_mut() = jobs
                .iter()
                .map(|j| (j.spacing, j.samples.to_vec()))
                .collect();
        }));
    }
    let params = KernelParams::from_config(config);
    let speed = if options.stress { 25.0 } else { options.speed };
    let aspect = w as f64 / h as f64;
    let flight = if let Some(path) = &options.path {
        Flight::recorded(world, path.clone(), aspect)
    } else if options.descent {
        Flight::descent(world, options.frames, aspect).ok_or_else(|| {
            GpuError::Invalid("the descent needs a river, and this planet has none".into())
        })?
    } else {
        Flight::new(world, options.frames, speed, aspect)
    };
    let mut frames = Vec::with_capacity(options.frames as usize);
    // Below the lowest height anything is drawn at: rays hitting this sphere must hit terrain or water.
    let inner = world.planet.radius + world.planet.height_bounds().0 as f64
        - config.river.basin_depth as f64
        - 1.0;
    // The last frame at which the benchmark waited for the GPU.
    let mut waited_at: Option<u32> = None;
    let in_flight = options.frames_in_flight as u32;
    let result = (|| {
        for frame in 0..options.frames {
            let camera = flight.camera(world, frame);
            // The water flows as it would at 30 frames a second.
            renderer.time = frame as f32 / 30.0;
            let start = std::time::Instant::now();
            let mut stats = renderer.render(
                &camera,
                &target.target(hole_check_clear(crate::render::SPACE)),
                Access::ColorAttachment,
                &[],
                &[],
            )?;
            let input = kernel_input.take();
            let compare = runner.is_some() && !input.is_empty();
            let check_holes = options.descent && frame % HOLE_CHECK_EVERY == 0;
            if compare || check_holes {
                // The benchmark's own work waits for the GPU; the wait for this frame is the frame's.
                renderer.finish()?;
                stats.frame_ms = start.elapsed().as_secs_f64() * 1e3;
                waited_at = Some(frame);
            }
            let paced = waited_at.is_none_or(|w| frame > w + in_flight + 1);
            let kernels = match (&mut runner, input.is_empty()) {
                (Some(runner), false) => {
                    let jobs = PatchJob::from_pairs(&input);
                    let (v, _, _) = runner.measure(ctx, &jobs, &params, 1, false)?;
                    Some(FrameKernels {
                        cpu_single_ms: v.cpu_single.kernel_ms,
                        cpu_rayon_ms: v.cpu_rayon.kernel_ms,
                        gpu_simple_ms: v.gpu_simple.kernel_ms,
                        gpu_tiled_ms: v.gpu_tiled.kernel_ms,
                        gpu_simple_end_to_end_ms: v.gpu_simple.end_to_end_ms.unwrap_or(0.0),
                        gpu_tiled_end_to_end_ms: v.gpu_tiled.end_to_end_ms.unwrap_or(0.0),
                    })
                }
                _ => None,
            };
            let hole_pixels = if check_holes {
                let image = target.read(ctx)?;
                let holes = Holes::find(&image, &camera, inner);
                let hole_dir = options.hole_images.as_ref().filter(|_| holes.count() > 0);
                let saves = [
                    (hole_dir, format!("holes-{frame:03}.png")),
                    (
                        options.frame_images.as_ref(),
                        format!("frame-{frame:03}.png"),
                    ),
                ];
                // The picture is made once, and only when a file wants it.
                let mut shown = None;
                for (dir, name) in saves {
                    if let Some(dir) = dir {
                        let picture = shown.get_or_insert_with(|| holes.shown_on(&image));
                        crate::export::files::save_image(picture, &dir.join(name))
                            .map_err(|e| GpuError::Invalid(e.to_string()))?;
                    }
                }
                Some(holes.count())
            } else {
                None
            };
            let altitude = camera.position.length() - world.planet.radius;
            frames.push(FlightFrame {
                altitude,
                stats: FrameStats {
                    gpu_ms: BTreeMap::new(),
                    gpu_fragments: BTreeMap::new(),
                    ..stats
                },
                kernels,
                hole_pixels,
                paced,
            });
            attribute_gpu_times(&mut frames, renderer.take_gpu_times());
            progress(frame);
        }
        // The frames still in flight end the flight: their wait is the last frame's.
        let start = std::time::Instant::now();
        renderer.finish()?;
        if let Some(last) = frames.last_mut() {
            last.stats.frame_ms += start.elapsed().as_secs_f64() * 1e3;
            last.paced = false;
        }
        attribute_gpu_times(&mut frames, renderer.take_gpu_times());
        Ok(())
    })();
    result.map(|()| frames)
}

/// Per pass, the mean of its fragment shader invocations over `pixels` across the frames that counted them.
fn fragments_per_pixel(stats: &[&FrameStats], pixels: u64) -> BTreeMap<String, f64> {
    let names: std::collections::BTreeSet<&String> =
        stats.iter().flat_map(|s| s.gpu_fragments.keys()).collect();
    names
        .into_iter()
        .map(|name| {
            let per_pixel = stats
                .iter()
                .filter_map(|s| s.gpu_fragments.get(name))
                .map(|&count| count as f64 / pixels.max(1) as f64);
            (name.clone(), mean(per_pixel))
        })
        .collect()
}

/// Puts each finished frame's GPU times into its own frame's statistics: they arrive one or two frames late.
fn attribute_gpu_times(frames: &mut [FlightFrame], times: Vec<GpuTimes>) {
    for t in times {
        if let Some(f) = frames.iter_mut().rev().find(|f| f.stats.frame == t.frame) {
            f.stats.gpu_ms = t.ms;
            f.stats.gpu_fragments = t.fragments;
            f.stats.gpu_frame = t.frame;
        }
    }
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 {
        0.0
    } else {
        sum / n as f64
    }
}

fn summarise(frames: &[FlightFrame], budget: usize, pixels: u64) -> FlightSummary {
    let stats: Vec<&FrameStats> = frames.iter().map(|f| &f.stats).collect();
    let frame_ms: Vec<f64> = stats.iter().map(|s| s.frame_ms).collect();
    let frame_ms_mean = mean(frame_ms.iter().copied());
    // The frames whose time is the renderer's alone, and those of them after warm-up.
    let paced_ms: Vec<f64> = frames
        .iter()
        .filter(|f| f.paced)
        .map(|f| f.stats.frame_ms)
        .collect();
    let paced_after_warmup = frames
        .iter()
        .skip(WARMUP_FRAMES)
        .filter(|f| f.paced)
        .map(|f| f.stats.frame_ms);
    let keys = |f: &dyn Fn(&FrameStats) -> &BTreeMap<String, f64>| {
        let names: std::collections::BTreeSet<&String> =
            stats.iter().flat_map(|s| f(s).keys()).collect();
        names
            .into_iter()
            .map(|k| {
                (
                    k.clone(),
                    mean(stats.iter().map(|s| f(s).get(k).copied().unwrap_or(0.0))),
                )
            })
            .collect::<BTreeMap<_, _>>()
    };
    let kernel_frames: Vec<&FrameKernels> =
        frames.iter().filter_map(|f| f.kernels.as_ref()).collect();
    let mut kernel_average_ms = BTreeMap::new();
    for (name, get) in [
        (
            "cpu_single",
            (|k: &FrameKernels| k.cpu_single_ms) as fn(&FrameKernels) -> f64,
        ),
        ("cpu_rayon", |k| k.cpu_rayon_ms),
        ("gpu_simple", |k| k.gpu_simple_ms),
        ("gpu_tiled", |k| k.gpu_tiled_ms),
        ("gpu_simple_end_to_end", |k| k.gpu_simple_end_to_end_ms),
        ("gpu_tiled_end_to_end", |k| k.gpu_tiled_end_to_end_ms),
    ] {
        kernel_average_ms.insert(name.to_string(), mean(kernel_frames.iter().map(|k| get(k))));
    }
    let avg = |k: &str| kernel_average_ms.get(k).copied().unwrap_or(0.0);
    // Each ratio of two variants' averages, named after them.
    let kernel_ratios: BTreeMap<String, f64> = [
        ("tiled_over_simple", "gpu_tiled", "gpu_simple"),
        ("cpu_single_over_gpu_tiled", "cpu_single", "gpu_tiled"),
        (
            "cpu_single_over_gpu_tiled_end_to_end",
            "cpu_single",
            "gpu_tiled_end_to_end",
        ),
        ("cpu_single_over_cpu_rayon", "cpu_single", "cpu_rayon"),
    ]
    .into_iter()
    .filter(|_| !kernel_frames.is_empty())
    .map(|(name, over, under)| (name.to_string(), avg(over) / avg(under)))
    .collect();
    let max_memory_bytes = stats.iter().map(|s| s.memory_bytes).max().unwrap_or(0);
    FlightSummary {
        frames: frames.len(),
        frame_ms_mean,
        triangles_mean: mean(stats.iter().map(|s| s.terrain_triangles as f64)),
        frame_ms_median: super::median(&paced_ms),
        deepest_level: stats.iter().map(|s| s.deepest_level).max().unwrap_or(0),
        peak_memory_bytes: max_memory_bytes,
        frame_ms_max_after_warmup: paced_after_warmup.fold(0.0, f64::max),
        paced_frames: paced_ms.len(),
        max_generated_patches: stats.iter().map(|s| s.new_patches).max().unwrap_or(0),
        hole_checked_frames: frames.iter().filter(|f| f.hole_pixels.is_some()).count(),
        hole_pixels: frames.iter().filter_map(|f| f.hole_pixels).sum(),
        frame_ms_max: frame_ms.iter().copied().fold(0.0, f64::max),
        average_fps: if frame_ms_mean > 0.0 {
            1000.0 / frame_ms_mean
        } else {
            0.0
        },
        average_visible_patches: mean(stats.iter().map(|s| s.visible_patches as f64)),
        max_visible_patches: stats.iter().map(|s| s.visible_patches).max().unwrap_or(0),
        average_new_patches: mean(stats.iter().map(|s| s.new_patches as f64)),
        max_new_patches: stats.iter().map(|s| s.new_patches).max().unwrap_or(0),
        average_samples: mean(stats.iter().map(|s| s.samples as f64)),
        max_samples: stats.iter().map(|s| s.samples).max().unwrap_or(0),
        max_memory_bytes,
        max_patch_texture_bytes: stats
            .iter()
            .map(|s| s.patch_texture_bytes)
            .max()
            .unwrap_or(0),
        max_temporary_sample_bytes: stats
            .iter()
            .map(|s| s.temporary_sample_bytes)
            .max()
            .unwrap_or(0),
        max_resident_patches: stats.iter().map(|s| s.resident_patches).max().unwrap_or(0),
        resident_patch_budget: budget,
        average_gpu_ms: keys(&|s| &s.gpu_ms),
        average_cpu_ms: keys(&|s| &s.cpu_ms),
        fragments_per_pixel: fragments_per_pixel(&stats, pixels),
        kernel_frames: kernel_frames.len(),
        kernel_average_ms,
        kernel_ratios,
        water_mode_frame_ms: BTreeMap::new(),
    }
}

/// Flies the scripted path and reports every frame. `progress` is told each finished frame.
pub fn flight_bench(
    ctx: &Context,
    world: &World,
    options: &FlightOptions,
    mut progress: impl FnMut(&str, u32),
) -> Result<FlightReport, GpuError> {
    let config = flight_config(&world.config, options.stress);
    let n = config.rendering.vertices;
    let mut runner = if options.compare_kernels {
        Some(VariantRunner::new(
            ctx,
            config.rendering.new_patches_per_frame as usize + 8,
            n,
            autotune::tuned(ctx, n)?.tuning,
        )?)
    } else {
        None
    };
    let frames = fly(
        ctx,
        world,
        &config,
        options,
        WaterMode::Auto,
        runner.as_mut(),
        |f| progress("auto", f),
    );
    let frames = frames?;
    let pixels = options.size[0] as u64 * options.size[1] as u64;
    let mut summary = summarise(
        &frames,
        config.rendering.max_resident_patches as usize,
        pixels,
    );
    summary
        .water_mode_frame_ms
        .insert("auto".into(), summary.frame_ms_mean);
    let mut water_mode_frames = BTreeMap::new();
    if options.compare_water_modes {
        for (name, mode) in [
            ("geometry", WaterMode::Geometry),
            ("painted", WaterMode::Painted),
        ] {
            let other = fly(ctx, world, &config, options, mode, None, |f| {
                progress(name, f)
            })?;
            let times: Vec<f64> = other.iter().map(|f| f.stats.frame_ms).collect();
            summary
                .water_mode_frame_ms
                .insert(name.into(), mean(times.iter().copied()));
            water_mode_frames.insert(name.to_string(), times);
        }
    }
    Ok(FlightReport {
        device: ctx.adapter.name.clone(),
        driver: format!("{} {}", ctx.adapter.driver_name, ctx.adapter.driver_info),
        threads: Threads::current(),
        stress: options.stress,
        descent: options.descent,
        recorded_path: options.path.is_some(),
        morphing: options.morphing,
        atmosphere: options.atmosphere,
        vertex_cache: options.vertex_cache,
        water_in_mesh: options.water_in_mesh,
        parent_reuse: options.parent_reuse,
        frames_in_flight: options.frames_in_flight,
        lod_rule: options.rule(&config),
        river_model: config.river.model,
        radius: world.planet.radius,
        seed: world.seed,
        resolution: options.size,
        switch_factor: config.rendering.level_of_detail_switch_factor,
        frames,
        water_mode_frames,
        summary,
    })
}

/// One CSV row per frame.
pub fn to_csv(report: &FlightReport) -> String {
    let mut out = String::from(
        "frame,altitude,visible_patches,new_patches,river_patches,fallback_patches,samples,frame_ms,gpu_kernel_ms,\
         gpu_terrain_ms,gpu_water_ms,memory_bytes,patch_texture_bytes,temporary_sample_bytes,resident_patches,\
         cpu_single_ms,cpu_rayon_ms,gpu_simple_ms,gpu_tiled_ms,paced,cpu_cull_ms,cpu_lod_ms,cpu_samples_ms,\
         cpu_wait_ms,cpu_upload_ms,cpu_record_ms,cpu_submit_ms,terrain_fragments_per_pixel\n",
    );
    let pixels = (report.resolution[0] as u64 * report.resolution[1] as u64).max(1);
    for f in &report.frames {
        let s = &f.stats;
        let g = |k: &str| s.gpu_ms.get(k).copied().unwrap_or(0.0);
        let c = |k: &str| s.cpu_ms.get(k).copied().unwrap_or(0.0);
        let k = f.kernels.clone().unwrap_or_default();
        let fragments = s.gpu_fragments.get("terrain").map_or(String::new(), |&n| {
            format!("{:.3}", n as f64 / pixels as f64)
        });
        out.push_str(&format!(
            "{},{:.3},{},{},{},{},{},{:.3},{:.4},{:.3},{:.3},{},{},{},{},{:.4},{:.4},{:.4},{:.4},{},{:.3},{:.3},{:.3},\
             {:.3},{:.3},{:.3},{:.3},{}\n",
            s.frame,
            f.altitude,
            s.visible_patches,
            s.new_patches,
            s.river_patches,
            s.fallback_patches,
            s.samples,
            s.frame_ms,
            g("kernel"),
            g("terrain"),
            g("water"),
            s.memory_bytes,
            s.patch_texture_bytes,
            s.temporary_sample_bytes,
            s.resident_patches,
            k.cpu_single_ms,
            k.cpu_rayon_ms,
            k.gpu_simple_ms,
            k.gpu_tiled_ms,
            f.paced as u8,
            c("cull"),
            c("lod"),
            c("influence+samples"),
            c("frame wait"),
            c("upload"),
            c("record"),
            c("submit"),
            fragments,
        ));
    }
    out
}
