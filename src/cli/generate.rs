//! `riverplanet generate`: the planet's face images, preview, rivers and statistics.

use crate::{load_config, planet_seed, usage};
use riverplanet::geomorphology::profiles;

/// The finest level `generate` writes face images at (8193 pixels per edge with 33 vertices).
const MAX_FACE_IMAGE_LEVEL: u32 = 8;
/// The level of `generate`'s face images without `--level` (the thesis's finest precomputed level).
const DEFAULT_FACE_IMAGE_LEVEL: u32 = 6;

pub fn generate(
    config_path: Option<&std::path::Path>,
    out: &std::path::Path,
    seed: Option<u32>,
    (preview, equirect): (bool, bool),
    level: Option<u32>,
) -> anyhow::Result<()> {
    let (config, source) = load_config(config_path)?;
    let deepest = config
        .rendering
        .max_level_of_detail
        .min(MAX_FACE_IMAGE_LEVEL);
    let level = level.unwrap_or(DEFAULT_FACE_IMAGE_LEVEL.min(deepest));
    if level > deepest {
        return Err(usage(format!(
            "--level {level} must be in [0, {deepest}] (max-level-of-detail {} of {}; face images stop at \
             level {MAX_FACE_IMAGE_LEVEL}, {} pixels per edge)",
            config.rendering.max_level_of_detail,
            source,
            ((config.rendering.vertices - 1) << MAX_FACE_IMAGE_LEVEL) + 1
        )));
    }
    let seed = planet_seed(seed, &config);
    let progress = super::progress::Progress::start("planet");
    let planet = riverplanet::planet::Planet::generate(&config, seed, |stage| {
        progress.stage(stage.to_string());
    })?;
    progress.stage("rivers");
    let t = std::time::Instant::now();
    let network = riverplanet::river::network::RiverNetwork::generate(&planet, &config, seed);
    let river_ms = t.elapsed().as_secs_f64() * 1e3;
    // The GeoJSON holds the branches stats.json counts.
    let geojson_depth = config.river.hull_levels;
    let t = std::time::Instant::now();
    let (rivers, tributaries) = network.count(geojson_depth);
    let count_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = std::time::Instant::now();
    progress.stage("writing");
    // Everything below replaces the folder's old set as a whole, or not at all.
    let set = riverplanet::export::files::OutputSet::begin(out)?;
    let dir = set.path();
    let faces = planet.face_lattice(level);
    let faces_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = std::time::Instant::now();
    let faces_dir = dir.join("faces");
    std::fs::create_dir_all(&faces_dir)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", faces_dir.display()))?;
    let metadata = riverplanet::export::heightmaps::planet_metadata(&planet, seed, level, false);
    riverplanet::export::heightmaps::write_faces(
        &faces,
        riverplanet::export::raster::RasterFormat::Png,
        &faces_dir,
        &metadata,
    )?;
    if preview {
        let path = dir.join("preview.png");
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
        let path = dir.join("continents.png");
        let land = riverplanet::export::equirectangular_land(&planet, 1024);
        riverplanet::export::files::save_image(&land, &path)?;
    }
    let path = dir.join("rivers.geojson");
    let geojson = match &planet.drainage {
        Some(drainage) => riverplanet::export::drainage::drainage_geojson(drainage, &config),
        None => riverplanet::export::rivers_geojson(&network, geojson_depth, planet.radius),
    };
    riverplanet::export::files::write_bytes(&path, serde_json::to_string(&geojson)?.as_bytes())?;
    let mut stats = planet.stats.clone();
    stats.timings_ms.insert("rivers".to_string(), river_ms);
    stats.timings_ms.insert("river count".to_string(), count_ms);
    // The finer levels' streams are routed within the rivers' stage; each level's share apart.
    for level in &network.streams {
        stats
            .timings_ms
            .insert(format!("streams level {}", level.level), level.ms);
    }
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
    value["stream_levels"] = network
        .streams
        .iter()
        .map(|l| {
            serde_json::json!({
                "level": l.level,
                "reaches": l.reaches,
                "systems": l.systems.len(),
                "drawn": l.drawn,
            })
        })
        .collect();
    if let Some(drainage) = &planet.drainage {
        // The sinuosity of the rivers as drawn at their finest (docs/geomorphology.md).
        let t = std::time::Instant::now();
        let sinuous = |k: usize| drainage.reaches[k].strahler >= profiles::SINUOUS_ORDER;
        let lengths = riverplanet::river::drainage::drawn_reach_lengths(
            (&network.systems, &network.params),
            drainage,
            sinuous,
        );
        let sinuosity = profiles::sinuosity_median(&drainage.reaches, |k| lengths[k]);
        value["stream_sinuosity_median"] =
            serde_json::json!(sinuosity.is_finite().then_some(sinuosity));
        value["timings_ms"]["drawn sinuosity"] = serde_json::json!(t.elapsed().as_secs_f64() * 1e3);
        // The drainage model's measures, at the top level (docs/rivers.md).
        if let serde_json::Value::Object(measures) = serde_json::to_value(&drainage.measures)? {
            for (key, v) in measures {
                value[key] = v;
            }
        }
        value["river_systems"] = serde_json::json!(rivers);
    }
    let path = dir.join("stats.json");
    riverplanet::export::files::write_bytes(
        &path,
        serde_json::to_string_pretty(&value)?.as_bytes(),
    )?;
    set.commit()?;
    Ok(())
}
