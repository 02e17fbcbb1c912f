//! Make a planet and read it from Rust: its land, its relief's geomorphology, its drainage network and heights
//! anywhere on the sphere. No GPU needed.
//!
//! `cargo run --release --example planet [CONFIG.xml] [SEED]` (default: config/planet.xml, its seed).

use anyhow::Context as _;
use glam::DVec3;
use riverplanet::{config::Config, world::World};

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args.next().unwrap_or_else(|| "config/planet.xml".into());
    let config = Config::load(path.as_ref()).with_context(|| format!("reading {path}"))?;
    let seed = match args.next() {
        Some(s) => s
            .parse()
            .with_context(|| format!("seed {s:?} is not a whole number"))?,
        None => config.resolve_seed(),
    };
    // The planet (continents, relief, lakes, drainage) and its rivers, as `riverplanet generate` builds them.
    let world = World::build(&config, seed)?;
    let stats = &world.planet.stats;
    let form = &stats.form;
    println!("{path}, seed {seed}: radius {}", world.planet.radius);
    println!(
        "  land {:.1} %, coast dimension {:.3}, land below / above the band edges {:?} %",
        stats.landmass_percent,
        form.coast.coast_dimension,
        form.land_height_bands
            .iter()
            .map(|b| (b * 10.0).round() / 10.0)
            .collect::<Vec<_>>()
    );
    if let Some(drainage) = &world.planet.drainage {
        let m = &drainage.measures;
        println!(
            "  {} reaches, {} lakes, Strahler order {}, Horton ratio {:.2}, Hack exponent {:.3}",
            m.reaches, m.lakes, m.strahler_max, m.bifurcation_ratio, m.hack_exponent
        );
    }
    println!("  {} river systems drawn", world.network.systems.len());
    // Heights anywhere: a unit direction from the planet's centre.
    let mouth = world
        .network
        .systems
        .first()
        .map(|s| ("first river's mouth", s.mouth));
    for (name, direction) in [("north pole", DVec3::Z), ("0 N 0 E", DVec3::X)]
        .into_iter()
        .chain(mouth)
    {
        let d = direction.normalize();
        println!(
            "  {name}: height {:.2} ({})",
            world.planet.height_at(d),
            if world.planet.is_land(d) {
                "land"
            } else {
                "sea"
            }
        );
    }
    Ok(())
}
