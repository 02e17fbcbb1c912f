//! Export a region of a planet as binary glTF from Rust: the terrain and the water surface with the carved rivers,
//! around the first river's mouth, as `riverplanet export region --format glb` writes it. No GPU needed.
//!
//! `cargo run --release --example export_glb [CONFIG.xml] [OUT.glb] [SEED]` (default: config/planet.xml,
//! river-mouth.glb, the configuration's seed).

use anyhow::Context as _;
use riverplanet::{
    config::Config,
    export::{
        heightmaps::planet_metadata,
        mesh::write_glb,
        region::{sample_region, Region},
    },
    planet::lon_lat,
    world::World,
};

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args.next().unwrap_or_else(|| "config/planet.xml".into());
    let out = args.next().unwrap_or_else(|| "river-mouth.glb".into());
    let config = Config::load(path.as_ref()).with_context(|| format!("reading {path}"))?;
    let seed = match args.next() {
        Some(s) => s
            .parse()
            .with_context(|| format!("seed {s:?} is not a whole number"))?,
        None => config.resolve_seed(),
    };
    let world = World::build(&config, seed)?;
    let mouth = world
        .network
        .systems
        .first()
        .context("this planet has no river")?
        .mouth;
    // Two degrees on a side around the mouth, from the patches of level 7.
    let (lon, lat) = lon_lat(mouth);
    let (lon, lat) = (lon.clamp(-178.0, 178.0), lat.clamp(-88.0, 88.0));
    let level = 7;
    let region = Region::new([lon - 1.0, lat - 1.0, lon + 1.0, lat + 1.0], level)
        .map_err(anyhow::Error::msg)?;
    // The patches are carved in parallel; the last argument hears of each one done (progress).
    let surface = sample_region(
        &world.planet,
        &world.network,
        &config,
        level,
        &region,
        &|_| {},
    );
    let metadata = planet_metadata(&world.planet, seed, level, true);
    let planet = (world.planet.radius, world.planet.sea_level);
    let (terrain, water) = write_glb(out.as_ref(), &region, &surface, planet, &metadata)?;
    println!(
        "{out}: seed {seed}, {} x {} vertices around {lat:.2} N {lon:.2} E, {terrain} terrain and {water} water \
         triangles",
        region.size.0, region.size.1
    );
    Ok(())
}
