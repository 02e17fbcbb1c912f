//! The XML configuration: Appendix A as printed, and every class of bad input reported by element and range.

use riverplanet::config::{Config, ConfigError, LodRule, ReliefModel, RiverModel, TerrainColours};

const APPENDIX_A: &str = include_str!("../config/thesis.xml");

fn with(section: &str, element: &str, value: &str) -> String {
    let open = format!("<{element}>");
    let close = format!("</{element}>");
    if let (Some(a), Some(b)) = (APPENDIX_A.find(&open), APPENDIX_A.find(&close)) {
        format!("{}{open}{value}{}", &APPENDIX_A[..a], &APPENDIX_A[b..])
    } else {
        let tag = format!("<{section}>");
        APPENDIX_A.replacen(&tag, &format!("{tag}\n    {open}{value}{close}"), 1)
    }
}

fn error_of(xml: &str) -> String {
    match Config::parse(xml, "test.xml") {
        Ok(c) => panic!("accepted invalid configuration: {c:?}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn appendix_a_reads_as_printed() {
    let c = Config::parse(APPENDIX_A, "config/thesis.xml").expect("Appendix A must parse");
    assert_eq!(c.river.model, RiverModel::Thesis);
    assert_eq!(c.planet.radius, 1024.0);
    assert_eq!(c.planet.continents, 5);
    assert_eq!(c.planet.landmass_percentage, 30.0);
    assert_eq!(c.planet.sea_level_height, 0.4);
    assert_eq!(c.planet.max_mountain_height, 16.0);
    assert_eq!(c.planet.atmosphere_height, 32.0);
    assert_eq!(c.planet.master_seed, -1);
    assert!(
        !c.planet.continents_from_file,
        "the stray '>' in '>false' is tolerated"
    );
    assert_eq!(c.river.influence_distance, 20.0);
    assert_eq!(c.river.basin_depth, 0.1);
    assert_eq!(c.river.basin_water_offset, 0.001);
    assert_eq!(c.river.starting_width, 2.5);
    assert_eq!(c.river.min_width, 0.075);
    assert_eq!(c.river.ending_factor, 2.0);
    assert_eq!(c.river.segments, 5);
    assert_eq!(c.rendering.vertices, 33);
    assert_eq!(c.rendering.max_level_of_detail, 6);
    assert_eq!(c.rendering.level_of_detail_switch_factor, 8.0);
}

#[test]
fn the_shipped_files_load_from_disk_with_their_models() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
    // The drainage model's planet draws by screen-space error, the thesis's model by the thesis's Eq. 6.1.
    for (file, model, rule) in [
        (
            "planet.xml",
            RiverModel::Drainage,
            LodRule::ScreenSpaceError,
        ),
        ("thesis.xml", RiverModel::Thesis, LodRule::Distance),
        ("earth.xml", RiverModel::Drainage, LodRule::Distance),
    ] {
        let c = Config::load(&dir.join(file)).unwrap();
        assert_eq!(c.river.model, model, "{file}");
        assert_eq!(c.rendering.level_of_detail_rule, rule, "{file}");
        // The thesis's model keeps the thesis's height bands; the drainage model's planets are coloured by climate.
        let colours = if model == RiverModel::Thesis {
            TerrainColours::Height
        } else {
            TerrainColours::Climate
        };
        assert_eq!(c.rendering.terrain_colours, colours, "{file}");
    }
}

#[test]
fn the_terrain_colours_are_named_or_refused() {
    let c = Config::parse(
        &with("rendering-attributes", "terrain-colours", "Height"),
        "t.xml",
    )
    .unwrap();
    assert_eq!(c.rendering.terrain_colours, TerrainColours::Height);
    let message = error_of(&with("rendering-attributes", "terrain-colours", "biomes"));
    assert!(
        message.contains("terrain-colours") && message.contains("height, climate"),
        "{message}"
    );
}

#[test]
fn the_level_of_detail_rule_and_pixel_error_are_named_or_refused() {
    let c = Config::parse(
        &with(
            "rendering-attributes",
            "level-of-detail-rule",
            "screen-space-error",
        ),
        "t.xml",
    )
    .unwrap();
    assert_eq!(c.rendering.level_of_detail_rule, LodRule::ScreenSpaceError);
    assert_eq!(c.rendering.pixel_error, 2.0);
    let message = error_of(&with(
        "rendering-attributes",
        "level-of-detail-rule",
        "near",
    ));
    assert!(
        message.contains("level-of-detail-rule")
            && message.contains("screen-space-error, distance"),
        "{message}"
    );
    let message = error_of(&with("rendering-attributes", "pixel-error", "0"));
    assert!(message.contains("<pixel-error>"), "{message}");
    // 0 turns the painted rivers' term off; below it is an error.
    let message = error_of(&with("rendering-attributes", "river-pixel-error", "-1"));
    assert!(
        message.contains("<river-pixel-error>") && message.contains(">= 0"),
        "{message}"
    );
    let off = Config::parse(&with("rendering-attributes", "river-pixel-error", "0"), "t").unwrap();
    assert_eq!(off.rendering.river_pixel_error, 0.0);
}

#[test]
fn without_a_river_model_the_drainage_model_and_its_defaults_apply() {
    let c = Config::parse("<planet></planet>", "t.xml").unwrap();
    assert_eq!(c.river.model, RiverModel::Drainage);
    assert_eq!(c.planet.relief_model, ReliefModel::Eroded);
    assert_eq!(c.river.source_area, 300.0);
    assert_eq!(Config::default().river.model, RiverModel::Drainage);
    assert_eq!(Config::appendix_a().river.model, RiverModel::Thesis);
    assert_eq!(Config::appendix_a().planet.detail_amplitude, 8.0);
}

#[test]
fn vertices_must_be_power_of_two_plus_one() {
    for bad in ["32", "34", "0", "1", "abc", "-33"] {
        let msg = error_of(&with("rendering-attributes", "vertices", bad));
        assert!(msg.contains("<vertices>"), "{msg}");
        assert!(msg.contains(&format!("'{bad}'")), "{msg}");
        assert!(msg.contains("2^n+1"), "{msg}");
    }
    for good in ["17", "33", "65"] {
        Config::parse(&with("rendering-attributes", "vertices", good), "t").unwrap();
    }
}

#[test]
fn radius_must_lie_between_1_and_1e8() {
    for bad in ["0", "-5.0f", "nan", "inf", "0.5", "1e-45", "2e8"] {
        let msg = error_of(&with("planet-attributes", "radius", bad));
        assert!(
            msg.contains("<radius>") && msg.contains("[1, 100000000]"),
            "{msg}"
        );
    }
}

/// Issue 38, finding 6: every size is bounded by the planet's: heights to a quarter of the radius, the air to the
/// radius, the widest river and the influence distance to a quarter of it, the source area to the sphere's.
#[test]
fn sizes_beyond_the_planets_are_refused_by_element() {
    for (section, element, value) in [
        ("planet-attributes", "max-mountain-height", "3e38"),
        ("planet-attributes", "ocean-height", "-1e30"),
        ("planet-attributes", "detail-amplitude", "1e30"),
        ("planet-attributes", "atmosphere-height", "1e5"),
        ("river-attributes", "basin-depth", "1e30"),
        ("river-attributes", "influence-distance", "1e30"),
        ("river-attributes", "source-area", "1e20"),
    ] {
        let msg = error_of(&with(section, element, value));
        assert!(
            msg.contains(&format!("<{element}>")) && msg.contains("radius 1024"),
            "{msg}"
        );
    }
}

#[test]
fn widths_must_be_positive() {
    for element in ["starting-width", "min-width", "influence-distance"] {
        let msg = error_of(&with("river-attributes", element, "0.0f"));
        assert!(
            msg.contains(&format!("<{element}>")) && msg.contains("> 0"),
            "{msg}"
        );
    }
    let msg = error_of(&with("river-attributes", "min-width", "3.0f"));
    assert!(msg.contains("must not exceed starting-width"), "{msg}");
}

/// Each of `bads` as `<planet-attributes>`'s `element` is refused with an error naming the element and `range`.
fn assert_out_of_range(element: &str, bads: &[&str], range: &str) {
    for bad in bads {
        let msg = error_of(&with("planet-attributes", element, bad));
        assert!(
            msg.contains(&format!("<{element}>")) && msg.contains(range),
            "{msg}"
        );
    }
}

#[test]
fn the_interior_rise_lies_between_0_and_20() {
    assert_out_of_range("interior-rise", &["-0.5", "21", "1e30"], "[0, 20]");
    let earth =
        Config::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/earth.xml"))
            .unwrap();
    assert_eq!(earth.planet.interior_rise, 2.5);
    assert_eq!(
        Config::defaults_for(RiverModel::Drainage)
            .planet
            .interior_rise,
        0.0
    );
}

#[test]
fn the_flat_detail_is_a_share_between_0_and_1() {
    assert_out_of_range("flat-detail", &["-0.1", "1.5", "nan"], "[0, 1]");
    // Not yet the default (docs/planet.md, "Detail that follows the slope").
    assert_eq!(
        Config::defaults_for(RiverModel::Drainage)
            .planet
            .flat_detail,
        1.0
    );
}

#[test]
fn the_network_diffusivity_lies_between_0_and_a_thousandth() {
    assert_out_of_range(
        "network-diffusivity",
        &["-1e-4", "0.002", "nan"],
        "[0, 0.001]",
    );
    let planet = Config::defaults_for(RiverModel::Drainage).planet;
    assert_eq!(planet.network_diffusivity, 2e-4);
}

#[test]
fn terrain_bounds_are_four_degrees_in_order_and_need_a_terrain_file() {
    assert_out_of_range(
        "terrain-bounds",
        &[
            "1,2,3",
            "10,0,5,5",
            "0,10,5,5",
            "0,-91,5,5",
            "-10,0,400,5",
            "a,b,c,d",
        ],
        "must be WEST,SOUTH,EAST,NORTH in degrees",
    );
    let msg = error_of(&with("planet-attributes", "terrain-bounds", "5,44,17,49"));
    assert!(
        msg.contains("<terrain-bounds>") && msg.contains("needs relief-model file"),
        "{msg}"
    );
}

#[test]
fn landmass_must_lie_strictly_between_0_and_100() {
    for bad in ["0", "100", "-1", "150.0f"] {
        let msg = error_of(&with("planet-attributes", "landmass-percentage", bad));
        assert!(
            msg.contains("<landmass-percentage>") && msg.contains("(0, 100)"),
            "{msg}"
        );
    }
    Config::parse(
        &with("planet-attributes", "landmass-percentage", "0.5f"),
        "t",
    )
    .unwrap();
}

#[test]
fn unknown_elements_are_rejected_by_name() {
    let msg = error_of(&with("river-attributes", "river-colour", "blue"));
    assert!(msg.contains("unknown element `river-colour`"), "{msg}");
    let msg = error_of(
        &APPENDIX_A
            .replace("<river-attributes>", "<rivers-attributes>")
            .replace("</river-attributes>", "</rivers-attributes>"),
    );
    assert!(msg.contains("rivers-attributes"), "{msg}");
}

#[test]
fn malformed_xml_is_an_error_not_a_panic() {
    for bad in [
        "",
        "not xml at all",
        "<planet><planet-attributes><radius>1</planet-attributes></planet>",
        &APPENDIX_A[..APPENDIX_A.len() / 2],
    ] {
        let err = Config::parse(bad, "broken.xml").unwrap_err();
        assert!(matches!(err, ConfigError::Xml { .. }), "{err}");
        assert!(err.to_string().contains("broken.xml"), "{err}");
    }
}

#[test]
fn unreadable_file_names_the_path() {
    let err = Config::load(std::path::Path::new("/nonexistent/planet.xml")).unwrap_err();
    assert!(err.to_string().contains("/nonexistent/planet.xml"), "{err}");
}

#[test]
fn missing_elements_take_defaults() {
    let c = Config::parse(
        "<planet><planet-attributes><radius>1000</radius></planet-attributes></planet>",
        "t",
    )
    .unwrap();
    assert_eq!(c.planet.radius, 1000.0);
    assert_eq!(c.rendering.vertices, 33);
}

#[test]
fn seed_accepts_minus_one_and_rejects_below() {
    let msg = error_of(&with("planet-attributes", "master-seed", "-2"));
    assert!(msg.contains("<master-seed>"), "{msg}");
    let c = Config::parse(&with("planet-attributes", "master-seed", "42"), "t").unwrap();
    assert_eq!(c.resolve_seed(), 42);
}

#[test]
fn numbers_beyond_single_precision_are_refused_by_element() {
    // Issue 38, finding 7: 1e-50 became 0 and 1e-45 a denormal.
    for (section, element, value) in [
        ("planet-attributes", "sea-level-height", "1e39"),
        ("planet-attributes", "sea-level-height", "1e-50"),
        ("river-attributes", "influence-distance", "4e38"),
        ("river-attributes", "basin-depth", "1e-45"),
    ] {
        let message = error_of(&with(section, element, value));
        assert!(
            message.contains(element) && message.contains(value),
            "{message}"
        );
        assert!(message.contains("single-precision"), "{message}");
    }
}

#[test]
fn the_river_model_is_named_or_refused() {
    let c = Config::parse(
        &with("river-attributes", "river-model", "drainage"),
        "t.xml",
    )
    .unwrap();
    assert_eq!(c.river.model, RiverModel::Drainage);
    let message = error_of(&with("river-attributes", "river-model", "rain"));
    assert!(
        message.contains("river-model") && message.contains("thesis, drainage"),
        "{message}"
    );
}

#[test]
fn the_relief_model_is_named_and_fits_its_river_model_or_is_refused() {
    let message = error_of(&with("planet-attributes", "relief-model", "rain"));
    assert!(
        message.contains("relief-model") && message.contains("thesis, carved, eroded, file"),
        "{message}"
    );
    // The thesis's rivers start at the thesis's mountains; the drainage model drains the other reliefs.
    let drainage = with("river-attributes", "river-model", "drainage");
    let message = error_of(&drainage.replacen(
        "<planet-attributes>",
        "<planet-attributes><relief-model>thesis</relief-model>",
        1,
    ));
    assert!(message.contains("eroded, carved or file"), "{message}");
    let message = error_of(&with("planet-attributes", "relief-model", "eroded"));
    assert!(message.contains("must be thesis"), "{message}");
    assert_eq!(
        Config::parse(APPENDIX_A, "t.xml")
            .unwrap()
            .planet
            .relief_model,
        ReliefModel::Thesis
    );
}

#[test]
fn the_drainage_model_brings_its_own_defaults_and_explicit_values_still_win() {
    let drainage = with("river-attributes", "river-model", "drainage");
    let c = Config::parse(&drainage, "t.xml").unwrap();
    assert_eq!(c.river.source_area, 300.0);
    // The carved relief keeps the source area it was tuned with.
    let carved = drainage.replacen(
        "<planet-attributes>",
        "<planet-attributes><relief-model>carved</relief-model>",
        1,
    );
    let c = Config::parse(&carved, "t.xml").unwrap();
    assert_eq!(
        (c.planet.relief_model, c.river.source_area),
        (ReliefModel::Carved, 700.0)
    );
    assert_eq!(c.planet.detail_amplitude, 2.0);
    assert_eq!(c.river.samples_per_vertex_spacing, 4);
    let explicit = drainage.replacen(
        "<river-model>",
        "<samples-per-vertex-spacing>0</samples-per-vertex-spacing><river-model>",
        1,
    );
    let c = Config::parse(&explicit, "t.xml").unwrap();
    assert_eq!(c.river.samples_per_vertex_spacing, 0);
    // The thesis's model keeps Appendix A's defaults.
    let c = Config::parse(APPENDIX_A, "t.xml").unwrap();
    assert_eq!(c.planet.detail_amplitude, 8.0);
    assert_eq!(c.river.samples_per_vertex_spacing, 0);
}

#[test]
fn the_root_must_be_one_planet_element() {
    for (xml, expected) in [
        ("<world></world>", "must be <planet>"),
        ("<planet></planet><planet></planet>", "a second <planet>"),
        ("<planet>", "malformed"),
    ] {
        let message = error_of(xml);
        assert!(message.contains(expected), "{xml}: {message}");
    }
    Config::parse(
        "<?xml version=\"1.0\"?>\n<!-- a comment -->\n<planet></planet>",
        "t.xml",
    )
    .unwrap();
}

#[test]
fn a_base_resolution_that_no_level_holds_is_refused_by_the_configuration() {
    // What `generate` used to refuse only after `config` had accepted it. Issue 38, finding 12: a level too shallow
    // for the base resolution names the level (base-resolution is often not in the file), with what it must be.
    for value in ["0", "1"] {
        let message = error_of(&with("rendering-attributes", "max-level-of-detail", value));
        assert!(
            message.contains("<max-level-of-detail>")
                && message.contains("must be at least 2, the level of base-resolution 129"),
            "{value}: {message}"
        );
    }
    let message = error_of(&with("planet-attributes", "base-resolution", "9"));
    assert!(
        message.contains("<base-resolution>") && message.contains("(vertices - 1) x 2^b + 1"),
        "{message}"
    );
    let ok = with("rendering-attributes", "max-level-of-detail", "2");
    assert_eq!(Config::parse(&ok, "t.xml").unwrap().base_level(), Some(2));
}

/// Issue 38, finding 12: every level too deep gets the same message, the bound with these vertices (27 was out of
/// [0, 26] while 26 was "at most 25").
#[test]
fn every_level_too_deep_is_refused_with_the_bound_of_the_vertices() {
    for value in ["26", "27", "4000000000"] {
        let message = error_of(&with("rendering-attributes", "max-level-of-detail", value));
        assert!(
            message.contains("<max-level-of-detail>")
                && message.contains("at most 25 with vertices 33"),
            "{value}: {message}"
        );
    }
    Config::parse(
        &with("rendering-attributes", "max-level-of-detail", "25"),
        "t.xml",
    )
    .unwrap();
}

#[test]
fn a_continents_image_named_in_a_file_is_found_beside_the_file() {
    let text = with("planet-attributes", "continents-image", "continents.png");
    let c = Config::parse(&text, "/somewhere/config/mine.xml").unwrap();
    assert_eq!(
        c.planet.continents_image,
        "/somewhere/config/continents.png"
    );
    let absolute = with("planet-attributes", "continents-image", "/data/earth.png");
    assert_eq!(
        Config::parse(&absolute, "/somewhere/mine.xml")
            .unwrap()
            .planet
            .continents_image,
        "/data/earth.png"
    );
}

/// docs/configuration.md documents exactly the elements the reader's tables know: every element has a row (the
/// Table 6.1 table names the element, the added table its section and element), and every row names an element
/// of that section.
#[test]
fn the_documentation_lists_exactly_the_elements_read() {
    let docs = include_str!("../docs/configuration.md");
    let rows: Vec<Vec<&str>> = docs
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("|---"))
        .map(|l| {
            l.split('|')
                .map(str::trim)
                .filter(|c| !c.is_empty())
                .collect()
        })
        .collect();
    let elements = riverplanet::config::elements();
    let section_of = |s: &str| format!("{s}-attributes");
    let documented = |(section, element): &(&str, &str)| {
        rows.iter().any(|r| {
            r.first() == Some(element)
                || (r.len() > 1 && r[1] == *element && section_of(r[0]) == *section)
        })
    };
    let missing: Vec<_> = elements.iter().filter(|e| !documented(e)).collect();
    assert!(
        missing.is_empty(),
        "elements read but not documented: {missing:?}"
    );
    let known = |name: &str| elements.iter().any(|(_, e)| *e == name);
    let sections = ["planet", "river", "rendering"];
    let unknown: Vec<_> = rows
        .iter()
        .filter(|r| r.first() != Some(&"element") && r.first() != Some(&"section"))
        .filter(|r| {
            if sections.contains(&r[0]) {
                !elements
                    .iter()
                    .any(|(s, e)| *s == section_of(r[0]) && *e == r[1])
            } else {
                !known(r[0])
            }
        })
        .collect();
    assert!(unknown.is_empty(), "documented but not read: {unknown:?}");
}

#[test]
fn a_run_without_morphing_takes_the_thesis_rule_unless_another_is_asked_for() {
    let screen = LodRule::ScreenSpaceError;
    assert_eq!(LodRule::for_run(None, true, screen), screen);
    assert_eq!(LodRule::for_run(None, false, screen), LodRule::Distance);
    assert_eq!(LodRule::for_run(Some(screen), false, screen), screen);
    assert_eq!(
        LodRule::for_run(Some(LodRule::Distance), true, screen),
        LodRule::Distance
    );
}

/// Issue 38, finding 11: a flag is `true` or `false` as its message says (any case, and Appendix A's one stray `>`),
/// and the thesis's alias next to the element it names is the element given twice.
#[test]
fn flags_are_true_or_false_and_an_alias_is_the_same_element() {
    for bad in ["yes", "1", "0", "no", ">>true"] {
        let message = error_of(&with("planet-attributes", "continents-from-file", bad));
        assert!(
            message.contains("<continents-from-file>") && message.contains("true or false"),
            "{bad}: {message}"
        );
    }
    for good in [">false", "FALSE", "false"] {
        let c = Config::parse(
            &with("planet-attributes", "continents-from-file", good),
            "t",
        )
        .unwrap();
        assert!(!c.planet.continents_from_file);
    }
    let both = with("rendering-attributes", "max-level-of-detail", "5").replacen(
        "<rendering-attributes>",
        "<rendering-attributes>\n    <mas-level-of-detail>6</mas-level-of-detail>",
        1,
    );
    let message = error_of(&both);
    assert!(
        message.contains("<max-level-of-detail> appears twice")
            && message.contains("<mas-level-of-detail>"),
        "{message}"
    );
}

/// Issue 38, findings 9 and 15: a configuration with entity declarations is refused before it is expanded; UTF-16
/// with a byte-order mark (legal XML) reads as the same configuration, and a file of neither encoding is refused once,
/// with the reason (it was printed twice).
#[test]
fn entities_are_refused_and_utf16_is_read() {
    let bomb = format!(
        "<!DOCTYPE planet [<!ENTITY a \"{}\"><!ENTITY b \"{}\">]><planet><planet-attributes><radius>&b;</radius></planet-attributes></planet>",
        "x".repeat(1000),
        "&a;".repeat(1000)
    );
    let message = error_of(&bomb);
    assert!(message.contains("entity declarations"), "{message}");
    let dir = std::env::temp_dir().join(format!("riverplanet-config-utf16-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let utf16 = dir.join("utf16.xml");
    let bytes: Vec<u8> = [0xFF, 0xFE]
        .into_iter()
        .chain(APPENDIX_A.encode_utf16().flat_map(u16::to_le_bytes))
        .collect();
    std::fs::write(&utf16, bytes).unwrap();
    let read = Config::load(&utf16).unwrap();
    let direct = Config::parse(APPENDIX_A, &utf16.display().to_string()).unwrap();
    assert_eq!(format!("{read:?}"), format!("{direct:?}"));
    let latin1 = dir.join("latin1.xml");
    std::fs::write(&latin1, b"<planet>\xe9</planet>").unwrap();
    let message = Config::load(&latin1).unwrap_err().to_string();
    assert!(
        message.contains("not UTF-8") && message.matches("invalid utf-8").count() == 1,
        "{message}"
    );
}
