//! A planet with its rivers, built from a configuration and a seed: what `render`, `view` and `bench` share.

use crate::{
    config::Config,
    planet::{Planet, PlanetError},
    river::network::RiverNetwork,
};

/// A planet and its river network, from one configuration and seed.
pub struct World {
    /// The configuration it was built from.
    pub config: Config,
    /// The seed.
    pub seed: u32,
    /// The planet: base lattice, precomputed heights, drainage.
    pub planet: Planet,
    /// Its rivers.
    pub network: RiverNetwork,
}

impl World {
    /// Generates the planet (Chapter 4) and its river network (Chapter 5).
    pub fn build(config: &Config, seed: u32) -> Result<Self, PlanetError> {
        Self::build_reporting(config, seed, |_| {})
    }

    /// As [`World::build`], telling `stage` what it does: the planet's stages, then `rivers`.
    pub fn build_reporting(
        config: &Config,
        seed: u32,
        mut stage: impl FnMut(&str),
    ) -> Result<Self, PlanetError> {
        let planet = Planet::generate(config, seed, &mut stage)?;
        stage("rivers");
        let network = RiverNetwork::generate(&planet, config, seed);
        log::info!("world: seed {seed}, {} rivers", network.systems.len());
        Ok(Self {
            config: config.clone(),
            seed,
            planet,
            network,
        })
    }
}
