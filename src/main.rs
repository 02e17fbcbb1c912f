//! The `riverplanet` command line.

use std::{path::PathBuf, process::ExitCode};

use clap::{Parser, Subcommand};
use riverplanet::{
    config::Config,
    gpu::{self, ContextOptions},
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
