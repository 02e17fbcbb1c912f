//! Fuzzing the configuration reader (issue 16): mutated copies of every shipped configuration (an element's value
//! replaced by empty text, signs, zero, NaN, infinities, huge and tiny numbers, words, control characters or any
//! string; an element duplicated, removed, moved into another section or given attributes; a DOCTYPE with entities;
//! the file cut short) never panic, and are either refused with an error that names the file (and, for a bad
//! value, the element) or read into a configuration whose numbers are finite and within their ranges. Arbitrary
//! numbers in several elements at once (issue 38) are refused by name or make a planet whose outputs are finite.

use proptest::prelude::*;
use riverplanet::config::Config;

const FILES: [&str; 3] = [
    include_str!("../config/planet.xml"),
    include_str!("../config/thesis.xml"),
    include_str!("../config/earth.xml"),
];

/// The elements of a file that hold a value: (start of `<name>`, end of `</name>`, name).
fn elements(text: &str) -> Vec<(usize, usize, String)> {
    let mut out = Vec::new();
    let mut at = 0;
    while let Some(open) = text[at..].find('<').map(|o| at + o) {
        let close = match text[open..].find('>') {
            Some(c) => open + c,
            None => break,
        };
        let name = &text[open + 1..close];
        at = close + 1;
        if name.starts_with(['/', '?', '!']) || name.contains(' ') {
            continue;
        }
        let end_tag = format!("</{name}>");
        if let Some(end) = text[at..].find(&end_tag).map(|e| at + e) {
            if !text[at..end].contains('<') {
                out.push((open, end + end_tag.len(), name.to_string()));
            }
        }
    }
    out
}

#[derive(Clone, Debug)]
enum Mutation {
    Value(String),
    Duplicate,
    Remove,
    Attribute,
    Misnest,
    Doctype,
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let values = prop_oneof![
        Just(String::new()),
        Just("-1".to_string()),
        Just("0".to_string()),
        Just("NaN".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("1e30".to_string()),
        Just("1e39".to_string()),
        Just("1e-50".to_string()),
        Just("-0.0f".to_string()),
        Just("text".to_string()),
        Just("99999999999999999999".to_string()),
        Just("\u{7}".to_string()),
        any::<f64>().prop_map(|v| v.to_string()),
        any::<i64>().prop_map(|v| v.to_string()),
        "[ -~]{0,12}",
    ];
    prop_oneof![
        4 => values.prop_map(Mutation::Value),
        1 => Just(Mutation::Duplicate),
        1 => Just(Mutation::Remove),
        1 => Just(Mutation::Attribute),
        1 => Just(Mutation::Misnest),
        1 => Just(Mutation::Doctype),
        1 => (0usize..2000).prop_map(Mutation::Truncate),
    ]
}

fn mutate(text: &str, pick: usize, mutation: &Mutation) -> (String, String) {
    let elements = elements(text);
    let (start, end, name) = elements[pick % elements.len()].clone();
    let element = &text[start..end];
    let replaced = match mutation {
        Mutation::Value(v) => format!("<{name}>{}</{name}>", xml_escape(v)),
        Mutation::Duplicate => format!("{element}{element}"),
        Mutation::Remove => String::new(),
        Mutation::Attribute => {
            element.replacen(&format!("<{name}>"), &format!("<{name} unit=\"m\">"), 1)
        }
        Mutation::Misnest => format!("<nested>{element}</nested>"),
        Mutation::Doctype => {
            let body = text.replacen(element, &format!("<{name}>&big;</{name}>"), 1);
            let doctype = "<!DOCTYPE planet [<!ENTITY a \"aaaaaaaaaa\"><!ENTITY big \"&a;&a;&a;&a;&a;&a;\">]>";
            return (
                body.replacen("<planet>", &format!("{doctype}<planet>"), 1),
                name,
            );
        }
        Mutation::Truncate(n) => return (text[..(*n).min(text.len())].to_string(), name),
    };
    (
        format!("{}{replaced}{}", &text[..start], &text[end..]),
        name,
    )
}

fn xml_escape(v: &str) -> String {
    v.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    #[test]
    fn mutated_configurations_are_read_or_refused_by_name(
        file in 0usize..FILES.len(),
        pick in any::<usize>(),
        mutation in mutation(),
    ) {
        let (text, element) = mutate(FILES[file], pick, &mutation);
        let result = std::panic::catch_unwind(|| Config::parse(&text, "fuzz.xml"));
        prop_assert!(result.is_ok(), "{mutation:?} of <{element}> panicked");
        match result.unwrap() {
            Err(e) => {
                let message = e.to_string();
                prop_assert!(message.contains("fuzz.xml"), "{message}");
                if let (Mutation::Value(_), riverplanet::config::ConfigError::Value { .. }) = (&mutation, &e) {
                    prop_assert!(message.contains(&element), "{message} does not name <{element}>");
                }
            }
            Ok(config) => {
                let p = &config.planet;
                let r = &config.river;
                let numbers = [
                    p.radius, p.sea_level_height, p.max_mountain_height, p.atmosphere_height,
                    p.landmass_percentage, r.influence_distance, r.basin_depth, r.basin_water_offset,
                    r.starting_width, r.min_width, r.ending_factor,
                    config.rendering.level_of_detail_switch_factor, config.rendering.pixel_error,
                ];
                prop_assert!(numbers.iter().all(|v| v.is_finite()), "{mutation:?} of <{element}>: {numbers:?}");
                prop_assert!(p.radius > 0.0 && (0.0..=100.0).contains(&p.landmass_percentage));
                prop_assert!(config.rendering.vertices >= 3);
            }
        }
    }
}

/// The mutations reach every valued element, and the reader tells them apart: the unchanged files read, and a
/// NaN radius is refused by name.
#[test]
fn the_fuzzer_reaches_the_elements_and_the_reader_refuses_by_name() {
    for text in FILES {
        let found = elements(text);
        assert!(found.len() >= 12, "{} elements", found.len());
        assert!(Config::parse(text, "fuzz.xml").is_ok());
        let radius = found.iter().position(|(_, _, n)| n == "radius").unwrap();
        let (bad, _) = mutate(text, radius, &Mutation::Value("NaN".into()));
        let message = Config::parse(&bad, "fuzz.xml").unwrap_err().to_string();
        assert!(message.contains("radius"), "{message}");
        // A scaled number keeps the element's unit and reads: the property test builds planets from such.
        let (doubled, name, value) = set_number(text, radius, &Number::Scaled(2.0));
        assert_eq!(name, "radius");
        let read = Config::parse(&doubled, "fuzz.xml").unwrap();
        assert_eq!(read.planet.radius as f64, value.parse::<f64>().unwrap());
    }
}

/// A number for an element: one of the extremes of f32 and beyond it, tiny and subnormal ones, small whole numbers
/// and any f64, or the element's own value scaled (most of which the reader accepts, so planets get built).
#[derive(Clone, Debug)]
enum Number {
    Absolute(String),
    Scaled(f64),
}

fn number() -> impl Strategy<Value = Number> {
    prop_oneof![
        1 => prop::sample::select(vec![
            "1e30", "1e-45", "3e38", "3.5e38", "-3e38", "1e-38", "0", "-0", "-1", "0.5", "1", "2", "8"
        ])
        .prop_map(|v| Number::Absolute(v.to_string())),
        1 => (0u32..=64).prop_map(|v| Number::Absolute(v.to_string())),
        1 => any::<f64>().prop_map(|v| Number::Absolute(v.to_string())),
        3 => prop::sample::select(vec![0.0, 1e-3, 0.1, 0.5, 0.9, 1.1, 2.0, 10.0, 1e3])
            .prop_map(Number::Scaled),
    ]
}

/// `text` with its `pick`-th valued element set to `number`, and the element's name and new value.
fn set_number(text: &str, pick: usize, number: &Number) -> (String, String, String) {
    let value = match number {
        Number::Absolute(v) => v.clone(),
        Number::Scaled(k) => {
            let (start, end, name) = elements(text)[pick % elements(text).len()].clone();
            let inner = &text[start + name.len() + 2..end - name.len() - 3];
            match inner.trim().trim_end_matches('f').parse::<f64>() {
                Ok(v) => (v * k).to_string(),
                Err(_) => inner.to_string(),
            }
        }
    };
    let (text, name) = mutate(text, pick, &Mutation::Value(value.clone()));
    (text, name, value)
}

/// Whether every output of the planet built from `config` holds finite values: its heights at every lattice point,
/// its stats, its drainage network's courses, beds and areas, and its river systems' pieces.
fn planet_is_finite(config: &Config) -> Result<(), String> {
    let planet =
        riverplanet::planet::Planet::generate(config, 1, |_| {}).map_err(|e| e.to_string())?;
    let lattice = &planet.lattice;
    for face in 0..6 {
        for j in 0..=lattice.cells {
            for i in 0..=lattice.cells {
                let h = lattice.get(face, i, j);
                if !h.is_finite() {
                    return Err(format!("height {h} at face {face} ({i}, {j})"));
                }
            }
        }
    }
    let s = &planet.stats;
    let stats = [
        s.landmass_percent,
        s.min_height as f64,
        s.max_height as f64,
        s.form.mean_land_height,
    ];
    if !stats.iter().all(|v| v.is_finite()) {
        return Err(format!("stats {stats:?}"));
    }
    if let Some(drainage) = &planet.drainage {
        for reach in &drainage.reaches {
            let finite = reach.points.iter().all(|p| p.is_finite())
                && reach.beds.iter().all(|b| b.is_finite())
                && reach.areas.iter().all(|a| a.is_finite());
            if !finite {
                return Err("a reach with a value that is not finite".into());
            }
        }
    }
    let network = riverplanet::river::network::RiverNetwork::generate(&planet, config, 1);
    for system in &network.systems {
        for segment in &system.segments {
            let c = segment.curve;
            let finite = [c.p0, c.d0, c.p1, c.d1].iter().all(|v| v.is_finite())
                && segment.heights.0.is_finite()
                && segment.widths.1.is_finite();
            if !finite {
                return Err(format!(
                    "river system {} has a piece that is not finite",
                    system.id
                ));
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Issue 38: arbitrary numbers in several elements at once (each a number the reader may accept) are refused
    /// with an error that names the file and a changed element, or make a planet whose outputs are all finite.
    #[test]
    fn arbitrary_numbers_are_refused_by_name_or_make_a_finite_planet(
        file in 0usize..2,
        picks in prop::collection::vec((any::<usize>(), number()), 1..3),
    ) {
        // The default planet (drainage model) and the thesis's: config/earth.xml is the default planet in metres.
        let mut text = FILES[file].to_string();
        let mut changed = Vec::new();
        for (pick, number) in &picks {
            let (mutated, name, value) = set_number(&text, *pick, number);
            text = mutated;
            changed.push(format!("{name}={value}"));
        }
        match Config::parse(&text, "fuzz.xml") {
            Err(e) => {
                let message = e.to_string();
                prop_assert!(message.contains("fuzz.xml"), "{message}");
                let named = changed.iter().any(|c| message.contains(c.split('=').next().unwrap()));
                prop_assert!(named, "{message} names none of {changed:?}");
            }
            Ok(config) => {
                let finite = std::panic::catch_unwind(|| planet_is_finite(&config));
                prop_assert!(finite.is_ok(), "{changed:?} panicked");
                if let Err(e) = finite.unwrap() {
                    prop_assert!(false, "{changed:?}: {e}");
                }
            }
        }
    }
}
