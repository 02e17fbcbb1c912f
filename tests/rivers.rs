//! River networks: generation, subdivision, tributaries, hulls, samples.

use std::sync::OnceLock;

use glam::{DVec2, DVec3};
use riverplanet::{
    config::Config,
    planet::{cube::PatchId, Planet},
    river::{
        hull,
        network::RiverNetwork,
        samples::{influences, patch_samples, piece_samples, PatchFrame},
        system::{hulls_meet, pieces_to_depth, subdivide},
    },
};

const SEED: u32 = 11;

fn config() -> Config {
    let mut c = Config::appendix_a();
    c.rendering.max_level_of_detail = 4;
    c.planet.base_resolution = 129;
    c
}

fn world() -> &'static (Config, Planet, RiverNetwork) {
    static WORLD: OnceLock<(Config, Planet, RiverNetwork)> = OnceLock::new();
    WORLD.get_or_init(|| {
        let c = config();
        let planet = Planet::generate(&c, SEED, |_| {}).unwrap();
        let network = RiverNetwork::generate(&planet, &c, SEED);
        (c, planet, network)
    })
}

#[test]
fn rivers_start_on_land_and_end_in_the_sea() {
    let (_, planet, network) = world();
    assert!(
        network.systems.len() >= 10,
        "only {} rivers",
        network.systems.len()
    );
    for s in &network.systems {
        assert!(
            planet.height_at(s.source) > planet.sea_level,
            "river {} source under water",
            s.id
        );
        assert!(
            s.segments[0].heights.0 > planet.sea_level,
            "river {} starts below sea level",
            s.id
        );
        assert!(
            planet.height_at(s.mouth) <= planet.sea_level,
            "river {} mouth on land",
            s.id
        );
        assert!(s.segments.last().unwrap().heights.1 <= planet.sea_level);
        // Heights never rise downstream.
        for w in s.segments.windows(2) {
            assert!(w[0].heights.0 >= w[0].heights.1 && w[0].heights.1 == w[1].heights.0);
        }
    }
}

#[test]
fn subdivision_is_c1_and_deterministic() {
    let (_, _, network) = world();
    for s in &network.systems {
        for seg in &s.segments {
            let (a, ta) = subdivide(seg, &network.params);
            let (b, tb) = subdivide(seg, &network.params);
            assert_eq!(a.len(), b.len());
            assert_eq!(ta.map(|t| t.key), tb.map(|t| t.key));
            assert!(a.first().unwrap().curve.p0.distance(seg.curve.p0) < 1e-9);
            assert!(
                a.first()
                    .unwrap()
                    .curve
                    .d0
                    .distance(seg.curve.d0 / a.len() as f64)
                    < 1e-9
            );
            assert!(a.last().unwrap().curve.p1.distance(seg.curve.p1) < 1e-9);
            for w in a.windows(2) {
                assert_eq!(w[0].curve.p1, w[1].curve.p0);
                assert_eq!(w[0].curve.d1, w[1].curve.d0);
            }
            for (x, y) in a.iter().zip(&b) {
                assert_eq!(x.curve, y.curve);
            }
        }
    }
}

#[test]
fn tributary_angles_stay_within_22_to_45_degrees() {
    let (_, _, network) = world();
    let mut seen = 0;
    for s in &network.systems {
        for piece in pieces_to_depth(&s.segments, 3, &network.params) {
            if piece.generation > 0 && piece.key == piece.branch {
                let start_direction = piece.curve.p0 - piece.curve.p1;
                let backwards = -piece.curve.d1;
                let angle = start_direction.angle_to(backwards).abs().to_degrees();
                assert!(
                    (22.0 - 1e-6..=45.0 + 1e-6).contains(&angle),
                    "tributary at {angle} degrees"
                );
                seen += 1;
            }
        }
    }
    assert!(seen > 0);
}

fn curve_points(piece: &riverplanet::river::system::Segment) -> Vec<DVec2> {
    (0..=32)
        .map(|k| piece.curve.point(k as f64 / 32.0))
        .collect()
}

#[test]
fn hulls_contain_every_level_up_to_their_depth_and_extended_hulls_the_rest() {
    let (c, _, network) = world();
    for s in &network.systems {
        for piece in pieces_to_depth(&s.segments, c.river.hull_levels, &network.params) {
            for p in curve_points(&piece) {
                assert!(
                    hull::contains(&s.hull, p, 1e-6),
                    "river {} depth {}: {p} outside hull",
                    s.id,
                    piece.depth
                );
            }
        }
        for piece in pieces_to_depth(&s.segments, c.river.hull_levels + 2, &network.params) {
            for p in curve_points(&piece) {
                for a in 0..8 {
                    let q =
                        p + DVec2::from_angle(a as f64 * 0.785) * c.river.influence_distance as f64;
                    assert!(
                        hull::contains(&s.extended, q, 1e-6),
                        "river {}: {q} outside extended hull",
                        s.id
                    );
                }
            }
        }
    }
}

#[test]
fn no_two_river_systems_cross() {
    let (_, _, network) = world();
    for (i, a) in network.systems.iter().enumerate() {
        for b in &network.systems[i + 1..] {
            assert!(
                !hulls_meet(a, b) && !hulls_meet(b, a),
                "rivers {} and {} overlap",
                a.id,
                b.id
            );
        }
    }
}

#[test]
fn tributaries_meet_their_parent_only_at_the_junction() {
    let (_, _, network) = world();
    for s in &network.systems {
        let pieces = pieces_to_depth(&s.segments, 2, &network.params);
        for trib in pieces
            .iter()
            .filter(|p| p.generation > 0 && p.key == p.branch && p.depth <= 2)
        {
            let parent: Vec<DVec2> = pieces
                .iter()
                .filter(|p| Some(p.branch) == trib.parent_branch && p.depth == trib.depth)
                .flat_map(curve_points)
                .collect();
            let width = trib.widths.0.max(trib.widths.1) as f64;
            for k in 0..=24 {
                let p = trib.curve.point(k as f64 / 32.0);
                let nearest = parent
                    .iter()
                    .map(|q| q.distance(p))
                    .fold(f64::MAX, f64::min);
                assert!(
                    nearest > width * 0.5,
                    "river {}: tributary touches its parent away from the junction",
                    s.id
                );
            }
        }
    }
}

#[test]
fn every_continent_with_mountains_has_rivers_with_tributaries() {
    let (c, planet, network) = world();
    let features = planet.features.as_ref().unwrap();
    let continent_of = |d: DVec3| {
        (0..features.continental.len())
            .min_by(|&a, &b| {
                d.angle_between(features.continental[a])
                    .total_cmp(&d.angle_between(features.continental[b]))
            })
            .unwrap()
    };
    for k in 0..features.continental.len() {
        let has_mountain = planet
            .mountains
            .iter()
            .any(|m| continent_of(DVec3::from_array(m.direction)) == k);
        if !has_mountain {
            continue;
        }
        let rivers: Vec<_> = network
            .systems
            .iter()
            .filter(|s| continent_of(s.source) == k)
            .collect();
        assert!(
            !rivers.is_empty(),
            "continent {k} has mountains but no river"
        );
        let tributaries = rivers
            .iter()
            .flat_map(|s| pieces_to_depth(&s.segments, c.river.hull_levels, &network.params))
            .filter(|p| p.generation > 0)
            .count();
        assert!(
            tributaries > 0,
            "continent {k} has rivers without tributaries"
        );
    }
}

#[test]
fn samples_are_close_enough_to_see_every_basin_vertex() {
    let (c, planet, network) = world();
    let system = &network.systems[0];
    let limit = 1.0 / (2.0 * c.river.samples_per_half_width as f64);
    for level in [2u8, 4, 6] {
        let (face, u, v) = riverplanet::planet::cube::face_of(system.source);
        let n = 1u32 << level;
        let patch = PatchId {
            face: face as u8,
            level,
            x: (((u + 1.0) / 2.0 * n as f64) as u32).min(n - 1),
            y: (((v + 1.0) / 2.0 * n as f64) as u32).min(n - 1),
        };
        let frame = PatchFrame::new(patch, planet.radius, c.rendering.vertices);
        assert!(influences(system, &frame));
        assert!(!patch_samples(network, &frame).samples.is_empty());
        for piece in pieces_to_depth(&system.segments, 2, &network.params) {
            let samples: Vec<_> = piece_samples(network, system, &frame, &piece)
                .map(|(_, s)| s)
                .collect();
            for w in samples.windows(2) {
                let gap = DVec2::from(w[0].position.map(f64::from))
                    .distance(DVec2::from(w[1].position.map(f64::from)));
                let width = w[0].width.min(w[1].width) as f64;
                assert!(
                    gap <= width * limit + 1e-4,
                    "level {level}: samples {gap} apart for width {width}"
                );
            }
        }
    }
}

#[test]
fn far_patches_get_no_samples() {
    let (c, planet, network) = world();
    let system = &network.systems[0];
    let (face, _, _) = riverplanet::planet::cube::face_of(-system.source);
    let frame = PatchFrame::new(
        PatchId {
            face: face as u8,
            level: 3,
            x: 4,
            y: 4,
        },
        planet.radius,
        c.rendering.vertices,
    );
    assert!(!influences(system, &frame));
}

#[test]
fn generation_is_deterministic() {
    let (c, planet, network) = world();
    let again = RiverNetwork::generate(planet, c, SEED);
    assert_eq!(again.systems.len(), network.systems.len());
    for (a, b) in again.systems.iter().zip(&network.systems) {
        assert_eq!(a.hull, b.hull);
    }
}
