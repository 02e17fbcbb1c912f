//! The `riverplanet` command line.

use std::{path::PathBuf, process::ExitCode};

use clap::{Parser, Subcommand};
use riverplanet::{
    bench,
    config::Config,
    gpu::{self, Context, ContextOptions},
    kernel::gpu::KernelTuning,
    render::{ViewMode, WaterMode},
};

#[derive(Parser)]
#[command(
    name = "riverplanet",
    version,
    about = "River networks on procedural planets, rendered with Vulkan"
)]
struct Cli {
    /// Use the first Vulkan device whose name contains this text.
    #[arg(long, global = true, env = "RIVERPLANET_ADAPTER")]
    adapter: Option<String>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Show the Vulkan instance, every device, the chosen one and each required feature; fails if none is usable.
    Info {
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Print the resolved configuration of FILE (exit code 2 if it is invalid).
    Config { file: PathBuf },
    /// Generate the planet: per-face heightmaps, statistics and (with --preview) an unfolded picture.
    Generate {
        #[arg(long, default_value = "config/planet.xml")]
        config: PathBuf,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// Override master-seed.
        #[arg(long)]
        seed: Option<u32>,
        /// Also write DIR/preview.png, the six faces unfolded.
        #[arg(long)]
        preview: bool,
        /// Also write DIR/continents.png, land and sea as an equirectangular image (input for continents-from-file).
        #[arg(long)]
        equirect: bool,
        /// Level of detail of the face images (32 x 2^N + 1 pixels per edge with 33 vertices), made by the same
        /// on-demand refinement as the renderer's patches. Default: 6, or max-level-of-detail if lower.
        #[arg(long)]
        level: Option<u32>,
    },
    /// Render one image headless (no display, no window system) and print per-pass GPU times.
    Render(RenderArgs),
    /// Open the interactive viewer (needs a display; see the README for keys).
    View(ViewArgs),
    /// Draw the figures of Chapter 9 (SVG and PNG) from `bench flight` JSON reports.
    Plot {
        /// Report of the normal flight.
        #[arg(long)]
        flight: PathBuf,
        /// Report of the stress flight.
        #[arg(long)]
        stress: Option<PathBuf>,
        #[arg(long)]
        out: PathBuf,
    },
    /// Write docs/results.md from the JSON reports of `bench kernel` and `bench flight` (see tools/results).
    Report {
        #[arg(long)]
        kernel: PathBuf,
        #[arg(long)]
        kernel_stress: PathBuf,
        #[arg(long)]
        flight: PathBuf,
        #[arg(long)]
        flight_stress: PathBuf,
        #[arg(long)]
        long_flight: Option<PathBuf>,
        /// The report of `bench kernel --parent-reuse`.
        #[arg(long)]
        kernel_reuse: Option<PathBuf>,
        /// Reports of `bench flight --descent` (repeat the option for several).
        #[arg(long)]
        descent: Vec<PathBuf>,
        /// A file with the commands that made the reports (quoted in the document).
        #[arg(long)]
        commands: PathBuf,
        #[arg(long)]
        out: PathBuf,
    },
    /// Measure the river kernel variants side by side in one run.
    Bench {
        #[command(subcommand)]
        what: BenchCommand,
    },
}

#[derive(clap::Args)]
struct RenderArgs {
    #[arg(long, default_value = "config/planet.xml")]
    config: PathBuf,
    /// Override master-seed.
    #[arg(long)]
    seed: Option<u32>,
    /// Camera position, world units with the planet centre at the origin.
    #[arg(long, value_parser = parse_vec3, default_value = "0,1200,3400", allow_hyphen_values = true)]
    eye: glam::DVec3,
    #[arg(long, value_parser = parse_vec3, default_value = "0,0,0", allow_hyphen_values = true)]
    look_at: glam::DVec3,
    /// Place the camera from the planet's own features instead of --eye/--look-at: `orbit` (the first river's
    /// side of the planet), `mountains` (above the first river's source), `river` (close above the first river).
    #[arg(long, value_enum, conflicts_with_all = ["eye", "look_at"])]
    preset: Option<riverplanet::render::presets::Preset>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 45.0)]
    fov: f64,
    #[arg(long, value_parser = parse_size, default_value = "1280x720")]
    size: [u32; 2],
    #[arg(long, value_enum, default_value = "auto")]
    water: WaterMode,
    #[arg(long, value_enum, default_value = "shaded")]
    view: ViewMode,
    #[arg(long, value_enum, default_value = "tiled")]
    kernel: riverplanet::kernel::gpu::KernelVariant,
    /// The thesis's level of detail: Eq. 6.1 on patch centres and instant switching, instead of nearest-point
    /// selection with morphing.
    #[arg(long)]
    no_morphing: bool,
    #[arg(long, value_parser = parse_vec3, default_value = "0.02,0.03,0.06", allow_hyphen_values = true)]
    clear_color: glam::DVec3,
    /// Frames to run at most while patch data streams in (the image is taken when nothing is pending).
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(1..))]
    max_frames: u32,
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct ViewArgs {
    #[arg(long, default_value = "config/planet.xml")]
    config: PathBuf,
    #[arg(long)]
    seed: Option<u32>,
    #[arg(long, value_parser = parse_size, default_value = "1280x720")]
    size: [u32; 2],
    /// Start position (default: the orbit preset).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    eye: Option<glam::DVec3>,
    #[arg(long, value_parser = parse_vec3, default_value = "0,0,0", allow_hyphen_values = true)]
    look_at: glam::DVec3,
    #[arg(long, value_enum, default_value = "auto")]
    water: WaterMode,
    /// Run this many frames, then exit (with --screenshot, write it first).
    #[arg(long)]
    frames: Option<u64>,
    #[arg(long)]
    screenshot: Option<PathBuf>,
}

#[derive(Subcommand)]
enum BenchCommand {
    /// CPU single-thread, CPU rayon, GPU simple and GPU tiled on identical input (Tables 9.1/9.2): every river
    /// patch the scripted flight meets, as one batch.
    Kernel {
        #[arg(long, default_value = "config/planet.xml")]
        config: PathBuf,
        #[arg(long, default_value_t = 1)]
        seed: u32,
        /// The thesis's stress test: switch factor x10, camera x25.
        #[arg(long)]
        stress: bool,
        /// Frames of the flight that produces the workload.
        #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u32).range(1..))]
        frames: u32,
        /// Compare river data taken from the parent patch (10.2) with computing from scratch, on the patches of
        /// the descent to the ground whose parents have the rivers' final detail (use config/earth.xml).
        #[arg(long, conflicts_with = "stress")]
        parent_reuse: bool,
        /// Repetitions per variant (the median is reported).
        #[arg(long, default_value_t = 5, value_parser = positive_count)]
        repetitions: usize,
        /// Invocations per workgroup of the simple kernel.
        #[arg(long, default_value_t = KernelTuning::default().simple_workgroup)]
        simple_workgroup: u32,
        /// Vertex block per workgroup of the tiled kernel, as WxH [default: 8x4, KernelTuning::default()].
        #[arg(long, value_parser = parse_block)]
        tiled_block: Option<[u32; 2]>,
        /// Samples staged per tile by the tiled kernel.
        #[arg(long, default_value_t = KernelTuning::default().tile_size)]
        tile_size: u32,
        /// Write the report here as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
    },
    /// The scripted flight from orbit to the surface, rendered headless, with per-frame statistics (Chapter 9).
    Flight {
        #[arg(long, default_value = "config/planet.xml")]
        config: PathBuf,
        #[arg(long, default_value_t = 1)]
        seed: u32,
        /// The thesis's stress test: switch factor x10, camera x25.
        #[arg(long)]
        stress: bool,
        /// Fly the descent from three radii out to two world units above the first river's water (the ground
        /// preset) instead of the thesis's path.
        #[arg(long, conflicts_with = "stress")]
        descent: bool,
        /// With --descent: write the frames whose hole check fails to DIR/holes-FRAME.png.
        #[arg(long, requires = "descent")]
        hole_images: Option<PathBuf>,
        /// With --descent: write every tenth frame (those checked for holes) to DIR/frame-FRAME.png.
        #[arg(long, requires = "descent")]
        frame_images: Option<PathBuf>,
        /// The thesis's level of detail: Eq. 6.1 on patch centres and instant switching.
        #[arg(long)]
        no_morphing: bool,
        /// Compute every patch's river data from scratch, as the thesis (no data from the parent, 10.2).
        #[arg(long)]
        no_parent_reuse: bool,
        #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u32).range(1..))]
        frames: u32,
        /// Camera speed factor (the stress test uses 25).
        #[arg(long, default_value_t = 1.0, value_parser = positive_number, allow_hyphen_values = true)]
        speed: f64,
        #[arg(long, value_parser = parse_size, default_value = "1280x720")]
        size: [u32; 2],
        /// Skip rerunning each frame's kernel input through all four variants.
        #[arg(long)]
        no_kernel_comparison: bool,
        /// Skip the flights in the geometry and painted water modes.
        #[arg(long)]
        no_water_comparison: bool,
        #[arg(long)]
        json: PathBuf,
        /// Leave the per-frame records out of the JSON (for very long flights).
        #[arg(long)]
        summary_only: bool,
        #[arg(long)]
        csv: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let mut options = ContextOptions::from_env();
    if cli.adapter.is_some() {
        options.adapter = cli.adapter.clone();
    }
    match cli.command {
        Command::Info { json } => info(&options, json),
        Command::Generate {
            config,
            out,
            seed,
            preview,
            equirect,
            level,
        } => match generate(&config, &out, seed, (preview, equirect), level) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e:#}");
                ExitCode::FAILURE
            }
        },
        Command::Render(args) => match render(&options, &args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e:#}");
                ExitCode::FAILURE
            }
        },
        Command::Plot {
            flight,
            stress,
            out,
        } => {
            let mut result = bench::plot::flight_figures(&flight, &out, "", false);
            if let (Ok(names), Some(stress)) = (&mut result, stress) {
                match bench::plot::flight_figures(&stress, &out, "stress_", true) {
                    Ok(more) => names.extend(more),
                    Err(e) => result = Err(e),
                }
            }
            match result {
                Ok(names) => {
                    for n in names {
                        println!("{}", out.join(n).with_extension("png").display());
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::Report {
            kernel,
            kernel_stress,
            flight,
            flight_stress,
            long_flight,
            kernel_reuse,
            descent,
            commands,
            out,
        } => {
            let commands = std::fs::read_to_string(&commands).unwrap_or_default();
            let inputs = bench::report::ReportInputs {
                kernel: &kernel,
                kernel_stress: &kernel_stress,
                flight: &flight,
                flight_stress: &flight_stress,
                long_flight: long_flight.as_deref(),
                kernel_reuse: kernel_reuse.as_deref(),
                descents: &descent,
                commands: &commands,
            };
            match bench::report::results_markdown(&inputs)
                .map(|md| riverplanet::export::files::write_bytes(&out, md.as_bytes()))
            {
                Ok(Ok(())) => ExitCode::SUCCESS,
                Ok(Err(e)) => {
                    eprintln!("error: cannot write {}: {e}", out.display());
                    ExitCode::FAILURE
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Command::View(args) => match view(&options, &args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e:#}");
                ExitCode::FAILURE
            }
        },
        Command::Bench { what } => match run_bench(&options, what) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e:#}");
                ExitCode::FAILURE
            }
        },
        Command::Config { file } => match Config::load(&file) {
            Ok(config) => {
                log::info!("resolved configuration: {config:?}");
                match serde_json::to_string_pretty(&config) {
                    Ok(text) => {
                        println!("{text}");
                        ExitCode::SUCCESS
                    }
                    Err(e) => {
                        eprintln!("error: {e}");
                        ExitCode::FAILURE
                    }
                }
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(2)
            }
        },
    }
}

fn info(options: &ContextOptions, json: bool) -> ExitCode {
    let (version, adapters) = match gpu::context::enumerate(options) {
        Ok(v) => v,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let usable = adapters
        .iter()
        .any(|a| a.chosen && a.features.all_supported());
    if json {
        let value = serde_json::json!({ "instance_version": version, "devices": adapters, "usable": usable });
        println!(
            "{}",
            serde_json::to_string_pretty(&value).unwrap_or_default()
        );
    } else {
        println!("Vulkan instance {version}");
        if adapters.is_empty() {
            println!("no devices");
        }
        for a in &adapters {
            println!(
                "{} {} ({}, Vulkan {}, driver {} {})",
                if a.chosen { "*" } else { "-" },
                a.name,
                a.device_type,
                a.api_version,
                a.driver_name,
                a.driver_info
            );
            for c in &a.features.checks {
                println!(
                    "    {:<48} {}",
                    c.name,
                    if c.supported { "yes" } else { "NO" }
                );
            }
        }
    }
    if usable {
        ExitCode::SUCCESS
    } else {
        let missing = adapters
            .iter()
            .find(|a| a.chosen)
            .map(|a| a.features.missing().join(", "))
            .unwrap_or_else(|| "no device matches".into());
        eprintln!("error: no usable Vulkan device ({missing})");
        ExitCode::FAILURE
    }
}

/// Checks an output path before any work (export::files::check_output).
fn check_output(argument: &str, path: &std::path::Path, png_only: bool) -> anyhow::Result<()> {
    riverplanet::export::files::check_output(argument, path, png_only).map_err(anyhow::Error::msg)
}

fn load_config(path: &std::path::Path) -> anyhow::Result<Config> {
    let config = Config::load(path)?;
    log::info!("resolved configuration: {config:?}");
    Ok(config)
}

fn write_json(path: &std::path::Path, value: &impl serde::Serialize) -> anyhow::Result<()> {
    Ok(riverplanet::export::files::write_bytes(
        path,
        serde_json::to_string_pretty(value)?.as_bytes(),
    )?)
}

fn check_validation(ctx: &Context) -> anyhow::Result<()> {
    let errors = ctx.validation_errors();
    match errors.first() {
        Some(first) => anyhow::bail!("validation reported {} error(s): {first}", errors.len()),
        None => Ok(()),
    }
}

fn run_bench(options: &ContextOptions, what: BenchCommand) -> anyhow::Result<()> {
    match what {
        BenchCommand::Kernel {
            config,
            seed,
            stress,
            frames,
            parent_reuse,
            repetitions,
            simple_workgroup,
            tiled_block,
            tile_size,
            json,
        } => {
            let config = load_config(&config)?;
            if let Some(path) = &json {
                check_output("--json", path, false)?;
            }
            let world = riverplanet::world::World::build(&config, seed)?;
            let ctx = Context::new(options)?;
            let tuning = KernelTuning {
                simple_workgroup,
                tiled_block: tiled_block.unwrap_or(KernelTuning::default().tiled_block),
                tile_size,
            };
            if parent_reuse {
                let report = bench::reuse::reuse_bench(&ctx, &world, frames, repetitions, tuning)?;
                print!("{}", report.summary());
                if let Some(path) = json {
                    write_json(&path, &report)?;
                }
                return Ok(());
            }
            let report =
                bench::kernel::kernel_bench(&ctx, &world, stress, frames, repetitions, tuning)?;
            let v = &report.variants;
            println!(
                "device {} | {} patches, {} samples, {} vertex-sample pairs ({} within reach) | rayon threads {}, \
                 LP_NUM_THREADS {}, RAYON_NUM_THREADS {}",
                report.device,
                report.patches,
                report.samples,
                report.pairs,
                report.relevant_pairs,
                report.threads.rayon_threads_used,
                report.threads.lp_num_threads.as_deref().unwrap_or("unset"),
                report.threads.rayon_num_threads.as_deref().unwrap_or("unset"),
            );
            println!("  cpu single   {:>10.3} ms", v.cpu_single.kernel_ms);
            println!("  cpu rayon    {:>10.3} ms", v.cpu_rayon.kernel_ms);
            for (name, t) in [("gpu simple", &v.gpu_simple), ("gpu tiled", &v.gpu_tiled)] {
                println!(
                    "  {name:<12} {:>10.3} ms kernel, {:>10.3} ms end to end",
                    t.kernel_ms,
                    t.end_to_end_ms.unwrap_or(f64::NAN)
                );
            }
            println!(
                "  tiled/simple {:.3} | cpu single / gpu tiled: {:.2}x kernel, {:.2}x end to end | max |diff| {:.3e} \
                 = {:.2e} of the height range {:?}",
                report.ratios.tiled_over_simple,
                report.ratios.cpu_single_over_gpu_tiled_kernel,
                report.ratios.cpu_single_over_gpu_tiled_end_to_end,
                report.max_abs_diff,
                report.relative_diff,
                report.height_range
            );
            check_validation(&ctx)?;
            if let Some(path) = json {
                write_json(&path, &report)?;
            }
            Ok(())
        }
        BenchCommand::Flight {
            config,
            seed,
            stress,
            descent,
            hole_images,
            frame_images,
            no_morphing,
            no_parent_reuse,
            frames,
            speed,
            size,
            no_kernel_comparison,
            no_water_comparison,
            json,
            summary_only,
            csv,
        } => {
            use std::io::IsTerminal;
            let config = load_config(&config)?;
            for (argument, path) in [("--json", Some(&json)), ("--csv", csv.as_ref())] {
                if let Some(path) = path {
                    check_output(argument, path, false)?;
                }
            }
            for dir in hole_images.iter().chain(&frame_images) {
                std::fs::create_dir_all(dir)
                    .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", dir.display()))?;
            }
            let world = riverplanet::world::World::build(&config, seed)?;
            let ctx = Context::new(options)?;
            let bar = std::io::stderr()
                .is_terminal()
                .then(|| indicatif::ProgressBar::new(frames as u64));
            let options = bench::flight::FlightOptions {
                frames,
                stress,
                speed,
                size,
                compare_kernels: !no_kernel_comparison,
                compare_water_modes: !no_water_comparison,
                descent,
                hole_images,
                frame_images,
                morphing: !no_morphing,
                parent_reuse: !no_parent_reuse,
            };
            let report = bench::flight::flight_bench(&ctx, &world, &options, |mode, frame| {
                if let Some(bar) = &bar {
                    bar.set_message(mode.to_string());
                    bar.set_position(frame as u64 + 1);
                }
            })?;
            if let Some(bar) = bar {
                bar.finish_and_clear();
            }
            let s = &report.summary;
            println!(
                "{} frames at {}x{} on {}{}: {:.1} ms/frame average ({:.1} fps), median {:.1}, max {:.1}",
                s.frames,
                size[0],
                size[1],
                report.device,
                if stress {
                    " (stress)"
                } else if descent {
                    " (descent)"
                } else {
                    ""
                },
                s.average_frame_ms,
                s.average_fps,
                s.median_frame_ms,
                s.max_frame_ms
            );
            println!(
                "  patches: {:.1} visible, {:.2} new per frame (max {}); samples {:.0} per frame (max {})",
                s.average_visible_patches, s.average_new_patches, s.max_new_patches, s.average_samples, s.max_samples
            );
            println!(
                "  memory: max {:.1} MB ({:.1} MB patch textures, {} of {} patches resident; {:.2} MB samples)",
                s.max_memory_bytes as f64 / 1e6,
                s.max_patch_texture_bytes as f64 / 1e6,
                s.max_resident_patches,
                s.resident_patch_budget,
                s.max_temporary_sample_bytes as f64 / 1e6
            );
            println!(
                "  deepest level {}; peak memory {:.1} MB; frame ms median {:.1}, max after {} warm-up frames {:.1}; \
                 at most {} patches made in a frame; {} hole pixels in {} checked frames",
                s.deepest_level,
                s.peak_memory_bytes as f64 / 1e6,
                s.frame_ms_median,
                bench::flight::WARMUP_FRAMES,
                s.frame_ms_max_after_warmup,
                s.max_generated_patches,
                s.hole_pixels,
                s.hole_checked_frames
            );
            println!("  gpu ms per frame: {:?}", s.average_gpu_ms);
            println!("  cpu ms per frame: {:?}", s.average_cpu_ms);
            if s.kernel_frames > 0 {
                println!(
                    "  kernel over {} frames, average ms: {:?}",
                    s.kernel_frames, s.kernel_average_ms
                );
                println!("  kernel ratios: {:?}", s.kernel_ratios);
            }
            println!("  frame ms by water mode: {:?}", s.water_mode_frame_ms);
            check_validation(&ctx)?;
            if let Some(path) = csv {
                riverplanet::export::files::write_bytes(
                    &path,
                    bench::flight::to_csv(&report).as_bytes(),
                )?;
            }
            let mut report = report;
            if summary_only {
                report.frames.clear();
                report.water_mode_frames.clear();
            }
            write_json(&json, &report)?;
            Ok(())
        }
    }
}

fn parse_block(text: &str) -> Result<[u32; 2], String> {
    let (w, h) = text
        .split_once('x')
        .ok_or_else(|| format!("'{text}' is not of the form WxH (e.g. 8x8)"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("'{text}' is not of the form WxH (e.g. 8x8)"))
    };
    Ok([parse(w)?, parse(h)?])
}

/// The finest level `generate` writes face images at (8193 pixels per edge with 33 vertices).
const MAX_FACE_IMAGE_LEVEL: u32 = 8;
/// The level of `generate`'s face images without `--level` (the thesis's finest precomputed level).
const DEFAULT_FACE_IMAGE_LEVEL: u32 = 6;

fn generate(
    config_path: &std::path::Path,
    out: &std::path::Path,
    seed: Option<u32>,
    (preview, equirect): (bool, bool),
    level: Option<u32>,
) -> anyhow::Result<()> {
    use std::io::IsTerminal;
    let config = load_config(config_path)?;
    let deepest = config
        .rendering
        .max_level_of_detail
        .min(MAX_FACE_IMAGE_LEVEL);
    let level = level.unwrap_or(DEFAULT_FACE_IMAGE_LEVEL.min(deepest));
    if level > deepest {
        anyhow::bail!(
            "--level {level} must be in [0, {deepest}] (max-level-of-detail {} of {}; face images stop at \
             level {MAX_FACE_IMAGE_LEVEL}, {} pixels per edge)",
            config.rendering.max_level_of_detail,
            config_path.display(),
            ((config.rendering.vertices - 1) << MAX_FACE_IMAGE_LEVEL) + 1
        );
    }
    let seed = seed.unwrap_or_else(|| config.resolve_seed());
    let bar = if std::io::stderr().is_terminal() {
        let bar = indicatif::ProgressBar::new_spinner();
        bar.enable_steady_tick(std::time::Duration::from_millis(100));
        Some(bar)
    } else {
        None
    };
    let planet = riverplanet::planet::Planet::generate(&config, seed, |stage| {
        if let Some(bar) = &bar {
            bar.set_message(stage.to_string());
        }
    })?;
    if let Some(bar) = &bar {
        bar.set_message("rivers");
    }
    let t = std::time::Instant::now();
    let network = riverplanet::river::network::RiverNetwork::generate(&planet, &config, seed);
    let river_ms = t.elapsed().as_secs_f64() * 1e3;
    let geojson_depth = 2;
    let (rivers, tributaries) = network.count(config.river.hull_levels);
    let t = std::time::Instant::now();
    if let Some(bar) = &bar {
        bar.set_message("writing");
    }
    std::fs::create_dir_all(out)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", out.display()))?;
    let faces = planet.face_lattice(level);
    let faces_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = std::time::Instant::now();
    riverplanet::export::write_faces(&faces, level, out)?;
    if preview {
        let path = out.join("preview.png");
        let mut image = riverplanet::export::preview(&planet, 256);
        match &planet.drainage {
            Some(drainage) => {
                riverplanet::export::drainage::draw_drainage(&mut image, drainage, 256)
            }
            None => riverplanet::export::draw_rivers(&mut image, &network, geojson_depth, 256),
        }
        riverplanet::export::files::save_image(&image, &path)?;
    }
    if equirect {
        let path = out.join("continents.png");
        let land = riverplanet::export::equirectangular_land(&planet, 1024);
        riverplanet::export::files::save_image(&land, &path)?;
    }
    let path = out.join("rivers.geojson");
    let geojson = match &planet.drainage {
        Some(drainage) => riverplanet::export::drainage::drainage_geojson(drainage, &config),
        None => riverplanet::export::rivers_geojson(&network, geojson_depth),
    };
    riverplanet::export::files::write_bytes(&path, serde_json::to_string(&geojson)?.as_bytes())?;
    let mut stats = planet.stats.clone();
    stats.timings_ms.insert("rivers".to_string(), river_ms);
    stats
        .timings_ms
        .insert(format!("face images level {level}"), faces_ms);
    stats
        .timings_ms
        .insert("write".to_string(), t.elapsed().as_secs_f64() * 1e3);
    let mut value = serde_json::to_value(&stats)?;
    value["rivers"] = serde_json::json!(rivers);
    value["tributaries"] = serde_json::json!(tributaries);
    value["abandoned_river_sources"] = serde_json::json!(network.abandoned_sources);
    value["rivers_geojson_lod"] = serde_json::json!(geojson_depth);
    if let Some(drainage) = &planet.drainage {
        // The drainage model's measures, at the top level (docs/rivers.md).
        if let serde_json::Value::Object(measures) = serde_json::to_value(&drainage.measures)? {
            for (key, v) in measures {
                value[key] = v;
            }
        }
        value["river_systems"] = serde_json::json!(rivers);
    }
    let path = out.join("stats.json");
    riverplanet::export::files::write_bytes(
        &path,
        serde_json::to_string_pretty(&value)?.as_bytes(),
    )?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    Ok(())
}

/// A whole number of at least 1.
fn positive_count(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("'{text}' is not a whole number of at least 1")),
    }
}

/// A finite number above 0.
fn positive_number(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("'{text}' is not a finite number above 0")),
    }
}

fn parse_vec3(text: &str) -> Result<glam::DVec3, String> {
    let parts: Vec<f64> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{text}' is not three comma-separated numbers (e.g. 0,1200,3400)"))?;
    match parts.as_slice() {
        [x, y, z] if parts.iter().all(|v| v.is_finite()) => Ok(glam::DVec3::new(*x, *y, *z)),
        _ => Err(format!(
            "'{text}' is not three comma-separated numbers (e.g. 0,1200,3400)"
        )),
    }
}

fn parse_size(text: &str) -> Result<[u32; 2], String> {
    let [w, h] = parse_block(text)?;
    if (1..=16384).contains(&w) && (1..=16384).contains(&h) {
        Ok([w, h])
    } else {
        Err(format!("size '{text}' must be WxH with both in [1, 16384]"))
    }
}

fn render(options: &ContextOptions, args: &RenderArgs) -> anyhow::Result<()> {
    let config = load_config(&args.config)?;
    check_output("--out", &args.out, true)?;
    let seed = args.seed.unwrap_or_else(|| config.resolve_seed());
    if args.preset.is_none() && args.eye.length() <= config.planet.radius as f64 * 0.5 {
        anyhow::bail!(
            "--eye {} is inside the planet (radius {})",
            args.eye,
            config.planet.radius
        );
    }
    if (args.look_at - args.eye).length() < 1e-9 {
        anyhow::bail!("--look-at must differ from --eye");
    }
    if !(1.0..=170.0).contains(&args.fov) {
        anyhow::bail!("--fov {} must be in [1, 170] degrees", args.fov);
    }
    let world = riverplanet::world::World::build(&config, seed)?;
    let (eye, look_at) = match args.preset {
        Some(preset) => riverplanet::render::presets::camera(preset, &world).ok_or_else(|| {
            anyhow::anyhow!("preset {preset:?} needs a river, and this planet has none")
        })?,
        None => (args.eye, args.look_at),
    };
    println!(
        "camera: --eye {},{},{} --look-at {},{},{}",
        eye.x, eye.y, eye.z, look_at.x, look_at.y, look_at.z
    );
    let ctx = Context::new(options)?;
    let [w, h] = args.size;
    let target = riverplanet::render::target::Offscreen::new(&ctx, w, h)?;
    let mut renderer = riverplanet::render::Renderer::new(
        &ctx,
        &world.planet,
        &world.network,
        &config,
        riverplanet::render::target::COLOR_FORMAT,
        riverplanet::render::target::DEPTH_FORMAT,
    )?;
    renderer.water_mode = args.water;
    renderer.view_mode = args.view;
    renderer.variant = args.kernel;
    renderer.morphing = !args.no_morphing;
    let altitude = eye.length() - config.planet.radius as f64;
    let camera = riverplanet::runtime::camera::Camera::look_at(
        eye,
        look_at,
        args.fov,
        w as f64 / h as f64,
        (altitude * 0.05).clamp(0.01, 10.0),
    );
    let c = args.clear_color;
    let clear = [c.x as f32, c.y as f32, c.z as f32, 1.0];
    let mut layout = gpu::vk::ImageLayout::UNDEFINED;
    let (stats, frames) = renderer.render_until_streamed(
        &camera,
        &target.target(clear),
        &mut layout,
        args.max_frames,
    )?;
    let image = target.read(&ctx)?;
    riverplanet::export::files::save_image(&image, &args.out)?;
    println!(
        "{}: {w}x{h}, {frames} frames to stream the patches; last frame: {} visible patches, {} resident, \
         deepest level {}",
        args.out.display(),
        stats.visible_patches,
        stats.resident_patches,
        stats.deepest_level
    );
    for (pass, ms) in &stats.gpu_ms {
        println!("  gpu {pass:<8} {ms:8.3} ms");
    }
    println!("  frame     {:8.3} ms", stats.frame_ms);
    let errors = ctx.validation_errors();
    renderer.destroy();
    target.destroy(&ctx);
    if !errors.is_empty() {
        anyhow::bail!(
            "validation reported {} error(s): {}",
            errors.len(),
            errors[0]
        );
    }
    Ok(())
}

fn view(options: &ContextOptions, args: &ViewArgs) -> anyhow::Result<()> {
    let config = load_config(&args.config)?;
    if let Some(path) = &args.screenshot {
        check_output("--screenshot", path, true)?;
    }
    let seed = args.seed.unwrap_or_else(|| config.resolve_seed());
    let world = riverplanet::world::World::build(&config, seed)?;
    let (eye, look_at) = match args.eye {
        Some(eye) => (eye, args.look_at),
        None => riverplanet::render::presets::camera(
            riverplanet::render::presets::Preset::Orbit,
            &world,
        )
        .unwrap_or((
            glam::DVec3::new(0.0, 0.0, config.planet.radius as f64 * 3.0),
            glam::DVec3::ZERO,
        )),
    };
    riverplanet::render::viewer::run(
        &world,
        options,
        riverplanet::render::viewer::ViewerOptions {
            size: args.size,
            eye,
            look_at,
            frames: args.frames,
            screenshot: args.screenshot.clone(),
            water: args.water,
        },
    )?;
    Ok(())
}
