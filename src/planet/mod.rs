//! The planet model (Chapters 3 and 4): the cube-sphere, continents, mountains and diamond-square heights. Only
//! the coarse levels are precomputed ([`PRECOMPUTED_LEVEL`]); every finer patch gets its heights on demand from its
//! parent's (`detail`).

pub mod air;
pub mod atmosphere;
pub mod coasts;
pub mod continents;
pub mod cube;
pub mod detail;
pub mod erosion;
pub mod heights;
pub mod lakes;
pub mod mountains;
pub mod noise;
pub mod relief;
pub mod terrain_file;

use std::{path::Path, time::Instant};

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

pub use self::mountains::Mountain;
use self::{
    continents::{ContinentError, ContinentImage, FeaturePoints},
    cube::PatchId,
    cube::FACES,
    detail::{DetailRule, PatchHeights},
    heights::{area_weight, FaceLattice},
    mountains::seed_mountains,
    terrain_file::{TerrainFile, TerrainFileError},
};
use crate::{
    config::{Config, ReliefModel, RiverModel},
    drainage::{self, grid::SphereGrid, Drainage},
};

/// The finest level precomputed at start-up (unless `max-level-of-detail` or the base lattice says otherwise):
/// with 33 vertices a lattice of 513 points per face edge, 6 x 513^2 f32 = 6.3 MB. Finer levels are made per
/// patch when first needed, so no start-up cost or memory depends on `max-level-of-detail`.
pub const PRECOMPUTED_LEVEL: u32 = 4;

/// Longitude and latitude in degrees of a direction: latitude from the equator towards +Y (north), longitude
/// from +X, east (towards -Z) positive.
pub fn lon_lat(p: DVec3) -> (f64, f64) {
    let p = p.normalize();
    (
        (-p.z).atan2(p.x).to_degrees(),
        p.y.clamp(-1.0, 1.0).asin().to_degrees(),
    )
}

/// The unit direction at a longitude and latitude in degrees: the inverse of [`lon_lat`].
pub fn direction_at(lon: f64, lat: f64) -> DVec3 {
    let (lon, lat) = (lon.to_radians(), lat.to_radians());
    DVec3::new(lat.cos() * lon.cos(), lat.sin(), -lat.cos() * lon.sin())
}

/// Problems generating a planet.
#[derive(Debug, thiserror::Error)]
pub enum PlanetError {
    /// The continents image cannot be used.
    #[error(transparent)]
    Continents(#[from] ContinentError),
    /// The terrain file cannot be used.
    #[error(transparent)]
    TerrainFile(#[from] TerrainFileError),
    /// The base lattice does not fit the patch levels.
    #[error("base-resolution {base} {rule}")]
    BaseResolution {
        /// The configuration's `base-resolution`.
        base: u32,
        /// What it must be.
        rule: String,
    },
}

/// What `generate` reports.
#[derive(Clone, Debug, Serialize)]
pub struct PlanetStats {
    /// The master seed the planet was made from.
    pub seed: u32,
    /// Share of the sphere's area above sea level on the precomputed lattice, in percent.
    pub landmass_percent: f64,
    /// Share of the sphere's area that the continents (Voronoi or image, after perturbation) cover, in percent.
    pub continent_percent: f64,
    /// Continents of the Voronoi map (0 when they come from an image or a terrain file).
    pub continents: usize,
    /// Mountains seeded (the thesis's relief; 0 otherwise).
    pub mountains: usize,
    /// The Voronoi weight that gave the landmass share (4.1), after the corrections.
    pub continental_weight: f64,
    /// The lowest height of the precomputed lattice.
    pub min_height: f32,
    /// The highest height of the precomputed lattice.
    pub max_height: f32,
    /// The patch level whose vertices are the base lattice's points.
    pub base_level: u32,
    /// The level of the precomputed lattice (`memory_bytes`); finer levels are generated per patch on demand.
    pub precomputed_level: u32,
    /// Cells per face edge of the precomputed lattice.
    pub precomputed_cells: u32,
    /// Milliseconds per stage (summed over the landmass corrections).
    pub timings_ms: std::collections::BTreeMap<String, f64>,
    /// Bytes of the precomputed lattice.
    pub memory_bytes: u64,
    /// Geomorphology's measures of the planet's form (docs/geomorphology.md).
    #[serde(flatten)]
    pub form: crate::geomorphology::WorldMeasures,
    /// How far the erosion ran (the eroded relief only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub erosion: Option<erosion::ErosionReport>,
}

/// A generated planet: its precomputed coarse heights, the rule that refines them to any level, and its
/// mountains.
pub struct Planet {
    /// The sphere's radius.
    pub radius: f64,
    /// The sea's height above the sphere.
    pub sea_level: f32,
    /// Vertices per patch edge (33).
    pub vertices: u32,
    /// The deepest level of detail drawn.
    pub max_level: u32,
    /// The heights of level `precomputed_level` (every coarser level is a sub-sampling of it).
    pub lattice: FaceLattice,
    /// The level `lattice` holds.
    pub precomputed_level: u32,
    /// The diamond-square rule of every finer level.
    pub rule: DetailRule,
    /// Per level 0..=precomputed_level, per patch (face, then row-major): lowest and highest height of the
    /// patch's points, border included.
    bounds: Vec<Vec<(f32, f32)>>,
    /// Per level 1..=precomputed_level (index level - 1), per patch: how far the precomputed lattice stands from
    /// its parent's bilinear surface over the patch at most (`FaceLattice::quadrant_deviations`).
    quadrant_deviations: Vec<Vec<f32>>,
    /// The thesis's mountains (4.2; empty with the drainage model).
    pub mountains: Vec<Mountain>,
    /// The Voronoi continents' feature points (`None` when the continents come from an image or a file).
    pub features: Option<FeaturePoints>,
    /// The rivers and lakes of the drainage model (`None` for the thesis's model).
    pub drainage: Option<Drainage>,
    /// What `generate` reports.
    pub stats: PlanetStats,
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

impl Planet {
    /// Generates the planet of `config` with `seed` (Chapter 4). `progress` is told each finished stage.
    pub fn generate(
        config: &Config,
        seed: u32,
        mut progress: impl FnMut(&str),
    ) -> Result<Self, PlanetError> {
        let p = &config.planet;
        let r = &config.rendering;
        let cells_per_patch = r.vertices - 1;
        let base_cells = p.base_resolution - 1;
        let base_level = config
            .base_level()
            .ok_or_else(|| PlanetError::BaseResolution {
                base: p.base_resolution,
                rule: config.base_resolution_rule(),
            })?;
        let mut timings = std::collections::BTreeMap::<String, f64>::new();
        let mut time = |stage: &str, since: Instant| {
            *timings.entry(stage.to_string()).or_default() += ms_since(since)
        };
        let seed64 = seed as u64;
        let precomputed_level = PRECOMPUTED_LEVEL.min(r.max_level_of_detail).max(base_level);
        let rule = DetailRule::new(seed, p.detail_amplitude, p.flat_detail);

        // Heights from a file (beyond the thesis): read and checked before any work.
        let t = Instant::now();
        let terrain = match p.relief_model {
            ReliefModel::File => Some(TerrainFile::load(
                Path::new(&p.terrain_file),
                (p.terrain_height_scale, p.terrain_height_offset),
                p.sea_level_height,
                p.terrain_bounds,
            )?),
            _ => None,
        };
        // A region lies on the procedural planet (eroded relief).
        let region = terrain.as_ref().filter(|t| t.is_region());
        if let Some(region) = region {
            region.check_spans_cells(&p.terrain_file, base_cells)?;
        }
        let whole_file = terrain.as_ref().filter(|t| !t.is_region());
        // The eroded relief, also around a region; a whole planet's file heights are the relief.
        let eroded = p.relief_model == ReliefModel::Eroded || region.is_some();
        if terrain.is_some() {
            time("terrain file", t);
        }

        // Continents on the base lattice (4.1).
        let t = Instant::now();
        let base = FaceLattice::new(base_cells, 0.0);
        let points: Vec<(usize, u32, u32)> = (0..FACES)
            .flat_map(|f| {
                (0..=base_cells).flat_map(move |j| (0..=base_cells).map(move |i| (f, i, j)))
            })
            .collect();
        let cell_angle = std::f64::consts::FRAC_PI_2 / base_cells as f64;
        let amplitude = p.coast_perturbation as f64 * cell_angle;
        let weights: Vec<f64> = points
            .iter()
            .map(|&(_, i, j)| area_weight(base_cells, i, j))
            .collect();
        // The continent map as a function of a threshold: an image gives land directly; the Voronoi diagram gives
        // each point's ratio of continental to water distance, and a weight turns ratios into land.
        // A terrain file's heights at the base lattice's points, which give its land and sea.
        let file_heights: Option<Vec<f32>> = whole_file.map(|terrain| {
            points
                .par_iter()
                .map(|&(f, i, j)| terrain.height_towards(base.direction(base.key(f, i, j))) as f32)
                .collect()
        });
        let (image_land, ratios, features) = if let Some(heights) = &file_heights {
            let sea_level = p.sea_level_height;
            (
                Some(heights.iter().map(|&h| h > sea_level).collect()),
                Vec::new(),
                None,
            )
        } else if p.continents_from_file {
            let image = ContinentImage::load(Path::new(&p.continents_image))?;
            let land: Vec<bool> = points
                .par_iter()
                .map(|&(f, i, j)| {
                    let d = base.direction(base.key(f, i, j));
                    image.is_land(continents::perturb(seed64, d, amplitude))
                })
                .collect();
            (Some(land), Vec::new(), None)
        } else {
            let features = FeaturePoints::generate(seed64, p.continents as usize);
            let ratios: Vec<f64> = points
                .par_iter()
                .map(|&(f, i, j)| {
                    let d = base.direction(base.key(f, i, j));
                    features.ratio(continents::perturb(seed64, d, amplitude))
                })
                .collect();
            (None, ratios, Some(features))
        };
        time("continents", t);
        progress("continents");

        // Diamond-square averages coastal points with the sea floor, which moves coasts inland. The share is
        // measured on the finished heights and the Voronoi threshold corrected (at most twice) until it is
        // within a quarter of a percentage point of the request.
        let target = p.landmass_percentage as f64 / 100.0;
        let mut requested = target;
        let total: f64 = weights.iter().sum();
        let mut attempt = 0;
        let mut erosion = None;
        let drainage_model = config.river.model == RiverModel::Drainage;
        let grid = drainage_model.then(|| {
            let t = Instant::now();
            let grid = SphereGrid::new(&FaceLattice::new(base_cells, 0.0));
            time("drainage grid", t);
            grid
        });
        loop {
            let t = Instant::now();
            let (land, weight) = match &image_land {
                Some(land) => (land.clone(), 0.0),
                None => {
                    let weight = continents::weight_for_share(
                        &ratios,
                        &weights,
                        requested.clamp(0.001, 0.999),
                    );
                    (
                        ratios
                            .iter()
                            .map(|r| r * weight < 1.0)
                            .collect::<Vec<bool>>(),
                        weight,
                    )
                }
            };
            let land = match &grid {
                Some(grid) if eroded => coasts::roughen(grid, &base, &points, &land, seed64),
                _ => land,
            };
            let continent_share: f64 = land
                .iter()
                .zip(&weights)
                .filter(|(l, _)| **l)
                .map(|(_, w)| w)
                .sum::<f64>()
                / total;
            let mut base = FaceLattice::new(base_cells, 0.0);
            for (k, &(f, i, j)) in points.iter().enumerate() {
                let index = base.index(f, i, j);
                base.data[index] = match (&file_heights, land[k]) {
                    (Some(heights), _) => heights[k],
                    (None, true) => p.continent_height,
                    (None, false) => p.ocean_height,
                };
            }
            let (mountains, drainage) = match &grid {
                None => {
                    let mountains = seed_mountains(&mut base, config, seed64);
                    time("mountains", t);
                    progress("mountains");
                    (mountains, None)
                }
                Some(grid) => {
                    if eroded {
                        erosion = Some(erosion::raise(
                            &mut base,
                            grid,
                            p,
                            config.river.lake_depth as f64,
                            seed64,
                        ));
                    } else if p.relief_model != ReliefModel::File {
                        relief::raise(&mut base, grid, p, seed64);
                    }
                    if let Some(region) = region {
                        region.paste(&mut base);
                    }
                    time("relief", t);
                    progress("relief");
                    let t = Instant::now();
                    let drainage = drainage::drain(&mut base, grid, p, &config.river);
                    time("drainage", t);
                    progress("drainage");
                    (Vec::new(), Some(drainage))
                }
            };

            let t = Instant::now();
            let mut heights =
                diamond_square(&base, &rule, base_level, precomputed_level, &mut progress);
            time("diamond-square", t);
            if let Some(terrain) = &terrain {
                let t = Instant::now();
                terrain.add_detail(&base, &mut heights);
                time("terrain file detail", t);
            }

            let t = Instant::now();
            let (landmass, min_height, max_height) = measure(&heights, p.sea_level_height);
            time("measure", t);
            attempt += 1;
            if image_land.is_some() || (landmass - target).abs() <= 0.0025 || attempt == 3 {
                break Ok(Self::finish(
                    config,
                    (heights, precomputed_level, rule),
                    (mountains, drainage),
                    features,
                    PlanetStats {
                        seed,
                        landmass_percent: landmass * 100.0,
                        continent_percent: continent_share * 100.0,
                        continents: if p.continents_from_file || whole_file.is_some() {
                            0
                        } else {
                            p.continents as usize
                        },
                        mountains: 0,
                        continental_weight: weight,
                        min_height,
                        max_height,
                        base_level,
                        precomputed_level,
                        precomputed_cells: cells_per_patch << precomputed_level,
                        timings_ms: timings,
                        memory_bytes: 0,
                        form: Default::default(),
                        erosion,
                    },
                ));
            }
            requested += target - landmass;
        }
    }

    fn finish(
        config: &Config,
        (lattice, precomputed_level, rule): (FaceLattice, u32, DetailRule),
        (mountains, drainage): (Vec<Mountain>, Option<Drainage>),
        features: Option<FeaturePoints>,
        mut stats: PlanetStats,
    ) -> Self {
        stats.mountains = mountains.len();
        let bounds = lattice.patch_bounds_pyramid(precomputed_level, config.rendering.vertices);
        let quadrant_deviations =
            lattice.quadrant_deviations(precomputed_level, config.rendering.vertices);
        stats.memory_bytes = lattice.bytes();
        let t = Instant::now();
        let sea_level = config.planet.sea_level_height;
        stats.form = crate::geomorphology::measure(
            &lattice,
            |d| height_on(&lattice, d) > sea_level,
            (
                sea_level as f64,
                config.planet.max_mountain_height as f64,
                config.planet.radius as f64,
            ),
            drainage.as_ref(),
        );
        stats
            .timings_ms
            .insert("geomorphology".to_string(), ms_since(t));
        log::info!("planet: {stats:?}");
        Self {
            radius: config.planet.radius as f64,
            sea_level: config.planet.sea_level_height,
            vertices: config.rendering.vertices,
            max_level: config.rendering.max_level_of_detail,
            lattice,
            precomputed_level,
            rule,
            bounds,
            quadrant_deviations,
            mountains,
            features,
            drainage,
            stats,
        }
    }

    /// The geometric error of a patch of `level` (beyond the thesis, for screen-space-error level of detail): how
    /// far its surface can stand from the finest surface, vertically, plus how far its flat triangles stand
    /// inside the sphere, anywhere on the planet: the largest [`Planet::quadrant_error`] of its children.
    pub fn geometric_error(&self, level: u32) -> f64 {
        let deviation = self
            .quadrant_deviations
            .get(level as usize)
            .map(|d| d.iter().copied().fold(0.0f32, f32::max));
        self.error_with(level, deviation)
    }

    /// The geometric error of drawing `patch`'s parent over `patch`'s area (beyond the thesis, for the
    /// screen-space rule's error field): below the precomputed level, the measured deviation of the precomputed
    /// lattice from the parent's bilinear surface there plus what finer levels add; from it on, what finer levels
    /// add (`DetailRule::remaining_range`, a bound, the same everywhere). Plus the sagitta of the parent's chords.
    pub fn quadrant_error(&self, patch: PatchId) -> f64 {
        let level = patch.level as u32 - 1;
        let deviation = self
            .quadrant_deviations
            .get(level as usize)
            .map(|d| d[patch.index()]);
        self.error_with(level, deviation)
    }

    /// The error of a patch of `level` whose surface stands `deviation` from the precomputed lattice (`None` from
    /// the precomputed level on): that, what finer levels add, and the sagitta `s^2 / (8 radius)` of a chord of
    /// the vertex spacing `s` along a face.
    fn error_with(&self, level: u32, deviation: Option<f32>) -> f64 {
        let detail = match deviation {
            Some(d) => d + self.rule.remaining_range(self.precomputed_level),
            None => self.rule.remaining_range(level),
        } as f64;
        let spacing = self.radius * std::f64::consts::FRAC_PI_2
            / ((self.vertices - 1) as f64 * (1u64 << level) as f64);
        detail + spacing * spacing / (8.0 * self.radius)
    }

    /// The base height at a unit direction, bilinear on the precomputed lattice (finer levels add at most
    /// `rule.remaining_range(precomputed_level)` to it).
    pub fn height_at(&self, direction: DVec3) -> f32 {
        height_on(&self.lattice, direction)
    }

    /// Lowest and highest base height any point of `patch` can have, at any level: its own range for
    /// precomputed levels, the precomputed ancestor's widened by what finer levels add otherwise.
    pub fn patch_bounds(&self, patch: PatchId) -> (f32, f32) {
        let level = (patch.level as u32).min(self.precomputed_level);
        let shift = patch.level as u32 - level;
        let ancestor = PatchId {
            level: level as u8,
            x: patch.x >> shift,
            y: patch.y >> shift,
            ..patch
        };
        let (lo, hi) = self.bounds[level as usize][ancestor.index()];
        let extra = if shift > 0 {
            self.rule.remaining_range(level)
        } else {
            0.0
        };
        (lo - extra, hi + extra)
    }

    /// Whether a direction is land on the base terrain (above sea level).
    pub fn is_land(&self, direction: DVec3) -> bool {
        self.height_at(direction) > self.sea_level
    }

    /// The heights of any patch on the CPU: cut from the precomputed lattice, or refined step by step from its
    /// nearest precomputed ancestor (the reference the GPU path is tested against).
    pub fn patch_heights(&self, patch: PatchId) -> PatchHeights {
        if patch.level as u32 <= self.precomputed_level {
            return self.lattice.patch_heights(patch, self.vertices);
        }
        let parent = self.patch_heights(patch.parent().expect("level > 0"));
        detail::refine(&parent, patch, &self.rule)
    }

    /// Lowest and highest height any level can reach: the precomputed range widened by what finer levels add.
    pub fn height_bounds(&self) -> (f32, f32) {
        let extra = self.rule.remaining_range(self.precomputed_level);
        (self.stats.min_height - extra, self.stats.max_height + extra)
    }

    /// The whole planet's heights at `level` as one lattice per face (for images): sub-sampled from the
    /// precomputed lattice, or assembled from every patch of that level, made level by level from their
    /// parents as the renderer makes them.
    pub fn face_lattice(&self, level: u32) -> FaceLattice {
        self.lattice
            .refined_to(self.precomputed_level, level, &self.rule, self.vertices)
    }
}

/// The height of `lattice` at a unit direction, bilinear between its points.
pub fn height_on(lattice: &FaceLattice, direction: DVec3) -> f32 {
    let (face, u, v) = cube::face_of(direction);
    let c = lattice.cells as f64;
    let x = ((u + 1.0) * 0.5 * c).clamp(0.0, c);
    let y = ((v + 1.0) * 0.5 * c).clamp(0.0, c);
    let (i, j) = (
        (x.floor() as u32).min(lattice.cells - 1),
        (y.floor() as u32).min(lattice.cells - 1),
    );
    let (fx, fy) = ((x - i as f64) as f32, (y - j as f64) as f32);
    let h = |di, dj| lattice.get(face, i + di, j + dj);
    let bottom = h(0, 0) * (1.0 - fx) + h(1, 0) * fx;
    let top = h(0, 1) * (1.0 - fx) + h(1, 1) * fx;
    bottom * (1.0 - fy) + top * fy
}

/// Spreads the base lattice onto the lattice of level `to` and runs diamond-square from the base level up to it
/// (3.6), by the same rule as the per-patch step.
fn diamond_square(
    base: &FaceLattice,
    rule: &DetailRule,
    base_level: u32,
    to: u32,
    progress: &mut impl FnMut(&str),
) -> FaceLattice {
    let scale = 1u32 << (to - base_level);
    let mut heights = FaceLattice::new(base.cells * scale, 0.0);
    for f in 0..FACES {
        for j in 0..=base.cells {
            for i in 0..=base.cells {
                let index = heights.index(f, i * scale, j * scale);
                heights.data[index] = base.get(f, i, j);
            }
        }
    }
    for level in base_level + 1..=to {
        heights.diamond_square_step(rule, 1 << (to - level), level);
        progress("diamond-square level");
    }
    heights
}

/// The area share above sea level, and the height range, of a lattice.
fn measure(heights: &FaceLattice, sea_level: f32) -> (f64, f32, f32) {
    let side = heights.side();
    let c = heights.cells;
    // Rows in parallel, summed in row order: a parallel reduction adds in an order that depends on the thread
    // count, and the land share then differed in its last digits between 1 and 2 threads.
    let rows: Vec<(f64, f64, f32, f32)> = (0..FACES * side)
        .into_par_iter()
        .map(|row| {
            let (face, j) = (row / side, (row % side) as u32);
            let mut acc = (0.0, 0.0, f32::MAX, f32::MIN);
            for i in 0..=c {
                let h = heights.get(face, i, j);
                let w = area_weight(c, i, j);
                acc.1 += w;
                if h > sea_level {
                    acc.0 += w;
                }
                acc.2 = acc.2.min(h);
                acc.3 = acc.3.max(h);
            }
            acc
        })
        .collect();
    let (land, total, lo, hi) = rows
        .into_iter()
        .fold((0.0, 0.0, f32::MAX, f32::MIN), |a, b| {
            (a.0 + b.0, a.1 + b.1, a.2.min(b.2), a.3.max(b.3))
        });
    (land / total, lo, hi)
}
