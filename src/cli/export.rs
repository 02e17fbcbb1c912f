//! `riverplanet export`: the planet in forms other tools read (beyond the thesis).

use riverplanet::{export, world::World};

use super::ExportCommand;
use crate::{load_config, planet_seed, usage};

/// The finest level `export rivers` refines the thesis's river pieces to (as `hull-levels`' range).
const MAX_RIVER_LEVEL: u32 = 8;

pub fn export(what: ExportCommand) -> anyhow::Result<()> {
    match what {
        ExportCommand::Rivers { planet, level, out } => {
            let (config, source) = load_config(planet.config.as_deref())?;
            export::files::check_output("--out", &out, false).map_err(usage)?;
            let geojson_name = out.extension().and_then(|e| e.to_str()).is_some_and(|e| {
                e.eq_ignore_ascii_case("geojson") || e.eq_ignore_ascii_case("json")
            });
            if !geojson_name {
                return Err(usage(format!(
                    "--out {}: rivers are written as GeoJSON; the name must end in .geojson or .json",
                    out.display()
                )));
            }
            let drainage = config.river.model == riverplanet::config::RiverModel::Drainage;
            if let (Some(level), true) = (level, drainage) {
                return Err(usage(format!(
                    "--level {level}: {source} uses the drainage river model, whose reaches have one level; \
                     --level refines the thesis's model (river-model thesis)"
                )));
            }
            let level = level.unwrap_or(config.river.hull_levels);
            if level > MAX_RIVER_LEVEL {
                return Err(usage(format!(
                    "--level {level} must be in [0, {MAX_RIVER_LEVEL}]"
                )));
            }
            let seed = planet_seed(planet.seed, &config);
            let world = World::build(&config, seed)?;
            let geojson = match &world.planet.drainage {
                Some(drainage) => export::drainage::drainage_geojson(drainage, &config),
                None => export::rivers_geojson(&world.network, level, world.planet.radius),
            };
            let features = geojson["features"].as_array().map_or(0, Vec::len);
            export::files::write_bytes(&out, serde_json::to_string(&geojson)?.as_bytes())?;
            println!("{}: {features} features", out.display());
            Ok(())
        }
    }
}
