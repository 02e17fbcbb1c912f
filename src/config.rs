//! The XML configuration of Table 6.1 and Appendix A, validated into typed values.
//!
//! The thesis's Appendix A file is accepted exactly as printed: C-style float suffixes (`1024.0f`) and the stray
//! `>` in `<continents-from-file>>false</continents-from-file>`. Every other deviation is an error that names the
//! element, the value and the valid range. Parameters beyond Table 6.1 (needed by the implementation) have
//! defaults and are documented in `docs/configuration.md`.

use std::{fmt, path::Path};

use serde::{Deserialize, Serialize};

/// A configuration problem: which file, which element, what was wrong.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read configuration file {path}: {source}")]
    Read {
        path: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}: malformed configuration XML: {message}")]
    Xml { path: String, message: String },
    #[error("{path}: unknown element {detail}")]
    UnknownElement { path: String, detail: String },
    #[error("{path}: <{element}> = '{value}' is invalid: {expected}")]
    Value {
        path: String,
        element: String,
        value: String,
        expected: String,
    },
}

/// The deepest `max-level-of-detail` accepted (33 vertices per patch edge allow 25: see MAX_LATTICE_CELLS).
pub const MAX_LEVEL_OF_DETAIL: u32 = 26;
/// Lattice cells per face edge at the deepest level, at most.
pub const MAX_LATTICE_CELLS: u32 = 1 << 30;

/// `<planet-attributes>`: Table 6.1 plus the base-terrain parameters of Chapter 4.
#[derive(Clone, Debug, Serialize)]
pub struct PlanetConfig {
    pub radius: f32,
    pub continents: u32,
    pub landmass_percentage: f32,
    pub sea_level_height: f32,
    pub max_mountain_height: f32,
    pub atmosphere_height: f32,
    /// `-1` in the file: pick a seed at start (logged). Resolved by [`Config::resolve_seed`].
    pub master_seed: i64,
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
    /// Cells per face edge of the coarsest heightmap on which continents are built: 2^n+1.
    pub base_resolution: u32,
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

/// `<river-attributes>`: Table 6.1 plus the river-generation parameters of Chapter 5.
#[derive(Clone, Debug, Serialize)]
pub struct RiverConfig {
    pub model: RiverModel,
    /// Drainage model: the drainage area (world units squared) at which a river begins.
    pub source_area: f32,
    /// Drainage model: how deep a depression must be (height units) to be kept as a lake.
    pub lake_depth: f32,
    pub influence_distance: f32,
    pub basin_depth: f32,
    pub basin_water_offset: f32,
    pub starting_width: f32,
    pub min_width: f32,
    pub ending_factor: f32,
    pub segments: u32,
    /// Subdivision levels included in each river's convex hull (5.2.3: the thesis uses 3).
    pub hull_levels: u32,
    /// Probability that a segment spawns a tributary when subdivided (5.2.3).
    pub tributary_probability: f32,
    /// Largest random displacement of a knot when a segment is subdivided, as a fraction of segment length / pieces
    /// (5.2.2).
    pub displacement: f32,
    /// Directions tried per mountain before it is given up as a river source (5.2.1).
    pub max_attempts: u32,
    /// Samples per half river width (6.4: "three sample points for every distance half the width").
    pub samples_per_half_width: u32,
    /// Beyond the thesis: samples at most this many per vertex spacing along a river (0: no limit, the thesis's
    /// rule). On a planet whose rivers are many orders of magnitude narrower than a coarse patch, the thesis's
    /// rule gives a coarse patch millions of samples for detail its vertices cannot show.
    pub samples_per_vertex_spacing: u32,
}

/// How the level of detail picks a patch's level (6.2.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LodRule {
    /// Beyond the thesis: refine while a patch's geometric error would cover more than `pixel-error` pixels.
    ScreenSpaceError,
    /// The thesis's Eq. 6.1 (the default): refine while nearer than radius x switch factor / 2^level.
    Distance,
}

/// `<rendering-attributes>`: Table 6.1 plus the run-time budgets.
#[derive(Clone, Debug, Serialize)]
pub struct RenderingConfig {
    pub vertices: u32,
    pub max_level_of_detail: u32,
    pub level_of_detail_switch_factor: f32,
    pub level_of_detail_rule: LodRule,
    /// Screen-space-error rule: the geometric error, in pixels, a patch may show before it is refined.
    pub pixel_error: f32,
    /// Patch textures resident at once (bindless slots); least recently used are evicted beyond it.
    pub max_resident_patches: u32,
    /// New patches generated per frame at most; the rest draw their parent until their data arrives.
    pub new_patches_per_frame: u32,
    /// GPU time per frame for making new patches (base heights and river data), in milliseconds: fewer patches
    /// are made when the measured time per patch says the count would exceed it.
    pub generation_budget_ms: f32,
    /// Memory of resident patch textures at most, in MB (with max-resident-patches, whichever is smaller).
    pub resident_memory_mb: u32,
}

#[derive(Clone, Debug, Serialize)]
pub struct Config {
    pub planet: PlanetConfig,
    pub river: RiverConfig,
    pub rendering: RenderingConfig,
}

impl Config {
    /// The defaults of a file with `model`: Appendix A's values (`appendix_a`), and for the drainage model the
    /// values config/planet.xml was tuned with (docs/rivers.md): a river where 700
    /// square units drain, a quarter of the diamond-square detail (the relief carries the shape), and at most four
    /// samples per vertex spacing (a thousand rivers would give coarse patches millions of samples).
    pub fn defaults_for(model: RiverModel) -> Self {
        let mut d = Self::appendix_a();
        d.river.model = model;
        if model == RiverModel::Drainage {
            d.planet.detail_amplitude = 2.0;
            d.river.source_area = 700.0;
            d.river.samples_per_vertex_spacing = 4;
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
                base_resolution: 129,
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
                max_attempts: 16,
                samples_per_half_width: 3,
                samples_per_vertex_spacing: 0,
            },
            rendering: RenderingConfig {
                vertices: 33,
                max_level_of_detail: 6,
                level_of_detail_switch_factor: 8.0,
                level_of_detail_rule: LodRule::Distance,
                pixel_error: 2.0,
                max_resident_patches: 2048,
                new_patches_per_frame: 64,
                generation_budget_ms: 8.0,
                resident_memory_mb: 256,
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

/// One root element, `<planet>`: serde reads the children of whatever root it finds and stops at its end, so a
/// misnamed root or a second one would otherwise pass silently.
fn check_root(text: &str, path: &str) -> Result<(), ConfigError> {
    let error = |message: String| ConfigError::Xml {
        path: path.to_string(),
        message,
    };
    let mut depth = 0usize;
    let mut roots = 0usize;
    for event in xml::reader::EventReader::new(text.as_bytes()) {
        match event.map_err(|e| error(e.to_string()))? {
            xml::reader::XmlEvent::StartElement { name, .. } => {
                if depth == 0 {
                    roots += 1;
                    if name.local_name != "planet" {
                        return Err(error(format!(
                            "the root element is <{}>; it must be <planet>",
                            name.local_name
                        )));
                    }
                    if roots > 1 {
                        return Err(error("a second <planet> after the first one's end".into()));
                    }
                }
                depth += 1;
            }
            xml::reader::XmlEvent::EndElement { .. } => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    Ok(())
}

// The file's shape. Every value is read as text first so that `1024.0f` and `>false` can be handled and a bad
// value reported with its element name.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawFile {
    planet_attributes: Option<RawPlanet>,
    river_attributes: Option<RawRiver>,
    rendering_attributes: Option<RawRendering>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawPlanet {
    radius: Option<String>,
    continents: Option<String>,
    landmass_percentage: Option<String>,
    sea_level_height: Option<String>,
    max_mountain_height: Option<String>,
    atmosphere_height: Option<String>,
    master_seed: Option<String>,
    continents_from_file: Option<String>,
    continents_image: Option<String>,
    mountains_per_continent: Option<String>,
    mountain_shoulder_factor: Option<String>,
    continent_height: Option<String>,
    ocean_height: Option<String>,
    coast_perturbation: Option<String>,
    detail_amplitude: Option<String>,
    base_resolution: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawRiver {
    river_model: Option<String>,
    source_area: Option<String>,
    lake_depth: Option<String>,
    influence_distance: Option<String>,
    basin_depth: Option<String>,
    basin_water_offset: Option<String>,
    starting_width: Option<String>,
    min_width: Option<String>,
    ending_factor: Option<String>,
    segments: Option<String>,
    hull_levels: Option<String>,
    tributary_probability: Option<String>,
    displacement: Option<String>,
    max_attempts: Option<String>,
    samples_per_half_width: Option<String>,
    samples_per_vertex_spacing: Option<String>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawRendering {
    vertices: Option<String>,
    // Table 6.1 prints "mas-level-of-detail"; Appendix A "max-level-of-detail". Both are accepted.
    #[serde(alias = "mas-level-of-detail")]
    max_level_of_detail: Option<String>,
    level_of_detail_switch_factor: Option<String>,
    level_of_detail_rule: Option<String>,
    pixel_error: Option<String>,
    max_resident_patches: Option<String>,
    new_patches_per_frame: Option<String>,
    generation_budget_ms: Option<String>,
    resident_memory_mb: Option<String>,
}

/// Reads one element's text into a typed value, with the file name for errors.
struct Reader<'a> {
    path: &'a str,
}

/// A closed or open numeric range for messages and checks.
#[derive(Clone, Copy)]
enum Range {
    Positive,
    NonNegative,
    Open(f64, f64),
    Closed(f64, f64),
    Any,
}

impl fmt::Display for Range {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Range::Positive => write!(f, "must be a number > 0"),
            Range::NonNegative => write!(f, "must be a number >= 0"),
            Range::Open(a, b) => write!(f, "must be a number in ({a}, {b}) (exclusive)"),
            Range::Closed(a, b) => write!(f, "must be a number in [{a}, {b}]"),
            Range::Any => write!(f, "must be a number"),
        }
    }
}

impl Range {
    fn contains(self, x: f64) -> bool {
        x.is_finite()
            && match self {
                Range::Positive => x > 0.0,
                Range::NonNegative => x >= 0.0,
                Range::Open(a, b) => x > a && x < b,
                Range::Closed(a, b) => x >= a && x <= b,
                Range::Any => true,
            }
    }
}

/// Strips what the thesis's C++ file format tolerated: surrounding space, a C float suffix, a stray leading `>`.
fn clean(text: &str) -> &str {
    let t = text.trim().trim_start_matches('>').trim();
    t.strip_suffix(['f', 'F'])
        .filter(|s| s.parse::<f64>().is_ok())
        .unwrap_or(t)
}

impl Reader<'_> {
    fn error(&self, element: &str, value: &str, expected: impl fmt::Display) -> ConfigError {
        ConfigError::Value {
            path: self.path.to_string(),
            element: element.to_string(),
            value: value.to_string(),
            expected: expected.to_string(),
        }
    }

    fn f32(
        &self,
        element: &str,
        raw: &Option<String>,
        default: f32,
        range: Range,
    ) -> Result<f32, ConfigError> {
        let Some(text) = raw else { return Ok(default) };
        match clean(text).parse::<f64>() {
            // The value must hold as an f32 too: 1e39 would become infinity and 1e-50 zero.
            Ok(x) if range.contains(x) && range.contains(x as f32 as f64) => Ok(x as f32),
            Ok(x) if range.contains(x) => Err(self.error(
                element,
                text,
                format!("{range}, within single precision (about 1.2e-38 to 3.4e38 in size)"),
            )),
            _ => Err(self.error(element, text, range)),
        }
    }

    fn u32(
        &self,
        element: &str,
        raw: &Option<String>,
        default: u32,
        min: u32,
        max: u32,
    ) -> Result<u32, ConfigError> {
        let Some(text) = raw else { return Ok(default) };
        match clean(text).parse::<u32>() {
            Ok(x) if (min..=max).contains(&x) => Ok(x),
            _ => Err(self.error(
                element,
                text,
                format!("must be a whole number in [{min}, {max}]"),
            )),
        }
    }

    fn bool(
        &self,
        element: &str,
        raw: &Option<String>,
        default: bool,
    ) -> Result<bool, ConfigError> {
        let Some(text) = raw else { return Ok(default) };
        match clean(text).to_ascii_lowercase().as_str() {
            "true" | "1" | "yes" => Ok(true),
            "false" | "0" | "no" => Ok(false),
            _ => Err(self.error(element, text, "must be true or false")),
        }
    }

    /// One of the names in `options`.
    fn choice<T: Copy>(
        &self,
        element: &str,
        raw: &Option<String>,
        default: T,
        options: &[(&str, T)],
    ) -> Result<T, ConfigError> {
        let Some(text) = raw else { return Ok(default) };
        let name = clean(text).to_ascii_lowercase();
        options
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| *v)
            .ok_or_else(|| {
                let names: Vec<&str> = options.iter().map(|(n, _)| *n).collect();
                self.error(
                    element,
                    text,
                    format!("must be one of {}", names.join(", ")),
                )
            })
    }

    /// A whole number of the form 2^n + 1 within [min, max].
    fn grid(
        &self,
        element: &str,
        raw: &Option<String>,
        default: u32,
        min: u32,
        max: u32,
    ) -> Result<u32, ConfigError> {
        let Some(text) = raw else { return Ok(default) };
        match clean(text).parse::<u32>() {
            Ok(x) if (min..=max).contains(&x) && (x - 1).is_power_of_two() => Ok(x),
            _ => Err(self.error(
                element,
                text,
                format!("must be of the form 2^n+1 in [{min}, {max}] (e.g. 17, 33, 65)"),
            )),
        }
    }
}

impl Config {
    /// Reads and validates a configuration file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
            path: path.display().to_string(),
            source,
        })?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Parses configuration XML; `path` names the source in errors.
    pub fn parse(text: &str, path: &str) -> Result<Self, ConfigError> {
        check_root(text, path)?;
        let raw: RawFile = serde_xml_rs::from_str(text).map_err(|e| {
            let message = e.to_string();
            match message.strip_prefix("Custom: unknown field ") {
                Some(rest) => ConfigError::UnknownElement {
                    path: path.to_string(),
                    detail: rest.to_string(),
                },
                None => ConfigError::Xml {
                    path: path.to_string(),
                    message,
                },
            }
        })?;
        let r = Reader { path };
        // The river model comes first: the defaults of the other elements depend on it.
        let model = r.choice(
            "river-model",
            &raw.river_attributes
                .as_ref()
                .and_then(|v| v.river_model.clone()),
            Config::default().river.model,
            &[
                ("thesis", RiverModel::Thesis),
                ("drainage", RiverModel::Drainage),
            ],
        )?;
        let d = Config::defaults_for(model);
        let p = raw.planet_attributes.unwrap_or_default();
        let dp = &d.planet;
        let seed_text = p.master_seed.clone();
        let master_seed = match &seed_text {
            None => dp.master_seed,
            Some(t) => clean(t)
                .parse::<i64>()
                .ok()
                .filter(|s| *s >= -1 && *s <= u32::MAX as i64)
                .ok_or_else(|| {
                    r.error(
                        "master-seed",
                        t,
                        format!("must be -1 (random) or a whole number in [0, {}]", u32::MAX),
                    )
                })?,
        };
        let planet = PlanetConfig {
            radius: r.f32("radius", &p.radius, dp.radius, Range::Positive)?,
            continents: r.u32("continents", &p.continents, dp.continents, 1, 64)?,
            landmass_percentage: r.f32(
                "landmass-percentage",
                &p.landmass_percentage,
                dp.landmass_percentage,
                Range::Open(0.0, 100.0),
            )?,
            sea_level_height: r.f32(
                "sea-level-height",
                &p.sea_level_height,
                dp.sea_level_height,
                Range::Any,
            )?,
            max_mountain_height: r.f32(
                "max-mountain-height",
                &p.max_mountain_height,
                dp.max_mountain_height,
                Range::Positive,
            )?,
            atmosphere_height: r.f32(
                "atmosphere-height",
                &p.atmosphere_height,
                dp.atmosphere_height,
                Range::NonNegative,
            )?,
            master_seed,
            continents_from_file: r.bool(
                "continents-from-file",
                &p.continents_from_file,
                dp.continents_from_file,
            )?,
            // A path written in the file is relative to the file's folder, so the file works from any folder.
            continents_image: p
                .continents_image
                .map(|s| {
                    let parent = std::path::Path::new(path)
                        .parent()
                        .unwrap_or(std::path::Path::new(""));
                    parent.join(s.trim()).to_string_lossy().into_owned()
                })
                .unwrap_or_else(|| dp.continents_image.clone()),
            mountains_per_continent: r.u32(
                "mountains-per-continent",
                &p.mountains_per_continent,
                dp.mountains_per_continent,
                0,
                1000,
            )?,
            mountain_shoulder_factor: r.f32(
                "mountain-shoulder-factor",
                &p.mountain_shoulder_factor,
                dp.mountain_shoulder_factor,
                Range::Closed(0.0, 1.0),
            )?,
            continent_height: r.f32(
                "continent-height",
                &p.continent_height,
                dp.continent_height,
                Range::Any,
            )?,
            ocean_height: r.f32("ocean-height", &p.ocean_height, dp.ocean_height, Range::Any)?,
            coast_perturbation: r.f32(
                "coast-perturbation",
                &p.coast_perturbation,
                dp.coast_perturbation,
                Range::Closed(0.0, 64.0),
            )?,
            detail_amplitude: r.f32(
                "detail-amplitude",
                &p.detail_amplitude,
                dp.detail_amplitude,
                Range::NonNegative,
            )?,
            base_resolution: r.grid(
                "base-resolution",
                &p.base_resolution,
                dp.base_resolution,
                9,
                1025,
            )?,
        };
        if planet.sea_level_height <= planet.ocean_height
            || planet.sea_level_height >= planet.continent_height
        {
            return Err(r.error(
                "sea-level-height",
                &planet.sea_level_height.to_string(),
                format!(
                    "must lie between ocean-height ({}) and continent-height ({})",
                    planet.ocean_height, planet.continent_height
                ),
            ));
        }

        let v = raw.river_attributes.unwrap_or_default();
        let dv = &d.river;
        let river = RiverConfig {
            model,
            source_area: r.f32(
                "source-area",
                &v.source_area,
                dv.source_area,
                Range::Positive,
            )?,
            lake_depth: r.f32("lake-depth", &v.lake_depth, dv.lake_depth, Range::Positive)?,
            influence_distance: r.f32(
                "influence-distance",
                &v.influence_distance,
                dv.influence_distance,
                Range::Positive,
            )?,
            basin_depth: r.f32(
                "basin-depth",
                &v.basin_depth,
                dv.basin_depth,
                Range::NonNegative,
            )?,
            basin_water_offset: r.f32(
                "basin-water-offset",
                &v.basin_water_offset,
                dv.basin_water_offset,
                Range::NonNegative,
            )?,
            starting_width: r.f32(
                "starting-width",
                &v.starting_width,
                dv.starting_width,
                Range::Positive,
            )?,
            min_width: r.f32("min-width", &v.min_width, dv.min_width, Range::Positive)?,
            ending_factor: r.f32(
                "ending-factor",
                &v.ending_factor,
                dv.ending_factor,
                Range::Positive,
            )?,
            segments: r.u32("segments", &v.segments, dv.segments, 1, 64)?,
            hull_levels: r.u32("hull-levels", &v.hull_levels, dv.hull_levels, 0, 8)?,
            tributary_probability: r.f32(
                "tributary-probability",
                &v.tributary_probability,
                dv.tributary_probability,
                Range::Closed(0.0, 1.0),
            )?,
            displacement: r.f32(
                "displacement",
                &v.displacement,
                dv.displacement,
                Range::Closed(0.0, 1.0),
            )?,
            max_attempts: r.u32("max-attempts", &v.max_attempts, dv.max_attempts, 1, 1000)?,
            samples_per_half_width: r.u32(
                "samples-per-half-width",
                &v.samples_per_half_width,
                dv.samples_per_half_width,
                1,
                16,
            )?,
            samples_per_vertex_spacing: r.u32(
                "samples-per-vertex-spacing",
                &v.samples_per_vertex_spacing,
                dv.samples_per_vertex_spacing,
                0,
                64,
            )?,
        };
        let widest = river.starting_width * river.ending_factor.max(1.0);
        if river.influence_distance <= widest * 0.5 {
            return Err(r.error(
                "influence-distance",
                &river.influence_distance.to_string(),
                format!(
                    "must exceed half the widest river (starting-width x ending-factor / 2 = {})",
                    widest * 0.5
                ),
            ));
        }
        if river.min_width > river.starting_width {
            return Err(r.error(
                "min-width",
                &river.min_width.to_string(),
                format!("must not exceed starting-width ({})", river.starting_width),
            ));
        }

        let g = raw.rendering_attributes.unwrap_or_default();
        let dg = &d.rendering;
        let rendering = RenderingConfig {
            vertices: r.grid("vertices", &g.vertices, dg.vertices, 3, 129)?,
            max_level_of_detail: r.u32(
                "max-level-of-detail",
                &g.max_level_of_detail,
                dg.max_level_of_detail,
                0,
                MAX_LEVEL_OF_DETAIL,
            )?,
            level_of_detail_switch_factor: r.f32(
                "level-of-detail-switch-factor",
                &g.level_of_detail_switch_factor,
                dg.level_of_detail_switch_factor,
                Range::Positive,
            )?,
            level_of_detail_rule: r.choice(
                "level-of-detail-rule",
                &g.level_of_detail_rule,
                dg.level_of_detail_rule,
                &[
                    ("screen-space-error", LodRule::ScreenSpaceError),
                    ("distance", LodRule::Distance),
                ],
            )?,
            pixel_error: r.f32(
                "pixel-error",
                &g.pixel_error,
                dg.pixel_error,
                Range::Positive,
            )?,
            max_resident_patches: r.u32(
                "max-resident-patches",
                &g.max_resident_patches,
                dg.max_resident_patches,
                16,
                1 << 20,
            )?,
            new_patches_per_frame: r.u32(
                "new-patches-per-frame",
                &g.new_patches_per_frame,
                dg.new_patches_per_frame,
                1,
                1 << 16,
            )?,
            generation_budget_ms: r.f32(
                "generation-budget-ms",
                &g.generation_budget_ms,
                dg.generation_budget_ms,
                Range::Positive,
            )?,
            resident_memory_mb: r.u32(
                "resident-memory-mb",
                &g.resident_memory_mb,
                dg.resident_memory_mb,
                16,
                1 << 20,
            )?,
        };
        // Lattice keys are 32-bit signed integers on the GPU (planet::detail): the finest lattice must keep its
        // cells per face edge, with the border, below 2^31.
        let deepest = MAX_LATTICE_CELLS.ilog2() - (rendering.vertices - 1).ilog2();
        if rendering.max_level_of_detail > deepest {
            return Err(r.error(
                "max-level-of-detail",
                &rendering.max_level_of_detail.to_string(),
                format!(
                    "must be at most {deepest} with vertices {} (at most 2^30 lattice cells per face edge)",
                    rendering.vertices
                ),
            ));
        }
        let config = Self {
            planet,
            river,
            rendering,
        };
        if config.base_level().is_none() {
            return Err(r.error(
                "base-resolution",
                &config.planet.base_resolution.to_string(),
                config.base_resolution_rule(),
            ));
        }
        Ok(config)
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
