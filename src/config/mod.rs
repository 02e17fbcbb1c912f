//! The XML configuration of Table 6.1 and Appendix A, validated into typed values (read.rs reads the file through
//! one table per section).
//!
//! The thesis's Appendix A file is accepted exactly as printed: C-style float suffixes (`1024.0f`) and the stray
//! `>` in `<continents-from-file>>false</continents-from-file>`. Every other deviation is an error that names the
//! element, the value and the valid range. Parameters beyond Table 6.1 (needed by the implementation) have
//! defaults and are documented in `docs/configuration.md`.

use std::path::Path;

use serde::Serialize;

mod read;
mod rules;
pub use read::elements;

/// A configuration problem: which file, which element, what was wrong.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    // The reason is in the message, not a source: printed with its chain, it appeared twice.
    /// The file cannot be read.
    #[error("cannot read configuration file {path}: {reason}")]
    Read {
        /// The file.
        path: String,
        /// The operating system's reason.
        reason: String,
    },
    /// The file is not well-formed XML.
    #[error("{path}: malformed configuration XML: {message}")]
    Xml {
        /// The file.
        path: String,
        /// The parser's message, with the position.
        message: String,
    },
    /// An element no section has.
    #[error("{path}: unknown element {detail}")]
    UnknownElement {
        /// The file.
        path: String,
        /// The element, its section, and the names that section has.
        detail: String,
    },
    /// A value out of its range or of the wrong kind.
    #[error("{path}: <{element}> = '{value}' is invalid: {expected}")]
    Value {
        /// The file.
        path: String,
        /// The element.
        element: String,
        /// What the file says.
        value: String,
        /// The valid range or names.
        expected: String,
    },
}

/// Lattice cells per face edge at the deepest level, at most.
pub const MAX_LATTICE_CELLS: u32 = 1 << 30;

/// `<planet-attributes>`: Table 6.1 plus the base-terrain parameters of Chapter 4.
#[derive(Clone, Debug, Serialize)]
pub struct PlanetConfig {
    /// The sphere's radius, in the configuration's length unit (Table 6.1).
    pub radius: f32,
    /// Continents of the Voronoi continent map (4.1).
    pub continents: u32,
    /// The share of the surface above sea level, in percent (4.1; corrected after diamond-square).
    pub landmass_percentage: f32,
    /// The sea's height above the sphere.
    pub sea_level_height: f32,
    /// The highest mountain's height (4.2); the relief scale of the drainage model.
    pub max_mountain_height: f32,
    /// The atmosphere shell's thickness (beyond the thesis: docs/atmosphere.md).
    pub atmosphere_height: f32,
    /// `-1` in the file: pick a seed at start (logged). Resolved by [`Config::resolve_seed`].
    pub master_seed: i64,
    /// Continents from `continents_image` instead of the Voronoi map (Appendix A).
    pub continents_from_file: bool,
    /// Image read when `continents_from_file` is true (equirectangular, land bright / sea dark); in a file,
    /// relative to the file's folder (the default, config/continents.png, to the working folder).
    pub continents_image: String,
    /// Mountains (3x3 masks) seeded per continent (4.2).
    pub mountains_per_continent: u32,
    /// Height of the eight cells around a mountain top, as a fraction of `max-mountain-height` (4.2).
    pub mountain_shoulder_factor: f32,
    /// Height of continental cells before diamond-square detail.
    pub continent_height: f32,
    /// Height of ocean cells before diamond-square detail.
    pub ocean_height: f32,
    /// Maximum step of the coast perturbation filter, in cells of the coarsest heightmap (4.1).
    pub coast_perturbation: f32,
    /// Diamond-square displacement at level 0, in height units; halves each level (3.6).
    pub detail_amplitude: f32,
    /// The share of that displacement on level ground, growing to all of it on slopes (beyond the thesis,
    /// `planet::detail::DetailRule`); 1: the thesis's displacement everywhere.
    pub flat_detail: f32,
    /// Cells per face edge of the coarsest heightmap on which continents are built: 2^n+1.
    pub base_resolution: u32,
    /// How the relief is made (the thesis's square mountains, or the drainage model's carved or eroded relief).
    pub relief_model: ReliefModel,
    /// Eroded relief (beyond the thesis): the lowlands' uplift grows inland by this share of itself per radian
    /// from the sea, so continental interiors stand higher than their coastal plains (0: one lowland uplift).
    pub interior_rise: f32,
    /// Eroded relief (beyond the thesis): hillslope diffusivity of the young relief while its drainage network
    /// forms (unit-sphere area per model time; 2e-4 by default with the drainage model, 0: the rivers alone).
    pub network_diffusivity: f32,
    /// Relief `file` (beyond the thesis): the planet's heights as an equirectangular raster (TIFF, OpenEXR or
    /// 16-bit PNG; docs/planet.md, "Heights from a file"), the whole sphere or a region; in a file, relative to
    /// the file's folder.
    pub terrain_file: String,
    /// Where `terrain_file` lies, `[west, south, east, north]` in degrees, over its GeoTIFF tags; `None`: from
    /// the tags, or the whole sphere.
    pub terrain_bounds: Option<[f64; 4]>,
    /// A 16-bit PNG terrain's heights: `terrain-height-offset + terrain-height-scale x value`, where no JSON
    /// beside the file gives them.
    pub terrain_height_scale: f32,
    /// See `terrain_height_scale`.
    pub terrain_height_offset: f32,
}

/// How the land gets its relief.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ReliefModel {
    /// Chapter 4: a plateau at `continent-height` with 3x3 mountain masks (the thesis's river model needs it).
    Thesis,
    /// Beyond the thesis: ridged noise rising from the coasts, with valleys carved around the rivers afterwards
    /// (docs/planet.md, "Relief of the drainage model").
    Carved,
    /// Beyond the thesis, the default: tectonic uplift balanced by stream-power erosion (docs/planet.md, "Relief
    /// from uplift and erosion"); the rivers are the ones the erosion made.
    Eroded,
    /// Beyond the thesis: the heights of `terrain-file`, a whole planet's raster (docs/planet.md, "Heights from a
    /// file"); its valleys are the data's, so rivers follow them as on eroded relief.
    File,
}

impl ReliefModel {
    /// Whether the relief has its valleys before any river is drawn (eroded or measured), so rivers keep to them:
    /// beds cut into the valley floors rather than valleys carved around the rivers, and meanders on gentle slopes.
    pub fn has_valleys(self) -> bool {
        matches!(self, ReliefModel::Eroded | ReliefModel::File)
    }

    /// The default `source-area` of the drainage model on this relief (world units squared): eroded relief drains
    /// in more branched networks, whose first-order streams start at 300 square units (about two base cells;
    /// docs/geomorphology.md measures Horton's ratio and Strahler's order with it); the carved relief keeps the
    /// 700 it was tuned with. Irrelevant to the thesis's model.
    pub fn source_area(self) -> f32 {
        match self {
            ReliefModel::Eroded | ReliefModel::File => 300.0,
            ReliefModel::Carved | ReliefModel::Thesis => 700.0,
        }
    }
}

impl crate::named::Named for ReliefModel {
    const ALL: &'static [(&'static str, Self)] = &[
        ("thesis", Self::Thesis),
        ("carved", Self::Carved),
        ("eroded", Self::Eroded),
        ("file", Self::File),
    ];
}

/// Where rivers come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RiverModel {
    /// Chapter 5: one river per mountain, a random walk to the nearest sea, over the thesis's relief.
    Thesis,
    /// Beyond the thesis (docs/rivers.md): relief with ranges and valleys, water routed over the whole sphere,
    /// rivers as trees that join at confluences and end in the sea or in lakes.
    Drainage,
}

impl crate::named::Named for RiverModel {
    const ALL: &'static [(&'static str, Self)] =
        &[("thesis", Self::Thesis), ("drainage", Self::Drainage)];
}

/// `<river-attributes>`: Table 6.1 plus the river-generation parameters of Chapter 5.
#[derive(Clone, Debug, Serialize)]
pub struct RiverConfig {
    /// The thesis's random-walk rivers, or the drainage network (the default).
    pub model: RiverModel,
    /// Drainage model: the drainage area (world units squared) at which a river begins.
    pub source_area: f32,
    /// Drainage model: how deep a depression must be (height units) to be kept as a lake.
    pub lake_depth: f32,
    /// How far from a river its samples shape the terrain (Table 6.1, Procedure 3).
    pub influence_distance: f32,
    /// The depth of the river basins (Procedure 5).
    pub basin_depth: f32,
    /// How far the water surface lies below the basin's top (Procedure 5).
    pub basin_water_offset: f32,
    /// A river's width at its source (5.1).
    pub starting_width: f32,
    /// The narrowest river drawn (tributaries and finer streams).
    pub min_width: f32,
    /// The width at the mouth, as a multiple of the starting width (5.1).
    pub ending_factor: f32,
    /// Segments per subdivision (5.2.1).
    pub segments: u32,
    /// Subdivision levels included in each river's convex hull (5.2.3: the thesis uses 3).
    pub hull_levels: u32,
    /// Probability that a segment spawns a tributary when subdivided (5.2.3).
    pub tributary_probability: f32,
    /// Largest random displacement of a knot when a segment is subdivided, as a fraction of segment length / pieces
    /// (5.2.2).
    pub displacement: f32,
    /// Beyond the thesis, drainage model on eroded relief: rivers too narrow to meander on the base lattice meander
    /// in the pieces that draw them at finer levels (docs/rivers.md, "Meanders below the base lattice"); `false`:
    /// the thesis's random displacement only below the base lattice, for comparison.
    pub fine_meanders: bool,
    /// Directions tried per mountain before it is given up as a river source (5.2.1).
    pub max_attempts: u32,
    /// Samples per half river width (6.4: "three sample points for every distance half the width").
    pub samples_per_half_width: u32,
    /// Beyond the thesis: samples at most this many per vertex spacing along a river (0: no limit, the thesis's
    /// rule). On a planet whose rivers are many orders of magnitude narrower than a coarse patch, the thesis's
    /// rule gives a coarse patch millions of samples for detail its vertices cannot show.
    pub samples_per_vertex_spacing: u32,
    /// Drainage model: patch levels above the base lattice's whose own streams are drawn (each routed anew,
    /// docs/rivers.md "Rivers at every scale"); 0 draws the base network alone.
    pub stream_levels: u32,
}

/// How the level of detail picks a patch's level (6.2.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LodRule {
    /// Beyond the thesis (the default of the drainage model): refine while a level's error would cover more than
    /// `pixel-error` pixels.
    ScreenSpaceError,
    /// The thesis's Eq. 6.1 (the default of the thesis's model): refine while nearer than radius x switch factor
    /// / 2^level.
    Distance,
}

impl LodRule {
    /// The rule of a run: the one asked for; else, without morphing, Eq. 6.1 (the thesis's level of detail is Eq.
    /// 6.1 with instant switching); else the configuration's.
    pub fn for_run(asked: Option<LodRule>, morphing: bool, configured: LodRule) -> LodRule {
        match asked {
            Some(rule) => rule,
            None if !morphing => LodRule::Distance,
            None => configured,
        }
    }
}

impl crate::named::Named for LodRule {
    const ALL: &'static [(&'static str, Self)] = &[
        ("screen-space-error", Self::ScreenSpaceError),
        ("distance", Self::Distance),
    ];
}

/// How the terrain is coloured (8.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum TerrainColours {
    /// The thesis's Fig. 8.2 (the default of the thesis's model): sand, dirt, grass, rock and snow by height alone.
    Height,
    /// Beyond the thesis (the default of the drainage model; docs/rendering.md, "Climate"): the same bands moved by
    /// latitude and aridity, as climate places them: a snow line that falls from the tropics to the poles (ice caps
    /// and polar sea ice), tundra and alpine rock below it, deserts and steppe in the subtropical dry belts, forest
    /// where it is wet, sand on the beaches only.
    Climate,
}

impl crate::named::Named for TerrainColours {
    const ALL: &'static [(&'static str, Self)] =
        &[("height", Self::Height), ("climate", Self::Climate)];
}

/// `<rendering-attributes>`: Table 6.1 plus the run-time budgets.
#[derive(Clone, Debug, Serialize)]
pub struct RenderingConfig {
    /// Vertices per patch edge, 2^n + 1 (Table 6.1).
    pub vertices: u32,
    /// The deepest level of detail drawn.
    pub max_level_of_detail: u32,
    /// The switchFactor of Eq. 6.1 (the distance rule).
    pub level_of_detail_switch_factor: f32,
    /// The thesis's distance rule (Eq. 6.1) or the screen-space-error rule (beyond the thesis).
    pub level_of_detail_rule: LodRule,
    /// Screen-space-error rule: the geometric error, in pixels, a patch may show before it is refined.
    pub pixel_error: f32,
    /// Screen-space-error rule, beyond the thesis: how many pixels the banks of a river painted from its vertices
    /// may stand from where they are (`runtime::lod::painted_bank_error`) before its patch is refined; 0: rivers
    /// do not refine the mesh (the screen-space rule before it).
    pub river_pixel_error: f32,
    /// Patch textures resident at once (bindless slots); least recently used are evicted beyond it.
    pub max_resident_patches: u32,
    /// New patches generated per frame at most; the rest draw their parent until their data arrives.
    pub new_patches_per_frame: u32,
    /// GPU time per frame for making new patches (base heights and river data), in milliseconds: fewer patches
    /// are made when the measured time per patch says the count would exceed it.
    pub generation_budget_ms: f32,
    /// Memory of resident patch textures at most, in MB (with max-resident-patches, whichever is smaller).
    pub resident_memory_mb: u32,
    /// How the terrain is coloured: the thesis's height bands or climate's.
    pub terrain_colours: TerrainColours,
}

/// A whole configuration: the three sections of Table 6.1.
#[derive(Clone, Debug, Serialize)]
pub struct Config {
    /// `<planet-attributes>`.
    pub planet: PlanetConfig,
    /// `<river-attributes>`.
    pub river: RiverConfig,
    /// `<rendering-attributes>`.
    pub rendering: RenderingConfig,
}

impl Config {
    /// The defaults of a file with `model`: Appendix A's values (`appendix_a`), and for the drainage model the
    /// values config/planet.xml was tuned with (docs/rivers.md): a river where 700
    /// square units drain, a quarter of the diamond-square detail (the relief carries the shape), at most four
    /// samples per vertex spacing (a thousand rivers would give coarse patches millions of samples), the
    /// screen-space-error level of detail and the climate's terrain colours (docs/rendering.md; the thesis's model
    /// keeps the thesis's Eq. 6.1 and height bands).
    pub fn defaults_for(model: RiverModel) -> Self {
        let mut d = Self::appendix_a();
        d.river.model = model;
        if model == RiverModel::Drainage {
            d.planet.relief_model = ReliefModel::Eroded;
            d.planet.detail_amplitude = 2.0;
            d.planet.network_diffusivity = 2e-4;
            d.river.source_area = d.planet.relief_model.source_area();
            d.river.samples_per_vertex_spacing = 4;
            d.river.stream_levels = 1;
            d.rendering.level_of_detail_rule = LodRule::ScreenSpaceError;
            d.rendering.terrain_colours = TerrainColours::Climate;
        }
        d
    }

    /// The values of Appendix A with the thesis's river model, and `master-seed` 1 instead of -1 so the planet is
    /// reproducible: the planet of the thesis's Chapter 9 experiments.
    pub fn appendix_a() -> Self {
        Self {
            planet: PlanetConfig {
                radius: 1024.0,
                continents: 5,
                landmass_percentage: 30.0,
                sea_level_height: 0.4,
                max_mountain_height: 16.0,
                atmosphere_height: 32.0,
                master_seed: 1,
                continents_from_file: false,
                continents_image: "config/continents.png".into(),
                mountains_per_continent: 4,
                mountain_shoulder_factor: 0.5,
                continent_height: 2.0,
                ocean_height: -4.0,
                coast_perturbation: 3.0,
                detail_amplitude: 8.0,
                flat_detail: 1.0,
                base_resolution: 129,
                relief_model: ReliefModel::Thesis,
                interior_rise: 0.0,
                network_diffusivity: 0.0,
                terrain_file: String::new(),
                terrain_bounds: None,
                terrain_height_scale: 1.0,
                terrain_height_offset: 0.0,
            },
            river: RiverConfig {
                model: RiverModel::Thesis,
                source_area: 20000.0,
                lake_depth: 0.5,
                influence_distance: 20.0,
                basin_depth: 0.1,
                basin_water_offset: 0.001,
                starting_width: 2.5,
                min_width: 0.075,
                ending_factor: 2.0,
                segments: 5,
                hull_levels: 3,
                tributary_probability: 0.5,
                displacement: 0.3,
                fine_meanders: true,
                max_attempts: 16,
                samples_per_half_width: 3,
                samples_per_vertex_spacing: 0,
                stream_levels: 0,
            },
            rendering: RenderingConfig {
                vertices: 33,
                max_level_of_detail: 6,
                level_of_detail_switch_factor: 8.0,
                level_of_detail_rule: LodRule::Distance,
                pixel_error: 2.0,
                river_pixel_error: 8.0,
                max_resident_patches: 2048,
                new_patches_per_frame: 64,
                generation_budget_ms: 8.0,
                resident_memory_mb: 256,
                terrain_colours: TerrainColours::Height,
            },
        }
    }
}

impl Default for Config {
    /// The product's default: Appendix A's planet with the drainage model (docs/rivers.md), the planet of
    /// config/planet.xml. The thesis's model is `Config::appendix_a()` and config/thesis.xml.
    fn default() -> Self {
        Self::defaults_for(RiverModel::Drainage)
    }
}

/// The largest configuration file read (the shipped ones are 2-3 KB).
const MAX_FILE_BYTES: u64 = 1 << 20;

/// The text of a configuration file: UTF-8 (with or without a byte-order mark) or UTF-16 with one, as XML allows.
fn decode(bytes: &[u8]) -> Result<String, String> {
    let utf16 = |big_endian: bool| {
        if bytes.len() % 2 != 0 {
            return Err("UTF-16 (by its byte-order mark) of an odd number of bytes".to_string());
        }
        let units: Vec<u16> = bytes[2..]
            .chunks_exact(2)
            .map(|c| match big_endian {
                true => u16::from_be_bytes([c[0], c[1]]),
                false => u16::from_le_bytes([c[0], c[1]]),
            })
            .collect();
        String::from_utf16(&units).map_err(|e| format!("not valid UTF-16: {e}"))
    };
    match bytes {
        [0xFF, 0xFE, ..] => utf16(false),
        [0xFE, 0xFF, ..] => utf16(true),
        [0xEF, 0xBB, 0xBF, rest @ ..] => {
            String::from_utf8(rest.to_vec()).map_err(|e| e.to_string())
        }
        _ => String::from_utf8(bytes.to_vec())
            .map_err(|e| format!("not UTF-8 ({e}), nor UTF-16 with a byte-order mark")),
    }
}

impl Config {
    /// Reads and validates a configuration file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let refuse = |reason: String| ConfigError::Read {
            path: path.display().to_string(),
            reason,
        };
        let bytes = std::fs::metadata(path)
            .map_err(|e| refuse(e.to_string()))?
            .len();
        if bytes > MAX_FILE_BYTES {
            return Err(refuse(format!(
                "{bytes} bytes, more than the {MAX_FILE_BYTES} a configuration may have"
            )));
        }
        let bytes = std::fs::read(path).map_err(|e| refuse(e.to_string()))?;
        let text = decode(&bytes).map_err(refuse)?;
        Self::parse(&text, &path.display().to_string())
    }

    /// The quadtree level whose whole-face lattice the base heightmap is: its cells per face edge are a patch's
    /// (`vertices - 1`) times 2^level, for a level down to `max-level-of-detail`; `None` if there is none.
    pub fn base_level(&self) -> Option<u32> {
        let cells = self.planet.base_resolution - 1;
        (0..=self.rendering.max_level_of_detail)
            .find(|l| (self.rendering.vertices - 1) << l == cells)
    }

    /// What `base-resolution` must be, with the valid values (up to level 6) for these vertices.
    pub fn base_resolution_rule(&self) -> String {
        let (n, max) = (self.rendering.vertices, self.rendering.max_level_of_detail);
        let valid: Vec<String> = (0..=max.min(6))
            .map(|l| (((n - 1) << l) + 1).to_string())
            .collect();
        format!(
            "must be (vertices - 1) x 2^b + 1 for some b <= max-level-of-detail {max} (with vertices {n}: {})",
            valid.join(", ")
        )
    }

    /// The seed to use: the configured one, or for `-1` a fresh one from the clock (logged so a run can be
    /// repeated).
    pub fn resolve_seed(&self) -> u32 {
        if self.planet.master_seed >= 0 {
            return self.planet.master_seed as u32;
        }
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos() as u64)
            .unwrap_or(0);
        let seed = (nanos ^ (nanos >> 32)) as u32;
        log::info!("master-seed -1: picked seed {seed}");
        seed
    }
}
