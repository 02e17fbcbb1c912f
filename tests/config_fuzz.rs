//! Fuzzing the configuration reader (issue 16): mutated copies of every shipped configuration (an element's value
//! replaced by empty text, signs, zero, NaN, infinities, huge and tiny numbers, words, control characters or any
//! string; an element duplicated, removed, moved into another section or given attributes; a DOCTYPE with entities;
//! the file cut short) never panic, and are either refused with an error that names the file (and, for a bad
//! value, the element) or read into a configuration whose numbers are finite and within their ranges.

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
    }
}
