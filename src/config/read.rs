//! Reading the XML file into a [`Config`]: one declarative table per section names every element once, with what
//! it accepts and the field it sets; the typed values and their defaults are config/mod.rs's, the rules between elements rules.rs's. An element that is
//! absent keeps its default (Appendix A's, or the drainage model's: `river-model` is read first). docs/configuration.md
//! documents every element of the tables (tests/config.rs checks both ways).

use std::fmt;

use xml::reader::{EventReader, XmlEvent};

use super::{Config, ConfigError, PlanetConfig, RenderingConfig, RiverConfig, RiverModel};
use crate::named::Named;

/// A closed or open numeric range for messages and checks.
#[derive(Clone, Copy, Debug)]
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

/// Whether `x` holds as an f32: 1e39 would become infinity, 1e-50 zero and 1e-45 a denormal (whose arithmetic loses
/// precision and, on some GPUs, is flushed to zero).
fn single_precision(x: f64) -> bool {
    let y = x as f32;
    y.is_finite() && (x == 0.0 || y.is_normal())
}

/// One element of a section of type `S`: its name, what it accepts, and the field it sets.
enum Param<S> {
    /// A number in a range, held in single precision.
    Number(&'static str, Range, fn(&mut S) -> &mut f32),
    /// A whole number in [min, max].
    Whole(&'static str, u32, u32, fn(&mut S) -> &mut u32),
    /// A whole number of the form 2^n + 1 in [min, max].
    Grid(&'static str, u32, u32, fn(&mut S) -> &mut u32),
    Flag(&'static str, fn(&mut S) -> &mut bool),
    /// One of a [`Named`] set's names: the setter sets the value named, or says which names there are.
    Choice(&'static str, fn(&mut S, &str) -> Result<(), String>),
    /// A path, relative to the file's folder.
    Path(&'static str, fn(&mut S) -> &mut String),
    /// -1 (pick one at start) or a 32-bit seed.
    Seed(&'static str, fn(&mut S) -> &mut i64),
}

impl<S> Param<S> {
    fn name(&self) -> &'static str {
        match self {
            Param::Number(n, ..)
            | Param::Whole(n, ..)
            | Param::Grid(n, ..)
            | Param::Flag(n, ..)
            | Param::Choice(n, ..)
            | Param::Path(n, ..)
            | Param::Seed(n, ..) => n,
        }
    }
}

/// Sets `field` to the value `text` names (any case), or says which names there are.
fn choose<T: Named>(text: &str, field: &mut T) -> Result<(), String> {
    let value = T::from_name(&text.to_ascii_lowercase()).ok_or_else(|| {
        let names: Vec<&str> = T::ALL.iter().map(|(n, _)| *n).collect();
        format!("must be one of {}", names.join(", "))
    })?;
    *field = value;
    Ok(())
}

/// `<planet-attributes>`.
const PLANET: &[Param<PlanetConfig>] = &[
    Param::Number("radius", Range::Closed(1.0, 1e8), |c| &mut c.radius),
    Param::Whole("continents", 1, 64, |c| &mut c.continents),
    Param::Number("landmass-percentage", Range::Open(0.0, 100.0), |c| {
        &mut c.landmass_percentage
    }),
    Param::Number("sea-level-height", Range::Any, |c| &mut c.sea_level_height),
    Param::Number("max-mountain-height", Range::Positive, |c| {
        &mut c.max_mountain_height
    }),
    Param::Number("atmosphere-height", Range::NonNegative, |c| {
        &mut c.atmosphere_height
    }),
    Param::Seed("master-seed", |c| &mut c.master_seed),
    Param::Flag("continents-from-file", |c| &mut c.continents_from_file),
    Param::Path("continents-image", |c| &mut c.continents_image),
    Param::Whole("mountains-per-continent", 0, 1000, |c| {
        &mut c.mountains_per_continent
    }),
    Param::Number("mountain-shoulder-factor", Range::Closed(0.0, 1.0), |c| {
        &mut c.mountain_shoulder_factor
    }),
    Param::Number("continent-height", Range::Any, |c| &mut c.continent_height),
    Param::Number("ocean-height", Range::Any, |c| &mut c.ocean_height),
    Param::Number("coast-perturbation", Range::Closed(0.0, 64.0), |c| {
        &mut c.coast_perturbation
    }),
    Param::Number("detail-amplitude", Range::NonNegative, |c| {
        &mut c.detail_amplitude
    }),
    Param::Number("flat-detail", Range::Closed(0.0, 1.0), |c| {
        &mut c.flat_detail
    }),
    Param::Grid("base-resolution", 9, 1025, |c| &mut c.base_resolution),
    Param::Choice("relief-model", |c, text| choose(text, &mut c.relief_model)),
    Param::Number("interior-rise", Range::Closed(0.0, 20.0), |c| {
        &mut c.interior_rise
    }),
    Param::Number("network-diffusivity", Range::Closed(0.0, 1e-3), |c| {
        &mut c.network_diffusivity
    }),
    Param::Path("terrain-file", |c| &mut c.terrain_file),
    Param::Choice("terrain-bounds", |c, text| {
        c.terrain_bounds = Some(parse_bounds(text)?);
        Ok(())
    }),
    Param::Number("terrain-height-scale", Range::Positive, |c| {
        &mut c.terrain_height_scale
    }),
    Param::Number("terrain-height-offset", Range::Any, |c| {
        &mut c.terrain_height_offset
    }),
];

/// `<river-attributes>`.
const RIVER: &[Param<RiverConfig>] = &[
    Param::Choice("river-model", |c, text| choose(text, &mut c.model)),
    Param::Number("source-area", Range::Positive, |c| &mut c.source_area),
    Param::Number("lake-depth", Range::Positive, |c| &mut c.lake_depth),
    Param::Number("influence-distance", Range::Positive, |c| {
        &mut c.influence_distance
    }),
    Param::Number("basin-depth", Range::NonNegative, |c| &mut c.basin_depth),
    Param::Number("basin-water-offset", Range::NonNegative, |c| {
        &mut c.basin_water_offset
    }),
    Param::Number("starting-width", Range::Positive, |c| &mut c.starting_width),
    Param::Number("min-width", Range::Positive, |c| &mut c.min_width),
    Param::Number("ending-factor", Range::Positive, |c| &mut c.ending_factor),
    Param::Whole("segments", 1, 64, |c| &mut c.segments),
    Param::Whole("hull-levels", 0, 8, |c| &mut c.hull_levels),
    Param::Number("tributary-probability", Range::Closed(0.0, 1.0), |c| {
        &mut c.tributary_probability
    }),
    Param::Number("displacement", Range::Closed(0.0, 1.0), |c| {
        &mut c.displacement
    }),
    Param::Flag("fine-meanders", |c| &mut c.fine_meanders),
    Param::Whole("max-attempts", 1, 1000, |c| &mut c.max_attempts),
    Param::Whole("samples-per-half-width", 1, 16, |c| {
        &mut c.samples_per_half_width
    }),
    Param::Whole("samples-per-vertex-spacing", 0, 64, |c| {
        &mut c.samples_per_vertex_spacing
    }),
    Param::Whole(
        "stream-levels",
        0,
        crate::drainage::finer::MAX_LEVELS_ABOVE_BASE,
        |c| &mut c.stream_levels,
    ),
];

/// `<rendering-attributes>`.
const RENDERING: &[Param<RenderingConfig>] = &[
    Param::Grid("vertices", 3, 129, |c| &mut c.vertices),
    // Bounded by `check` against `vertices` (25 with 33): one rule, one message, whatever the value.
    Param::Whole("max-level-of-detail", 0, u32::MAX, |c| {
        &mut c.max_level_of_detail
    }),
    Param::Number("level-of-detail-switch-factor", Range::Positive, |c| {
        &mut c.level_of_detail_switch_factor
    }),
    Param::Choice("level-of-detail-rule", |c, text| {
        choose(text, &mut c.level_of_detail_rule)
    }),
    Param::Number("pixel-error", Range::Positive, |c| &mut c.pixel_error),
    Param::Choice("terrain-colours", |c, text| {
        choose(text, &mut c.terrain_colours)
    }),
    Param::Number("river-pixel-error", Range::NonNegative, |c| {
        &mut c.river_pixel_error
    }),
    Param::Whole("max-resident-patches", 16, 1 << 20, |c| {
        &mut c.max_resident_patches
    }),
    Param::Whole("new-patches-per-frame", 1, 1 << 16, |c| {
        &mut c.new_patches_per_frame
    }),
    Param::Number("generation-budget-ms", Range::Positive, |c| {
        &mut c.generation_budget_ms
    }),
    Param::Whole("resident-memory-mb", 16, 1 << 20, |c| {
        &mut c.resident_memory_mb
    }),
];

/// The sections under the root, in the order they are read.
const SECTIONS: [&str; 3] = [
    "planet-attributes",
    "river-attributes",
    "rendering-attributes",
];

/// Every element of every section, as (section, element): what docs/configuration.md must document.
pub fn elements() -> Vec<(&'static str, &'static str)> {
    fn of<S>(section: &'static str, table: &[Param<S>]) -> Vec<(&'static str, &'static str)> {
        table.iter().map(|p| (section, p.name())).collect()
    }
    [
        of(SECTIONS[0], PLANET),
        of(SECTIONS[1], RIVER),
        of(SECTIONS[2], RENDERING),
    ]
    .concat()
}

/// Strips what the thesis's C++ file format tolerated: surrounding space, a C float suffix, one stray leading `>`
/// (Appendix A prints `<continents-from-file>>false`).
fn clean(text: &str) -> &str {
    let t = text.trim();
    let t = t.strip_prefix('>').unwrap_or(t).trim();
    t.strip_suffix(['f', 'F'])
        .filter(|s| s.parse::<f64>().is_ok())
        .unwrap_or(t)
}

/// An element's name as the tables know it: Table 6.1 prints "mas-level-of-detail", Appendix A
/// "max-level-of-detail"; both are accepted, as one element.
fn canonical(element: &str) -> &str {
    if element == "mas-level-of-detail" {
        "max-level-of-detail"
    } else {
        element
    }
}

/// The text of the elements of one section, in file order.
type Section = Vec<(String, String)>;

/// The file's sections by name (each at most once), after checking the shape: one `<planet>` root whose children
/// are sections, whose children are elements that hold text only.
fn sections(text: &str, path: &str) -> Result<Vec<(String, Section)>, ConfigError> {
    let error = |message: String| ConfigError::Xml {
        path: path.to_string(),
        message,
    };
    // A configuration has no use for entities, and nested ones expand quadratically or worse (a 300 KB file made a
    // 300 MB string before anything was refused).
    if text.contains("<!ENTITY") {
        return Err(error(
            "entity declarations (<!ENTITY ...>) are not accepted in a configuration".to_string(),
        ));
    }
    let mut out: Vec<(String, Section)> = Vec::new();
    // The open elements, outermost first.
    let mut open: Vec<String> = Vec::new();
    let mut roots = 0usize;
    for event in EventReader::new(text.as_bytes()) {
        match event.map_err(|e| error(e.to_string()))? {
            XmlEvent::StartElement {
                name, attributes, ..
            } => {
                let name = name.local_name;
                match open.len() {
                    0 => {
                        roots += 1;
                        if name != "planet" {
                            return Err(error(format!(
                                "the root element is <{name}>; it must be <planet>"
                            )));
                        }
                        if roots > 1 {
                            return Err(error(
                                "a second <planet> after the first one's end".into(),
                            ));
                        }
                    }
                    1 => {
                        if !SECTIONS.contains(&name.as_str()) {
                            return Err(ConfigError::UnknownElement {
                                path: path.to_string(),
                                detail: format!(
                                    "`{name}` in <planet>, expected one of `{}`",
                                    SECTIONS.join("`, `")
                                ),
                            });
                        }
                        if out.iter().any(|(s, _)| *s == name) {
                            return Err(error(format!("<{name}> appears twice")));
                        }
                        out.push((name.clone(), Vec::new()));
                    }
                    2 => {
                        let section = &mut out.last_mut().expect("a section is open").1;
                        if let Some((first, _)) = section
                            .iter()
                            .find(|(e, _)| canonical(e) == canonical(&name))
                        {
                            return Err(error(if *first == name {
                                format!("<{name}> appears twice in <{}>", open[1])
                            } else {
                                format!(
                                    "<{}> appears twice in <{}>, as <{first}> and <{name}>",
                                    canonical(&name),
                                    open[1]
                                )
                            }));
                        }
                        section.push((name.clone(), String::new()));
                    }
                    _ => {
                        return Err(error(format!(
                            "<{name}> inside <{}>: an element holds a value, not elements",
                            open[open.len() - 1]
                        )))
                    }
                }
                if let Some(attribute) = attributes.first() {
                    return Err(error(format!(
                        "<{name}> has the attribute {}; elements take none",
                        attribute.name.local_name
                    )));
                }
                open.push(name);
            }
            XmlEvent::EndElement { .. } => {
                open.pop();
            }
            XmlEvent::Characters(t) | XmlEvent::CData(t) | XmlEvent::Whitespace(t) => {
                if open.len() == 3 {
                    if let Some((_, value)) = out.last_mut().and_then(|(_, s)| s.last_mut()) {
                        value.push_str(&t);
                    }
                } else if !t.trim().is_empty() {
                    let place = open
                        .last()
                        .map_or("the file".to_string(), |o| format!("<{o}>"));
                    return Err(error(format!("text '{}' directly in {place}", t.trim())));
                }
            }
            _ => {}
        }
    }
    Ok(out)
}

/// Reads the elements of one section into `target` through `table`; an element the table does not name is an
/// error that lists those it does. `folder`: the file's folder, for paths.
fn read_section<S>(
    (name, elements): (&str, &Section),
    table: &[Param<S>],
    target: &mut S,
    (path, folder): (&str, &std::path::Path),
) -> Result<(), ConfigError> {
    let error = |element: &str, value: &str, expected: String| ConfigError::Value {
        path: path.to_string(),
        element: element.to_string(),
        value: value.to_string(),
        expected,
    };
    for (element, text) in elements {
        let wanted = canonical(element);
        let Some(param) = table.iter().find(|p| p.name() == wanted) else {
            let names: Vec<&str> = table.iter().map(Param::name).collect();
            return Err(ConfigError::UnknownElement {
                path: path.to_string(),
                detail: format!(
                    "`{element}` in <{name}>, expected one of `{}`",
                    names.join("`, `")
                ),
            });
        };
        let value = clean(text);
        match param {
            Param::Number(_, range, field) => match value.parse::<f64>() {
                Ok(x) if range.contains(x) && single_precision(x) => *field(target) = x as f32,
                Ok(x) if range.contains(x) => {
                    return Err(error(
                        wanted,
                        text,
                        format!(
                            "{range}, and 0 or a normal single-precision number (about 1.2e-38 to 3.4e38 in size)"
                        ),
                    ))
                }
                _ => return Err(error(wanted, text, range.to_string())),
            },
            Param::Whole(_, min, max, field) => match value.parse::<u32>() {
                Ok(x) if (*min..=*max).contains(&x) => *field(target) = x,
                _ => {
                    return Err(error(
                        wanted,
                        text,
                        format!("must be a whole number in [{min}, {max}]"),
                    ))
                }
            },
            Param::Grid(_, min, max, field) => match value.parse::<u32>() {
                Ok(x) if (*min..=*max).contains(&x) && (x - 1).is_power_of_two() => {
                    *field(target) = x
                }
                _ => {
                    return Err(error(
                        wanted,
                        text,
                        format!("must be of the form 2^n+1 in [{min}, {max}] (e.g. 17, 33, 65)"),
                    ))
                }
            },
            Param::Flag(_, field) => match value.to_ascii_lowercase().as_str() {
                "true" => *field(target) = true,
                "false" => *field(target) = false,
                _ => return Err(error(wanted, text, "must be true or false".into())),
            },
            Param::Choice(_, set) => {
                set(target, value).map_err(|expected| error(wanted, text, expected))?
            }
            // A path written in the file is relative to the file's folder, so the file works from any folder.
            Param::Path(_, field) => {
                *field(target) = folder.join(text.trim()).to_string_lossy().into_owned()
            }
            Param::Seed(_, field) => match value.parse::<i64>() {
                Ok(s) if (-1..=u32::MAX as i64).contains(&s) => *field(target) = s,
                _ => {
                    return Err(error(
                        wanted,
                        text,
                        format!("must be -1 (random) or a whole number in [0, {}]", u32::MAX),
                    ))
                }
            },
        }
    }
    Ok(())
}

impl Config {
    /// Parses configuration XML; `path` names the source in errors.
    pub fn parse(text: &str, path: &str) -> Result<Self, ConfigError> {
        let sections = sections(text, path)?;
        let section = |name: &str| {
            sections
                .iter()
                .find(|(s, _)| s == name)
                .map(|(_, e)| e.clone())
                .unwrap_or_default()
        };
        let (planet, river, rendering) = (
            section(SECTIONS[0]),
            section(SECTIONS[1]),
            section(SECTIONS[2]),
        );
        let folder = std::path::Path::new(path)
            .parent()
            .unwrap_or(std::path::Path::new(""));
        // The river model comes first: the defaults of the other elements depend on it.
        let mut model = Config::default().river;
        let model_only: Section = river
            .iter()
            .filter(|(e, _)| e == "river-model")
            .cloned()
            .collect();
        read_section(
            (SECTIONS[1], &model_only),
            RIVER,
            &mut model,
            (path, folder),
        )?;
        let mut config = Config::defaults_for(model.model);
        // The default image is relative to the working folder; one written in the file to the file's.
        read_section(
            (SECTIONS[0], &planet),
            PLANET,
            &mut config.planet,
            (path, folder),
        )?;
        // The relief, read with the planet, brings the drainage model's default source area.
        if config.river.model == RiverModel::Drainage {
            config.river.source_area = config.planet.relief_model.source_area();
        }
        read_section(
            (SECTIONS[1], &river),
            RIVER,
            &mut config.river,
            (path, folder),
        )?;
        read_section(
            (SECTIONS[2], &rendering),
            RENDERING,
            &mut config.rendering,
            (path, folder),
        )?;
        config.check(path)?;
        Ok(config)
    }
}

/// `WEST,SOUTH,EAST,NORTH` in degrees: west below east by at most 360, south below north within [-90, 90].
fn parse_bounds(text: &str) -> Result<[f64; 4], String> {
    let expected =
        "must be WEST,SOUTH,EAST,NORTH in degrees, west below east by at most 360 and south below \
                    north within [-90, 90] (e.g. 5,44,17,49)";
    let numbers: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| expected.to_string())?;
    match numbers[..] {
        [w, s, e, n]
            if [w, s, e, n].iter().all(|v| v.is_finite())
                && w < e
                && e - w <= 360.0
                && -90.0 <= s
                && s < n
                && n <= 90.0 =>
        {
            Ok([w, s, e, n])
        }
        _ => Err(expected.to_string()),
    }
}
