//! The planet model: face adjacency, patch neighbours, seamless heights, landmass share, determinism.

use glam::DVec3;
use riverplanet::{
    config::Config,
    planet::{
        cube::{self, adjacent, Edge, PatchId, EDGES, FACES},
        Planet,
    },
};

/// A small planet for fast tests: max level 3 (precomputed lattice 257 cells per face).
fn small_config(landmass: f32) -> Config {
    let mut c = Config::appendix_a();
    c.rendering.max_level_of_detail = 3;
    c.planet.base_resolution = 65;
    c.planet.landmass_percentage = landmass;
    c
}

#[test]
fn every_face_edge_pairs_with_exactly_one_other_and_back() {
    for face in 0..FACES {
        for edge in EDGES {
            let a = adjacent(face, edge);
            assert_ne!(a.face, face);
            let back = adjacent(a.face, a.edge);
            assert_eq!(
                (back.face, back.edge),
                (face, edge),
                "{face} {edge:?} -> {a:?} -> {back:?}"
            );
            assert_eq!(back.reversed, a.reversed);
            // The edges are the same line in space, traversed as `reversed` says.
            for s in [-1.0, -0.3, 0.5, 1.0] {
                let here = edge.point(face, s);
                let there = a.edge.point(a.face, if a.reversed { -s } else { s });
                assert!(
                    here.abs_diff_eq(there, 1e-12),
                    "{face} {edge:?} s={s}: {here} vs {there}"
                );
            }
        }
    }
}

#[test]
fn face_corners_are_shared_by_three_faces() {
    for face in 0..FACES {
        for (u, v) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            let p = cube::cube_point(face, u, v);
            let sharing = (0..FACES)
                .filter(|&f| {
                    let (_, a, b) = cube::face_of_on(f, p);
                    (p.dot(cube::FACE_AXES[f].0) - 1.0).abs() < 1e-12
                        && a.abs() <= 1.0 + 1e-12
                        && b.abs() <= 1.0 + 1e-12
                })
                .count();
            assert_eq!(sharing, 3, "corner {p}");
        }
    }
}

#[test]
fn patch_neighbours_touch_and_are_mutual() {
    for level in [0u8, 1, 3] {
        for face in 0..FACES {
            let n = 1u32 << level;
            for (x, y) in [
                (0, 0),
                (n - 1, 0),
                (0, n - 1),
                (n - 1, n - 1),
                (n / 2, n / 2),
            ] {
                let p = PatchId {
                    face: face as u8,
                    level,
                    x,
                    y,
                };
                for edge in EDGES {
                    let q = p.neighbour(edge);
                    assert_eq!(q.level, level);
                    // They share two corners.
                    let shared = p
                        .corners()
                        .iter()
                        .filter(|c| q.corners().iter().any(|d| c.abs_diff_eq(*d, 1e-9)))
                        .count();
                    assert_eq!(shared, 2, "{p:?} {edge:?} -> {q:?}");
                    assert!(
                        EDGES.iter().any(|e| q.neighbour(*e) == p),
                        "{p:?} not a neighbour of {q:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn face_of_inverts_the_face_mapping() {
    for face in 0..FACES {
        for (u, v) in [(0.0, 0.0), (0.5, -0.25), (-0.99, 0.99)] {
            let (f, a, b) = cube::face_of(cube::sphere_point(face, u, v));
            assert_eq!(f, face);
            assert!((a - u).abs() < 1e-12 && (b - v).abs() < 1e-12);
        }
    }
}

/// Heights of two patches along their shared edge, in the order of the edge's points in space.
fn edge_heights(planet: &Planet, p: PatchId, edge: Edge) -> Vec<(DVec3, f32)> {
    let n = planet.vertices;
    let h = planet.patch_heights(p).interior();
    (0..n)
        .map(|k| {
            let (i, j) = match edge {
                Edge::West => (0, k),
                Edge::East => (n - 1, k),
                Edge::South => (k, 0),
                Edge::North => (k, n - 1),
            };
            let s = i as f64 / (n - 1) as f64;
            let t = j as f64 / (n - 1) as f64;
            (p.sphere_point(s, t), h[(j * n + i) as usize])
        })
        .collect()
}

#[test]
fn seams_are_bit_equal_at_every_level_and_across_faces() {
    for seed in [1u32, 7, 12345] {
        let planet = Planet::generate(&small_config(30.0), seed, |_| {}).unwrap();
        for level in 0..=planet.max_level as u8 {
            let n = 1u32 << level;
            for face in 0..FACES {
                for x in 0..n {
                    for y in 0..n {
                        let p = PatchId {
                            face: face as u8,
                            level,
                            x,
                            y,
                        };
                        for edge in EDGES {
                            let q = p.neighbour(edge);
                            let mine = edge_heights(&planet, p, edge);
                            let theirs: Vec<_> = EDGES
                                .iter()
                                .flat_map(|e| edge_heights(&planet, q, *e))
                                .collect();
                            for (pos, h) in mine {
                                let other = theirs
                                    .iter()
                                    .find(|(d, _)| d.abs_diff_eq(pos, 1e-9))
                                    .unwrap_or_else(|| {
                                        panic!("{p:?} {edge:?}: {pos} not on {q:?}")
                                    });
                                assert_eq!(
                                    h.to_bits(),
                                    other.1.to_bits(),
                                    "seed {seed} {p:?} {edge:?} vs {q:?} at {pos}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn landmass_matches_the_request() {
    for target in [5.0f32, 30.0, 60.0] {
        let planet = Planet::generate(&small_config(target), 3, |_| {}).unwrap();
        let s = &planet.stats;
        assert!(
            (s.landmass_percent - target as f64).abs() <= 1.0,
            "requested {target}%, got {:.2}% (continents {:.2}%)",
            s.landmass_percent,
            s.continent_percent
        );
    }
}

#[test]
fn same_seed_same_planet_and_different_seed_differs() {
    let c = small_config(30.0);
    let a = Planet::generate(&c, 42, |_| {}).unwrap();
    let b = Planet::generate(&c, 42, |_| {}).unwrap();
    assert!(a
        .lattice
        .data
        .iter()
        .zip(&b.lattice.data)
        .all(|(x, y)| x.to_bits() == y.to_bits()));
    let d = Planet::generate(&c, 43, |_| {}).unwrap();
    assert!(a.lattice.data != d.lattice.data);
}

#[test]
fn mountains_stand_on_land() {
    let planet = Planet::generate(&small_config(30.0), 5, |_| {}).unwrap();
    assert!(!planet.mountains.is_empty());
    for m in &planet.mountains {
        let d = DVec3::from_array(m.direction);
        assert!(planet.height_at(d) > planet.sea_level, "{m:?}");
    }
}

#[test]
fn continents_from_an_image_follow_the_image() {
    let dir = std::env::temp_dir().join(format!("riverplanet-image-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let source = Planet::generate(&small_config(40.0), 9, |_| {}).unwrap();
    let path = dir.join("continents.png");
    riverplanet::export::equirectangular_land(&source, 512)
        .save(&path)
        .unwrap();
    let mut c = small_config(40.0);
    c.planet.continents_from_file = true;
    c.planet.continents_image = path.display().to_string();
    c.planet.coast_perturbation = 0.0;
    let planet = Planet::generate(&c, 9, |_| {}).unwrap();
    // Land and sea agree with the source planet almost everywhere (coasts move by a cell or so).
    let mut rng = riverplanet::rng::Rng::new(5, &[]);
    let trials = 4000;
    let agree = (0..trials)
        .filter(|_| {
            let p = riverplanet::planet::continents::random_direction(&mut rng);
            planet.is_land(p) == source.is_land(p)
        })
        .count();
    assert!(
        agree as f64 / trials as f64 > 0.93,
        "only {agree} of {trials} directions agree"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn unreadable_or_wrong_sized_images_are_clear_errors() {
    let dir = std::env::temp_dir().join(format!("riverplanet-badimage-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let square = dir.join("square.png");
    image::GrayImage::new(64, 64).save(&square).unwrap();
    let garbage = dir.join("garbage.png");
    std::fs::write(&garbage, b"not a png").unwrap();
    let missing = dir.join("missing.png");
    let sea = dir.join("sea.png");
    image::GrayImage::new(64, 32).save(&sea).unwrap();
    let land = dir.join("land.png");
    image::GrayImage::from_pixel(64, 32, image::Luma([255]))
        .save(&land)
        .unwrap();
    for (path, expect) in [
        (&square, "twice as wide as high"),
        (&garbage, "cannot read"),
        (&missing, "cannot read"),
        (&sea, "is all sea"),
        (&land, "is all land"),
    ] {
        let mut c = small_config(30.0);
        c.planet.continents_from_file = true;
        c.planet.continents_image = path.display().to_string();
        let err = Planet::generate(&c, 1, |_| {})
            .err()
            .expect("must fail")
            .to_string();
        assert!(
            err.contains(expect) && err.contains(&path.display().to_string()),
            "{err}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn base_resolution_must_fit_the_patch_grid() {
    let mut c = small_config(30.0);
    c.planet.base_resolution = 97;
    let err = Planet::generate(&c, 1, |_| {})
        .err()
        .expect("must fail")
        .to_string();
    assert!(
        err.contains("base-resolution 97") && err.contains("33, 65"),
        "{err}"
    );
}

#[test]
fn tiny_grids_generate_without_panicking() {
    let mut c = Config::appendix_a();
    c.rendering.vertices = 5;
    c.rendering.max_level_of_detail = 2;
    c.planet.base_resolution = 9;
    let planet = Planet::generate(&c, 1, |_| {}).unwrap();
    assert!(planet.mountains.is_empty());
    let network = riverplanet::river::network::RiverNetwork::generate(&planet, &c, 1);
    assert!(network.systems.is_empty());
}
