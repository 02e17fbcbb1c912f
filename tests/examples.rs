//! Issue "Your own terrain, your own program": the examples (the library in use, examples/) run from the project
//! root as a user runs them, and do what they say.

mod common;

use std::{path::PathBuf, process::Command};

/// The built example `name`: `cargo test` builds every example, `cargo test --test examples` alone does not (and
/// cargo cannot be run from here: the running cargo holds the build directory), so one missing or older than the
/// library it links is refused with what to run.
fn example(name: &str) -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    let path = deps.parent().unwrap().join("examples").join(name);
    let modified = |p: &std::path::Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let library = std::fs::read_dir(deps)
        .unwrap()
        .flatten()
        .filter(|e| {
            let file = e.file_name().to_string_lossy().to_string();
            file.starts_with("libriverplanet-") && file.ends_with(".rlib")
        })
        .filter_map(|e| modified(&e.path()))
        .max();
    let built = modified(&path);
    assert!(
        built.is_some() && built >= library,
        "example {name} is not built or older than the library: run `cargo build --release --examples` first"
    );
    path
}

/// A fresh folder of this test run for `name`'s files.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "riverplanet-examples-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs example `name` with `args` from the project root; its standard output.
fn run(name: &str, args: &[&str]) -> String {
    let output = Command::new(example(name))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout).to_string();
    assert!(
        output.status.success(),
        "{name} failed: {stdout}{}",
        String::from_utf8_lossy(&output.stderr)
    );
    stdout
}

#[test]
fn the_planet_example_reads_the_planet_that_generate_measures() {
    let out = run("planet", &["config/planet.xml", "1"]);
    println!("{out}");
    // Seed 1's drainage network, as the library (and `generate`'s stats.json) measures it.
    let config = riverplanet::config::Config::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/planet.xml"),
    )
    .unwrap();
    let world = riverplanet::world::World::build(&config, 1).unwrap();
    let m = &world.planet.drainage.as_ref().unwrap().measures;
    assert!(out.contains("seed 1: radius 1024"), "{out}");
    let network = format!(
        "{} reaches, {} lakes, Strahler order {}",
        m.reaches, m.lakes, m.strahler_max
    );
    assert!(out.contains(&network), "{out} does not say {network}");
    assert_eq!(
        out.matches(" (land)").count() + out.matches(" (sea)").count(),
        3
    );
}

#[test]
fn the_export_example_writes_a_gltf_with_terrain_and_water() {
    let dir = temp_dir("export");
    let glb = dir.join("mouth.glb");
    let out = run(
        "export_glb",
        &["config/planet.xml", glb.to_str().unwrap(), "1"],
    );
    let bytes = std::fs::read(&glb).unwrap();
    assert_eq!(&bytes[..4], b"glTF", "{out}");
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + length]).unwrap();
    let meshes: Vec<&str> = json["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(meshes, ["terrain", "water"], "{out}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_render_example_draws_what_riverplanet_render_draws() {
    if common::gpu().is_none() {
        return;
    }
    let dir = temp_dir("render");
    let png = dir.join("river.png");
    run(
        "render_png",
        &["config/planet.xml", png.to_str().unwrap(), "1"],
    );
    let cli = dir.join("cli.png");
    let status = Command::new(env!("CARGO_BIN_EXE_riverplanet"))
        .args([
            "render", "--seed", "1", "--preset", "river", "--size", "960x540", "--out",
        ])
        .arg(&cli)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(status.status.success());
    let (a, b) = (image::open(&png).unwrap(), image::open(&cli).unwrap());
    assert_eq!((a.width(), a.height()), (960, 540));
    assert!(
        a == b,
        "the example's image differs from riverplanet render's"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
