//! `riverplanet export`: the planet in forms other tools read (beyond the thesis).

use std::path::Path;

use riverplanet::{
    drainage::finer,
    export::{
        self,
        carved::{carved_terrain, MAX_EXPORT_LEVEL},
        heightmaps::{planet_metadata, write_equirect, write_faces, write_georeferenced},
        mesh::write_glb,
        region::{sample_region, Region},
    },
    world::World,
};

use super::{
    progress::{build_world, Progress},
    ExportCommand, RegionFormat,
};
use crate::{load_config, planet_seed, usage};

/// The finest level `export rivers` refines the thesis's river pieces to (as `hull-levels`' range).
const MAX_RIVER_LEVEL: u32 = 8;

pub fn export(what: ExportCommand) -> anyhow::Result<()> {
    match what {
        ExportCommand::Faces {
            planet,
            level,
            format,
            out,
        } => {
            check_level(level)?;
            export::files::check_folder("--out", &out).map_err(usage)?;
            let (config, _) = load_config(planet.config.as_deref())?;
            let seed = planet_seed(planet.seed, &config);
            let progress = Progress::start("building the planet");
            let (world, lattice) = carved_world(&config, seed, level, &progress)?;
            let metadata = planet_metadata(&world.planet, seed, level, true);
            progress.stage("writing the faces");
            // The faces and layout.json replace the folder's old set as a whole, or not at all.
            let set = export::files::OutputSet::begin(&out)?;
            let layout = write_faces(&lattice, format, set.path(), &metadata)?;
            set.commit()?;
            println!(
                "{}: 6 faces of {side} x {side} at level {level}, heights {} to {}",
                out.display(),
                layout["min_height"],
                layout["max_height"],
                side = lattice.side(),
            );
            Ok(())
        }
        ExportCommand::Equirect {
            planet,
            size: [width, height],
            level,
            format,
            out,
        } => {
            if width < 2 || height < 2 {
                return Err(usage(format!(
                    "--size {width}x{height}: both must be at least 2"
                )));
            }
            let level = level.unwrap_or_else(|| equirect_level(width));
            check_level(level)?;
            export::files::check_output("--out", &out, false).map_err(usage)?;
            if !format.names(&out) {
                return Err(usage(format!(
                    "--out {}: --format {} writes .{} files",
                    out.display(),
                    format.name(),
                    format.extension()
                )));
            }
            let (config, _) = load_config(planet.config.as_deref())?;
            let seed = planet_seed(planet.seed, &config);
            let progress = Progress::start("building the planet");
            let (world, lattice) = carved_world(&config, seed, level, &progress)?;
            let metadata = planet_metadata(&world.planet, seed, level, true);
            progress.stage(format!("sampling and writing {width} x {height}"));
            let written = write_equirect(
                &lattice,
                (width, height),
                format,
                &out,
                &metadata,
                world.planet.radius,
            )?;
            println!(
                "{}: {width} x {height} from level {level}, heights {} to {}; metadata in {}",
                out.display(),
                written["min_height"],
                written["max_height"],
                out.with_extension("json").display()
            );
            Ok(())
        }
        ExportCommand::Region {
            planet,
            bounds,
            level,
            format,
            out,
        } => export_region(planet, bounds, level, format, &out),
        ExportCommand::Rivers { planet, level, out } => export_rivers(planet, level, &out),
    }
}

/// The finest level `export region` samples: patches are made only where the window is, down to any level the
/// renderer reaches on config/earth.xml's scale of a few metres.
const MAX_REGION_LEVEL: u32 = 20;

fn export_region(
    planet: super::PlanetArgs,
    bounds: [f64; 4],
    level: u32,
    format: RegionFormat,
    out: &Path,
) -> anyhow::Result<()> {
    if level > MAX_REGION_LEVEL {
        return Err(usage(format!(
            "--level {level} must be in [0, {MAX_REGION_LEVEL}]"
        )));
    }
    let region = Region::new(bounds, level).map_err(usage)?;
    export::files::check_output("--out", out, false).map_err(usage)?;
    let named = match format {
        RegionFormat::Raster(raster) => raster.names(out),
        RegionFormat::Glb => out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("glb")),
    };
    if !named {
        let (name, extension) = match format {
            RegionFormat::Raster(raster) => (raster.name(), raster.extension()),
            RegionFormat::Glb => ("glb", "glb"),
        };
        return Err(usage(format!(
            "--out {}: --format {name} writes .{extension} files",
            out.display()
        )));
    }
    let (config, _) = load_config(planet.config.as_deref())?;
    let seed = planet_seed(planet.seed, &config);
    let world = build_world(&config, seed)?;
    let progress = Progress::start("sampling the region");
    let surface = sample_region(
        &world.planet,
        &world.network,
        &config,
        level,
        &region,
        &counter(&progress, format!("carving the patches of level {level}")),
    );
    drop(progress);
    let metadata = planet_metadata(&world.planet, seed, level, true);
    let (width, height) = region.size;
    match format {
        RegionFormat::Raster(raster) => {
            let geo = region.georeference(world.planet.radius);
            write_georeferenced(out, region.size, &surface.terrain, raster, &metadata, &geo)?;
            println!(
                "{}: {width} x {height} samples from level {level}; metadata in {}",
                out.display(),
                out.with_extension("json").display()
            );
        }
        RegionFormat::Glb => {
            let (terrain, water) = write_glb(
                out,
                &region,
                &surface,
                (world.planet.radius, world.planet.sea_level),
                &metadata,
            )?;
            println!(
                "{}: {width} x {height} vertices from level {level}, {terrain} terrain and {water} water triangles",
                out.display()
            );
        }
    }
    Ok(())
}

/// The planet of `config` and `seed` and its terrain carved at `level`, counted by `progress`.
fn carved_world(
    config: &riverplanet::config::Config,
    seed: u32,
    level: u32,
    progress: &Progress,
) -> anyhow::Result<(World, riverplanet::planet::heights::FaceLattice)> {
    let world = World::build_reporting(config, seed, |stage| progress.stage(stage.to_string()))?;
    let message = format!("carving the patches of level {level}");
    let lattice = carved_terrain(
        &world.planet,
        &world.network,
        config,
        level,
        &counter(progress, message),
    );
    Ok((world, lattice))
}

/// A step of `progress` per patch carved, counting the total the first call gives.
fn counter(progress: &Progress, message: String) -> impl Fn(usize) + Sync + '_ {
    let started = std::sync::Once::new();
    move |total| {
        started.call_once(|| progress.count(message.clone(), total as u64));
        progress.step();
    }
}

fn check_level(level: u32) -> anyhow::Result<()> {
    if level > MAX_EXPORT_LEVEL {
        return Err(usage(format!(
            "--level {level} must be in [0, {MAX_EXPORT_LEVEL}] (level 7: 6 faces of 4097 x 4097 heights)"
        )));
    }
    Ok(())
}

/// The coarsest level whose vertices lie no farther apart than an equirectangular raster `width` pixels wide
/// samples the equator: a face spans 90 degrees in 32 x 2^level cells, the raster in width / 4 pixels.
fn equirect_level(width: u32) -> u32 {
    let mut level = 0;
    while (32u32 << level) < width.div_ceil(4) && level < MAX_EXPORT_LEVEL {
        level += 1;
    }
    level
}

fn export_rivers(planet: super::PlanetArgs, level: Option<u32>, out: &Path) -> anyhow::Result<()> {
    let (config, source) = load_config(planet.config.as_deref())?;
    export::files::check_output("--out", out, false).map_err(usage)?;
    let geojson_name = out
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("geojson") || e.eq_ignore_ascii_case("json"));
    if !geojson_name {
        return Err(usage(format!(
            "--out {}: rivers are written as GeoJSON; the name must end in .geojson or .json",
            out.display()
        )));
    }
    let drainage = config.river.model == riverplanet::config::RiverModel::Drainage;
    // The drainage network is routed anew at levels above its base lattice's (docs/rivers.md).
    let max_level = if drainage {
        // A loaded configuration has a valid base resolution, so its base level exists.
        config.base_level().unwrap_or(0) + finer::MAX_LEVELS_ABOVE_BASE
    } else {
        MAX_RIVER_LEVEL
    };
    if let Some(level) = level.filter(|&l| l > max_level) {
        return Err(usage(format!(
            "--level {level} must be in [0, {max_level}] for {source}{}",
            if drainage {
                " (the drainage network's base level and two above it)"
            } else {
                ""
            }
        )));
    }
    let seed = planet_seed(planet.seed, &config);
    let world = build_world(&config, seed)?;
    let geojson = if drainage {
        let level = level.unwrap_or(world.planet.stats.base_level);
        let network = finer::network_at(&world.planet, &config, level)
            .ok_or_else(|| anyhow::anyhow!("{source}: the drainage model made no network"))?;
        let m = &network.measures;
        println!(
            "level {level}: {} reaches, {} confluences ({} of three rivers or more), {} lakes, Strahler order {}, \
             bifurcation ratio {:.2}, Hack exponent {:.3}, {} uphill steps, {} crossings",
            m.reaches,
            m.confluences,
            m.multiple_junctions,
            m.lakes,
            m.strahler_max,
            m.bifurcation_ratio,
            m.hack_exponent,
            m.uphill_steps,
            m.crossings
        );
        export::drainage::drainage_geojson(&network, &config)
    } else {
        let level = level.unwrap_or(config.river.hull_levels);
        export::rivers_geojson(&world.network, level, world.planet.radius)
    };
    let features = geojson["features"].as_array().map_or(0, Vec::len);
    export::files::write_bytes(out, serde_json::to_string(&geojson)?.as_bytes())?;
    println!("{}: {features} features", out.display());
    Ok(())
}
