//! Level of detail and culling against brute force and ray casting.

use std::collections::BTreeSet;

use glam::{DVec3, DVec4};
use riverplanet::{
    planet::cube::{self, PatchId, FACES},
    rng::Rng,
    runtime::{
        camera::Camera,
        cull::{beyond_horizon, visible_quadrants, Frustum, HeightRange},
        lod::{refines, select, LodParams, Selected},
    },
};

const RADIUS: f64 = 1024.0;

fn params(max_level: u32) -> LodParams {
    LodParams::distance(RADIUS, 8.0, max_level)
}

fn random_camera(rng: &mut Rng) -> DVec3 {
    let d = riverplanet::planet::continents::random_direction(rng);
    // From just above the surface to far orbit.
    d * (RADIUS + 10f64.powf(rng.range_f64(0.0, 4.0)))
}

/// Brute force of Eq. 6.1: a patch is visited when it and every ancestor refine; a visited patch draws the
/// quadrants whose child is not visited (all at the deepest level).
fn brute_force(camera: DVec3, p: &LodParams) -> BTreeSet<Selected> {
    let mut out = BTreeSet::new();
    for face in 0..FACES {
        for level in 0..=p.max_level as u8 {
            let n = 1u32 << level;
            for y in 0..n {
                for x in 0..n {
                    let patch = PatchId {
                        face: face as u8,
                        level,
                        x,
                        y,
                    };
                    let mut visited = true;
                    let mut a = patch;
                    while let Some(parent) = a.parent() {
                        visited &= refines(a, camera, p);
                        a = parent;
                    }
                    if !visited {
                        continue;
                    }
                    let quadrants = if level as u32 == p.max_level {
                        0b1111
                    } else {
                        (0..4)
                            .filter(|&q| !refines(patch.child(q), camera, p))
                            .fold(0u8, |m, q| m | 1 << q)
                    };
                    if quadrants != 0 {
                        out.insert(Selected { patch, quadrants });
                    }
                }
            }
        }
    }
    out
}

#[test]
fn lod_selection_equals_brute_force_of_eq_6_1() {
    let mut rng = Rng::new(1, &[]);
    for _ in 0..40 {
        let camera = random_camera(&mut rng);
        let p = params(5);
        let fast: BTreeSet<Selected> = select(camera, &p).into_iter().collect();
        assert_eq!(fast, brute_force(camera, &p), "camera {camera}");
    }
}

/// A geometric error per level that does not halve everywhere (a rough level 2), as a planet's measured errors.
fn uneven_error(level: u32) -> f64 {
    let base = 40.0 / (1u64 << level) as f64;
    if level == 2 {
        base * 3.0
    } else {
        base
    }
}

/// Screen-space error: no drawn quadrant (below the deepest level) shows more than the allowed pixels of its
/// patch's error at the quadrant's nearest distance, and switch distances at least halve per level (patches meet
/// only patches one level apart).
#[test]
fn screen_space_error_selection_never_draws_more_than_the_allowed_pixels() {
    let (pixels_per_radian, pixels) = (720.0 / (2.0 * (22.5f64).to_radians().tan()), 2.0);
    let p = LodParams::screen_space(RADIUS, uneven_error, pixels_per_radian, pixels, 7);
    for level in 1..p.max_level {
        assert!(
            p.threshold(level) >= 2.0 * p.threshold(level + 1),
            "level {level}: {} < 2 x {}",
            p.threshold(level),
            p.threshold(level + 1)
        );
    }
    let mut rng = Rng::new(5, &[]);
    let mut checked = 0;
    for _ in 0..100 {
        let camera = random_camera(&mut rng);
        for s in select(camera, &p) {
            if s.patch.level as u32 == p.max_level {
                continue;
            }
            for q in (0..4).filter(|q| s.quadrants & (1 << q) != 0) {
                let quadrant = s.patch.child(q);
                let distance = camera.distance(quadrant.center() * RADIUS);
                let shown = uneven_error(s.patch.level as u32) * pixels_per_radian / distance;
                assert!(
                    shown <= pixels * (1.0 + 1e-9),
                    "{:?} quadrant {q} shows {shown:.2} pixels of error at {distance:.1}",
                    s.patch
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 1000, "only {checked} quadrants checked");
}

#[test]
fn selected_quadrants_tile_the_sphere_exactly_once() {
    let mut rng = Rng::new(2, &[]);
    for _ in 0..10 {
        let camera = random_camera(&mut rng);
        let selected = select(camera, &params(6));
        for _ in 0..500 {
            let d = riverplanet::planet::continents::random_direction(&mut rng);
            let covering = selected.iter().filter(|s| covers(s, d)).count();
            assert_eq!(covering, 1, "direction {d}");
        }
    }
}

/// Whether a drawn quadrant of `s` contains direction `d`.
fn covers(s: &Selected, d: DVec3) -> bool {
    let (face, u, v) = cube::face_of(d);
    if face != s.patch.face as usize {
        return false;
    }
    let (u0, v0) = s.patch.origin();
    let size = s.patch.size();
    let (fx, fy) = ((u - u0) / size, (v - v0) / size);
    if !(0.0..1.0).contains(&fx) && fx != 1.0 || !(0.0..1.0).contains(&fy) && fy != 1.0 {
        return false;
    }
    let q = (fx >= 0.5) as u8 | (((fy >= 0.5) as u8) << 1);
    s.quadrants & (1 << q) != 0
}

#[test]
fn no_quadrant_with_a_visible_pixel_is_culled() {
    let range = HeightRange {
        min: -6.0,
        max: 16.5,
    };
    let mut rng = Rng::new(3, &[]);
    let (mut culled_somewhere, mut hits) = (false, 0);
    for _ in 0..30 {
        let camera = random_camera(&mut rng);
        // Look at a random point of the visible side, with a random field of view.
        let target = riverplanet::planet::continents::random_direction(&mut rng) * RADIUS * 0.5
            + camera.normalize() * RADIUS;
        let fov = rng.range_f64(20.0, 90.0).to_radians();
        let altitude = camera.length() - RADIUS;
        let eye = Camera::look_at(
            camera,
            target,
            fov.to_degrees(),
            4.0 / 3.0,
            (altitude * 0.01).max(0.01),
        );
        let clip = eye.clip();
        let frustum = Frustum::from_matrix(clip);
        let inverse = clip.inverse();
        let selected = select(camera, &params(6));
        let visible: Vec<Selected> = selected
            .iter()
            .filter_map(|s| visible_quadrants(s, camera, &frustum, RADIUS, range))
            .collect();
        for py in 0..24 {
            for px in 0..32 {
                let ndc = (px as f64 + 0.5) / 32.0 * 2.0 - 1.0;
                let ndc_y = (py as f64 + 0.5) / 24.0 * 2.0 - 1.0;
                let unproject = |z: f64| {
                    let p = inverse * DVec4::new(ndc, ndc_y, z, 1.0);
                    p.truncate() / p.w
                };
                // Reversed Z: depth 1 at the near plane; 1e-6 is far beyond the planet.
                let (near, far) = (unproject(1.0), unproject(1e-6));
                let dir = (far - near).normalize();
                // First hit with the sphere at sea-floor radius (every drawn surface is at or above it).
                let b = near.dot(dir);
                let c = near.length_squared() - (RADIUS + range.min).powi(2);
                let disc = b * b - c;
                if disc < 0.0 {
                    continue;
                }
                let t = -b - disc.sqrt();
                if t < 0.0 {
                    continue;
                }
                let hit = (near + dir * t).normalize();
                hits += 1;
                assert!(
                    selected.iter().any(|s| covers(s, hit)),
                    "every direction is covered"
                );
                assert!(
                    visible.iter().any(|v| covers(v, hit)),
                    "camera {camera}: the quadrant at pixel ({px}, {py}) was culled"
                );
            }
        }
        // Culling per quadrant must cull: a view of part of the planet leaves quadrants out.
        let drawn: u32 = visible.iter().map(|v| v.quadrants.count_ones()).sum();
        let selectable: u32 = selected.iter().map(|s| s.quadrants.count_ones()).sum();
        culled_somewhere |= drawn < selectable;
    }
    assert!(hits > 1000, "the cameras see the planet ({hits} pixels)");
    assert!(culled_somewhere, "no quadrant was ever culled");
}

#[test]
fn far_side_patches_are_culled() {
    let range = HeightRange {
        min: -6.0,
        max: 16.5,
    };
    let camera = DVec3::new(0.0, 0.0, RADIUS + 50.0);
    let back = PatchId::root(5);
    assert!(beyond_horizon(back, camera, RADIUS, range));
    assert!(!beyond_horizon(PatchId::root(4), camera, RADIUS, range));
}
