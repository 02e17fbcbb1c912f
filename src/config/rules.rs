//! The rules between elements of a [`Config`] read from a file (read.rs reads each element against its own range):
//! orders among heights, the models that go together, sizes against the planet's radius, the deepest level the
//! lattice holds with these vertices, and the base resolution's level.

use super::{Config, ConfigError, ReliefModel, RiverModel, MAX_LATTICE_CELLS};
use crate::named::Named;

impl Config {
    /// Sizes against the radius: heights beyond a quarter of the radius fold the planet onto itself, rivers wider than
    /// that or draining more than the sphere mean nothing, and air above the radius leaves the f32 shell maths. Each
    /// element alone passed its own range (1e30 included) before these rules.
    fn check_scales(&self, path: &str) -> Result<(), ConfigError> {
        let (planet, river) = (&self.planet, &self.river);
        let radius = planet.radius as f64;
        let quarter = radius / 4.0;
        let widest = river.starting_width as f64 * (river.ending_factor as f64).max(1.0);
        let sphere = 4.0 * std::f64::consts::PI * radius * radius;
        let quarter_of = |element, size| (element, size, quarter, "a quarter of the radius");
        let rules = [
            quarter_of("sea-level-height", planet.sea_level_height.abs() as f64),
            quarter_of("continent-height", planet.continent_height.abs() as f64),
            quarter_of("ocean-height", planet.ocean_height.abs() as f64),
            quarter_of("max-mountain-height", planet.max_mountain_height as f64),
            quarter_of("detail-amplitude", planet.detail_amplitude as f64),
            (
                "atmosphere-height",
                planet.atmosphere_height as f64,
                radius,
                "the radius",
            ),
            quarter_of("basin-depth", river.basin_depth as f64),
            quarter_of("basin-water-offset", river.basin_water_offset as f64),
            quarter_of("lake-depth", river.lake_depth as f64),
            quarter_of("influence-distance", river.influence_distance as f64),
            (
                "ending-factor",
                widest,
                quarter,
                "a quarter of the radius as the widest river (starting-width x ending-factor)",
            ),
            (
                "source-area",
                river.source_area as f64,
                sphere,
                "the sphere's area (4 pi radius^2)",
            ),
        ];
        for (element, size, most, what) in rules {
            if size > most {
                return Err(ConfigError::Value {
                    path: path.to_string(),
                    element: element.to_string(),
                    // Debug writes 3e38 as such, Display as 39 digits.
                    value: format!("{:?}", size as f32),
                    expected: format!("must be at most {what}: {most} with radius {radius}"),
                });
            }
        }
        Ok(())
    }

    /// The rules between elements.
    pub(super) fn check(&self, path: &str) -> Result<(), ConfigError> {
        let error = |element: &str, value: String, expected: String| ConfigError::Value {
            path: path.to_string(),
            element: element.to_string(),
            value,
            expected,
        };
        let (planet, river, rendering) = (&self.planet, &self.river, &self.rendering);
        if planet.sea_level_height <= planet.ocean_height
            || planet.sea_level_height >= planet.continent_height
        {
            return Err(error(
                "sea-level-height",
                planet.sea_level_height.to_string(),
                format!(
                    "must lie between ocean-height ({}) and continent-height ({})",
                    planet.ocean_height, planet.continent_height
                ),
            ));
        }
        // The thesis's rivers start at its square mountains; the drainage model drains any other relief.
        if (planet.relief_model == ReliefModel::Thesis) != (river.model == RiverModel::Thesis) {
            return Err(error(
                "relief-model",
                planet.relief_model.name().to_string(),
                match river.model {
                    RiverModel::Thesis => "must be thesis with river-model thesis".to_string(),
                    RiverModel::Drainage => {
                        "must be eroded, carved or file with river-model drainage".to_string()
                    }
                },
            ));
        }
        // Heights from a file: the file and the relief model name each other.
        match (
            planet.relief_model == ReliefModel::File,
            planet.terrain_file.is_empty(),
        ) {
            (true, true) => {
                return Err(error(
                    "terrain-file",
                    String::new(),
                    "must name a height raster (.tif, .exr or .png) with relief-model file"
                        .to_string(),
                ))
            }
            (false, false) => {
                return Err(error(
                    "relief-model",
                    planet.relief_model.name().to_string(),
                    format!("must be file with terrain-file ({})", planet.terrain_file),
                ))
            }
            _ => {}
        }
        if let (Some(bounds), true) = (planet.terrain_bounds, planet.terrain_file.is_empty()) {
            return Err(error(
                "terrain-bounds",
                format!("{bounds:?}"),
                "places terrain-file: it needs relief-model file and a terrain-file".to_string(),
            ));
        }
        let widest = river.starting_width * river.ending_factor.max(1.0);
        if river.influence_distance <= widest * 0.5 {
            return Err(error(
                "influence-distance",
                river.influence_distance.to_string(),
                format!(
                    "must exceed half the widest river (starting-width x ending-factor / 2 = {})",
                    widest * 0.5
                ),
            ));
        }
        if river.min_width > river.starting_width {
            return Err(error(
                "min-width",
                river.min_width.to_string(),
                format!("must not exceed starting-width ({})", river.starting_width),
            ));
        }
        self.check_scales(path)?;
        // Lattice keys are 32-bit signed integers on the GPU (planet::detail): the finest lattice must keep its
        // cells per face edge, with the border, below 2^31.
        let deepest = MAX_LATTICE_CELLS.ilog2() - (rendering.vertices - 1).ilog2();
        if rendering.max_level_of_detail > deepest {
            return Err(error(
                "max-level-of-detail",
                rendering.max_level_of_detail.to_string(),
                format!(
                    "must be at most {deepest} with vertices {} (at most 2^30 lattice cells per face edge)",
                    rendering.vertices
                ),
            ));
        }
        if self.base_level().is_none() {
            // A base resolution of the file's vertices that only a deeper level reaches: the level is at fault,
            // not base-resolution (which is often not in the file at all).
            let (n, cells) = (rendering.vertices - 1, planet.base_resolution - 1);
            let needed =
                (cells % n == 0 && (cells / n).is_power_of_two()).then(|| (cells / n).ilog2());
            return Err(match needed {
                Some(level) => error(
                    "max-level-of-detail",
                    rendering.max_level_of_detail.to_string(),
                    format!(
                        "must be at least {level}, the level of base-resolution {} with vertices {}",
                        planet.base_resolution, rendering.vertices
                    ),
                ),
                None => error(
                    "base-resolution",
                    self.planet.base_resolution.to_string(),
                    self.base_resolution_rule(),
                ),
            });
        }
        Ok(())
    }
}
