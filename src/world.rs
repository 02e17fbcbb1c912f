//! A planet with its rivers, built from a configuration and a seed: what `render`, `view` and `bench` share.

use crate::{
    config::Config,
    planet::{Planet, PlanetError},
    river::network::RiverNetwork,
};

pub struct World {
    pub config: Config,
    pub seed: u32,
    pub planet: Planet,
    pub network: RiverNetwork,
}

impl World {
    /// Generates the planet (Chapter 4) and its river network (Chapter 5).
    pub fn build(config: &Config, seed: u32) -> Result<Self, PlanetError> {
        let planet = Planet::generate(config, seed, |_| {})?;
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
