//! The `riverplanet` command line.

use std::process::ExitCode;

use clap::Parser;
use riverplanet::{
    bench,
    config::{Config, ConfigError},
    gpu::{self, Context, ContextOptions},
};
mod cli;

use cli::{
    benchmarks::run_bench,
    export::export,
    generate::generate,
    render::{render, view},
    Cli, Command,
};

fn main() -> ExitCode {
    // SAFETY: the first thing the program does, before any thread starts. The default action of SIGPIPE (which
    // Rust's runtime sets to ignore) ends the program quietly when what reads its output goes away
    // (`riverplanet render ... | head -1`), as other command-line tools do, instead of a panic in println!.
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // Before any thread starts: SIGINT and SIGTERM stop every command cleanly (src/interrupt.rs).
    riverplanet::interrupt::start();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let mut options = ContextOptions::from_env();
    if cli.adapter.is_some() {
        options.adapter = cli.adapter.clone();
    }
    match cli.command {
        Command::Info { json } => info(&options, json),
        Command::Generate {
            planet,
            out,
            preview,
            equirect,
            level,
        } => finish(generate(
            planet.config.as_deref(),
            &out,
            planet.seed,
            (preview, equirect),
            level,
        )),
        Command::Render(args) => finish(render(&options, &args)),
        Command::Plot {
            flight,
            stress,
            out,
        } => finish(plot(&flight, stress.as_deref(), &out)),
        Command::Report {
            kernel,
            kernel_stress,
            flight,
            flight_stress,
            long_flight,
            kernel_reuse,
            descent,
            frame_flight,
            commands,
            out,
        } => finish((|| {
            let commands = std::fs::read_to_string(&commands)
                .map_err(|e| usage(format!("--commands {}: {e}", commands.display())))?;
            let inputs = bench::report::ReportInputs {
                kernel: &kernel,
                kernel_stress: &kernel_stress,
                flight: &flight,
                flight_stress: &flight_stress,
                long_flight: long_flight.as_deref(),
                kernel_reuse: kernel_reuse.as_deref(),
                descents: &descent,
                frame_flights: &frame_flight,
                commands: &commands,
            };
            let md = bench::report::results_markdown(&inputs).map_err(input_error)?;
            riverplanet::export::files::write_bytes(&out, md.as_bytes())
                .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", out.display()))
        })()),
        Command::View(args) => finish(view(&options, &args)),
        Command::Export { what } => finish(export(what)),
        Command::Bench { what } => finish(run_bench(&options, what)),
        Command::Config { file } => finish((|| {
            let config = Config::load(&file)?;
            // What generate would refuse, config refuses too: the continents image is read as generate reads it.
            if config.planet.continents_from_file {
                riverplanet::planet::continents::ContinentImage::load(std::path::Path::new(
                    &config.planet.continents_image,
                ))
                .map_err(|e| usage(format!("<continents-image> of {}: {e}", file.display())))?;
            }
            log::info!("resolved configuration: {config:?}");
            println!("{}", serde_json::to_string_pretty(&config)?);
            Ok(())
        })()),
    }
}

/// A mistake in how the program was called: an argument's value or an output path. Exit code 2, as clap's own
/// usage errors and configuration errors; everything else that fails at run time exits 1.
#[derive(Debug)]
pub(crate) struct Usage(String);

impl std::fmt::Display for Usage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Usage {}

pub(crate) fn usage(message: impl Into<String>) -> anyhow::Error {
    anyhow::Error::new(Usage(message.into()))
}

/// The one place errors become exit codes: 2 for usage and configuration errors, 1 for the rest.
fn finish(result: anyhow::Result<()>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            if e.downcast_ref::<Usage>().is_some() || e.downcast_ref::<ConfigError>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}

/// A report that cannot be read, or is not the command's it was given as, is a usage error; drawing failures are not.
fn input_error(e: bench::plot::PlotError) -> anyhow::Error {
    match e {
        bench::plot::PlotError::Read { .. } | bench::plot::PlotError::Format { .. } => {
            usage(e.to_string())
        }
        e => e.into(),
    }
}

/// Figures 9.1-9.8 from the flight reports, printing the PNGs written.
fn plot(
    flight: &std::path::Path,
    stress: Option<&std::path::Path>,
    out: &std::path::Path,
) -> anyhow::Result<()> {
    let mut names = bench::plot::flight_figures(flight, out, "", false).map_err(input_error)?;
    if let Some(stress) = stress {
        names.extend(
            bench::plot::flight_figures(stress, out, "stress_", true).map_err(input_error)?,
        );
    }
    for n in names {
        println!("{}", out.join(n).with_extension("png").display());
    }
    Ok(())
}

fn info(options: &ContextOptions, json: bool) -> ExitCode {
    let (version, adapters) = match gpu::adapter::enumerate(options) {
        Ok(v) => v,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    let usable = adapters
        .iter()
        .any(|a| a.chosen && a.features.all_supported());
    // Why the chosen device cannot draw (it may still compute).
    let cannot_draw = adapters
        .iter()
        .find(|a| a.chosen)
        .and_then(gpu::adapter::cannot_draw);
    if json {
        let value = serde_json::json!({ "instance_version": version, "devices": adapters, "usable": usable,
            "draws": usable && cannot_draw.is_none(), "cannot_draw": cannot_draw });
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
        if let Some(reason) = &cannot_draw {
            println!("the chosen device cannot draw: {reason}");
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
pub(crate) fn check_output(
    argument: &str,
    path: &std::path::Path,
    png_only: bool,
) -> anyhow::Result<()> {
    riverplanet::export::files::check_output(argument, path, png_only).map_err(usage)
}

/// The configuration file used when `--config` is not given, if it exists.
const DEFAULT_CONFIG: &str = "config/planet.xml";

/// The configuration of `path`; without one, config/planet.xml if there is one here, or else the built-in default
/// (`Config::default()`: Appendix A's planet with the drainage model, seed 1), so the binary runs from any folder.
/// Returns it with where it came from, for messages.
pub(crate) fn load_config(path: Option<&std::path::Path>) -> anyhow::Result<(Config, String)> {
    let default = std::path::Path::new(DEFAULT_CONFIG);
    let (config, source) = match path {
        Some(path) => (Config::load(path)?, path.display().to_string()),
        None if default.exists() => (Config::load(default)?, DEFAULT_CONFIG.to_string()),
        None => (
            Config::default(),
            "the built-in default configuration".to_string(),
        ),
    };
    log::info!("resolved configuration of {source}: {config:?}");
    Ok((config, source))
}

/// The planet's seed: `--seed`, or else the configuration's `master-seed` (a new one each run if -1). Printed, so
/// that a planet can always be made again.
pub(crate) fn planet_seed(seed: Option<u32>, config: &Config) -> u32 {
    let seed = seed.unwrap_or_else(|| config.resolve_seed());
    println!("seed: {seed} (--seed {seed} makes this planet again)");
    seed
}

pub(crate) fn write_json(
    path: &std::path::Path,
    value: &impl serde::Serialize,
) -> anyhow::Result<()> {
    Ok(riverplanet::export::files::write_bytes(
        path,
        serde_json::to_string_pretty(value)?.as_bytes(),
    )?)
}

pub(crate) fn check_validation(ctx: &Context) -> anyhow::Result<()> {
    let errors = ctx.validation_errors();
    match errors.first() {
        Some(first) => anyhow::bail!("validation reported {} error(s): {first}", errors.len()),
        None => Ok(()),
    }
}
