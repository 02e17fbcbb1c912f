//! `riverplanet export`: what other tools read, read back from the written file and checked as they would check
//! it.

use std::process::Command;

use serde_json::Value;

fn riverplanet() -> Command {
    Command::new(env!("CARGO_BIN_EXE_riverplanet"))
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir =
        std::env::temp_dir().join(format!("riverplanet-export-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `export rivers` of seed 1 with `args` into DIR/rivers.geojson and reads the file back.
fn export_rivers(name: &str, args: &[&str]) -> Value {
    export_rivers_of(name, 1, args)
}

/// As [`export_rivers`], of `seed`.
fn export_rivers_of(name: &str, seed: u32, args: &[&str]) -> Value {
    let out = temp_dir(name).join("rivers.geojson");
    let run = riverplanet()
        .args(["export", "rivers", "--seed", &seed.to_string()])
        .args(args)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        stdout.contains(&format!("seed: {seed}")),
        "the seed is not printed: {stdout}"
    );
    serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap()
}

/// The lines (LineString coordinates, or each line of a MultiLineString) or rings (of a Polygon or each polygon of
/// a MultiPolygon) of a geometry.
fn paths(geometry: &Value) -> Vec<&Vec<Value>> {
    let coordinates = geometry["coordinates"].as_array().unwrap();
    match geometry["type"].as_str().unwrap() {
        "LineString" => vec![coordinates],
        "MultiLineString" | "Polygon" => {
            coordinates.iter().map(|l| l.as_array().unwrap()).collect()
        }
        "MultiPolygon" => coordinates
            .iter()
            .flat_map(|p| p.as_array().unwrap().iter().map(|r| r.as_array().unwrap()))
            .collect(),
        other => panic!("unexpected geometry type {other}"),
    }
}

/// RFC 7946 as a map tool relies on it: a FeatureCollection of features with geometry and properties; positions
/// of 2 or 3 numbers with longitude in [-180, 180] and latitude in [-90, 90], at most 6 decimals; no segment that
/// spans more than half the world in longitude (3.1.9: cut at the antimeridian instead); rings closed. Returns how
/// many features cross the antimeridian (are cut there).
fn assert_rfc7946(collection: &Value) -> usize {
    assert_eq!(collection["type"], "FeatureCollection");
    let mut cut = 0;
    for feature in collection["features"].as_array().unwrap() {
        assert_eq!(feature["type"], "Feature");
        assert!(feature["properties"].is_object());
        let geometry = &feature["geometry"];
        let kind = geometry["type"].as_str().unwrap();
        for path in paths(geometry) {
            assert!(
                path.len() >= 2,
                "{kind} with a path of {} positions",
                path.len()
            );
            let positions: Vec<Vec<f64>> = path
                .iter()
                .map(|p| {
                    p.as_array()
                        .unwrap()
                        .iter()
                        .map(|x| x.as_f64().unwrap())
                        .collect()
                })
                .collect();
            for p in &positions {
                assert!(p.len() == 2 || p.len() == 3, "position {p:?}");
                assert!(
                    (-180.0..=180.0).contains(&p[0]) && (-90.0..=90.0).contains(&p[1]),
                    "{p:?}"
                );
                for x in &p[..2] {
                    assert!(
                        (x * 1e6 - (x * 1e6).round()).abs() < 1e-3,
                        "{x} has more than 6 decimals"
                    );
                }
            }
            for pair in positions.windows(2) {
                assert!(
                    (pair[1][0] - pair[0][0]).abs() <= 180.0,
                    "a segment from {:?} to {:?} spans the map",
                    pair[0],
                    pair[1]
                );
            }
            if kind.ends_with("Polygon") {
                assert_eq!(positions.first(), positions.last(), "ring not closed");
            }
        }
        if kind.starts_with("Multi") {
            cut += 1;
        }
    }
    cut
}

#[test]
fn the_thesis_rivers_export_as_rfc_7946_with_the_counts_of_the_network() {
    let config = concat!(env!("CARGO_MANIFEST_DIR"), "/config/thesis.xml");
    let collection = export_rivers("thesis", &["--config", config, "--level", "2"]);
    assert_rfc7946(&collection);
    let features = collection["features"].as_array().unwrap();
    let mains = features
        .iter()
        .filter(|f| f["properties"]["parent"].is_null())
        .count();
    let tributaries = features.len() - mains;
    // The same planet's network, counted as stats.json counts it at that level.
    let config = riverplanet::config::Config::load(std::path::Path::new(config)).unwrap();
    let world = riverplanet::world::World::build(&config, 1).unwrap();
    assert_eq!(
        (mains, tributaries),
        world.network.count(2),
        "features against RiverNetwork::count"
    );
    for f in features {
        let p = &f["properties"];
        assert!(p["length"].as_f64().unwrap() > 0.0, "{p}");
        assert_eq!(p["level"], 2);
        let order = p["order"].as_u64().unwrap();
        assert_eq!(order == 0, p["parent"].is_null(), "{p}");
    }
}

#[test]
fn the_drainage_rivers_export_as_rfc_7946_with_bed_heights_and_lakes() {
    let collection = export_rivers("drainage", &[]);
    assert_rfc7946(&collection);
    let features = collection["features"].as_array().unwrap();
    let reaches: Vec<&Value> = features
        .iter()
        .filter(|f| f["properties"]["strahler"].is_u64())
        .collect();
    assert!(reaches.len() > 100, "only {} reaches", reaches.len());
    for reach in &reaches {
        for path in paths(&reach["geometry"]) {
            assert!(
                path.iter().all(|p| p.as_array().unwrap().len() == 3),
                "no bed heights"
            );
        }
        assert!(reach["properties"]["length"].as_f64().unwrap() > 0.0);
    }
    assert!(
        features.iter().any(|f| f["properties"]["lake"].is_u64()),
        "no lake"
    );
}

/// Issue 38: seed 606's rivers pass through points on the antimeridian, where a longitude's last bits put a point
/// on one side and its repetition on the other; rounded, they made a segment from 180 to -180 across the map.
#[test]
fn rivers_through_a_point_on_the_antimeridian_never_span_the_map() {
    let collection = export_rivers_of("antimeridian", 606, &[]);
    assert!(
        assert_rfc7946(&collection) > 0,
        "no river of seed 606 is cut"
    );
}

#[test]
fn export_rivers_refuses_what_it_cannot_write_before_any_work() {
    let dir = temp_dir("refused");
    let png = dir.join("rivers.png");
    let geojson = dir.join("rivers.geojson");
    let thesis = concat!(env!("CARGO_MANIFEST_DIR"), "/config/thesis.xml");
    // (arguments, the output, what the message names). The default planet uses the drainage model, routed at its
    // base lattice's level (2) and up to two above.
    let cases: [(Vec<&str>, &std::path::Path, &str); 3] = [
        (vec![], &png, ".geojson"),
        (vec!["--level", "5"], &geojson, "[0, 4]"),
        (vec!["--config", thesis, "--level", "9"], &geojson, "[0, 8]"),
    ];
    for (args, out, culprit) in cases {
        let run = riverplanet()
            .args(["export", "rivers"])
            .args(&args)
            .arg("--out")
            .arg(out)
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(2), "{args:?}");
        assert!(
            String::from_utf8_lossy(&run.stderr).contains(culprit),
            "{args:?}"
        );
        assert!(!out.exists(), "wrote {}", out.display());
    }
}
