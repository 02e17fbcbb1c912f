//! The `riverplanet` command line.

use std::{path::PathBuf, process::ExitCode};

use clap::{Parser, Subcommand};
use riverplanet::{
    bench,
    config::Config,
    gpu::{self, Context, ContextOptions},
    kernel::gpu::KernelTuning,
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
    },
    /// Measure the river kernel variants side by side in one run.
    Bench {
        #[command(subcommand)]
        what: BenchCommand,
    },
}

#[derive(Subcommand)]
enum BenchCommand {
    /// CPU single-thread, CPU rayon, GPU simple and GPU tiled on identical input (Tables 9.1/9.2).
    Kernel {
        #[arg(long, default_value = "config/planet.xml")]
        config: PathBuf,
        /// The thesis's stress test: switch factor x10.
        #[arg(long)]
        stress: bool,
        /// Repetitions per variant (the median is reported).
        #[arg(long, default_value_t = 5)]
        repetitions: usize,
        /// Invocations per workgroup of the simple kernel.
        #[arg(long, default_value_t = KernelTuning::default().simple_workgroup)]
        simple_workgroup: u32,
        /// Vertex block per workgroup of the tiled kernel, as WxH.
        #[arg(long, default_value = "8x8", value_parser = parse_block)]
        tiled_block: [u32; 2],
        /// Samples staged per tile by the tiled kernel.
        #[arg(long, default_value_t = KernelTuning::default().tile_size)]
        tile_size: u32,
        /// Write the report here as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
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
        } => match generate(&config, &out, seed, preview, equirect) {
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

fn load_config(path: &std::path::Path) -> anyhow::Result<Config> {
    let config = Config::load(path)?;
    log::info!("resolved configuration: {config:?}");
    Ok(config)
}

fn run_bench(options: &ContextOptions, what: BenchCommand) -> anyhow::Result<()> {
    match what {
        BenchCommand::Kernel {
            config,
            stress,
            repetitions,
            simple_workgroup,
            tiled_block,
            tile_size,
            json,
        } => {
            let config = load_config(&config)?;
            let ctx = Context::new(options)?;
            let tuning = KernelTuning {
                simple_workgroup,
                tiled_block,
                tile_size,
            };
            let report = bench::kernel_bench(&ctx, &config, stress, repetitions, tuning)?;
            let v = &report.variants;
            println!(
                "device {} | {} patches, {} samples, {} vertex-sample pairs ({} within reach) | rayon threads {}, LP_NUM_THREADS {}",
                report.device,
                report.patches,
                report.samples,
                report.pairs,
                report.relevant_pairs,
                report.threads.rayon_threads_used,
                report.threads.lp_num_threads.as_deref().unwrap_or("unset"),
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
                "  tiled/simple {:.3} | cpu single / gpu tiled end-to-end {:.2}x | max |diff| {:.3e} (height range {:?})",
                report.ratios.tiled_over_simple,
                report.ratios.cpu_single_over_gpu_tiled_end_to_end,
                report.max_abs_diff,
                report.height_range
            );
            let errors = ctx.validation_errors();
            if !errors.is_empty() {
                anyhow::bail!(
                    "validation reported {} error(s): {}",
                    errors.len(),
                    errors[0]
                );
            }
            if let Some(path) = json {
                std::fs::write(&path, serde_json::to_string_pretty(&report)?)
                    .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
            }
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

fn generate(
    config_path: &std::path::Path,
    out: &std::path::Path,
    seed: Option<u32>,
    preview: bool,
    equirect: bool,
) -> anyhow::Result<()> {
    use std::io::IsTerminal;
    let config = load_config(config_path)?;
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
    riverplanet::export::write_faces(&planet, out)?;
    if preview {
        let path = out.join("preview.png");
        let mut image = riverplanet::export::preview(&planet, 256);
        riverplanet::export::draw_rivers(&mut image, &network, geojson_depth, 256);
        image
            .save(&path)
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    }
    if equirect {
        let path = out.join("continents.png");
        riverplanet::export::equirectangular_land(&planet, 1024)
            .save(&path)
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    }
    let path = out.join("rivers.geojson");
    let geojson = riverplanet::export::rivers_geojson(&network, geojson_depth);
    std::fs::write(&path, serde_json::to_string(&geojson)?)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    let mut stats = planet.stats.clone();
    stats.timings_ms.insert("rivers".to_string(), river_ms);
    stats
        .timings_ms
        .insert("write".to_string(), t.elapsed().as_secs_f64() * 1e3);
    let mut value = serde_json::to_value(&stats)?;
    value["rivers"] = serde_json::json!(rivers);
    value["tributaries"] = serde_json::json!(tributaries);
    value["abandoned_river_sources"] = serde_json::json!(network.abandoned_sources);
    value["rivers_geojson_lod"] = serde_json::json!(geojson_depth);
    let path = out.join("stats.json");
    std::fs::write(&path, serde_json::to_string_pretty(&value)?)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    Ok(())
}
