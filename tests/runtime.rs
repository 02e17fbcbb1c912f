//! Level of detail and culling against brute force and ray casting.

use std::{collections::BTreeSet, sync::Arc};

use glam::{DVec3, DVec4};
use riverplanet::{
    drainage::meanders::apex_curvature,
    planet::cube::{self, PatchId, FACES},
    rng::Rng,
    runtime::{
        camera::Camera,
        cull::{beyond_horizon, visible_quadrants, Frustum, HeightRange},
        error_field::ErrorField,
        lod::{painted_bank_error, refines, select, LodParams, Selected},
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

/// The error of drawing `patch`'s parent over it: `uneven_error` of the parent level on one face's rough half
/// (x below half the level's count), a tenth of it elsewhere, as mountains beside plains.
fn quadrant_error(patch: PatchId) -> f64 {
    let parent = patch.level as u32 - 1;
    let rough = patch.face == 4 && patch.x < patch.count() / 2;
    uneven_error(parent) * if rough { 1.0 } else { 0.1 }
}

/// The error of a child of `level` anywhere: the largest quadrant error down to level 4 (the precomputed levels
/// of a planet), a small one below (what diamond-square adds, the same everywhere).
fn level_error(level: u32) -> f64 {
    uneven_error(level - 1) * if level <= 4 { 1.0 } else { 0.05 }
}

/// The error of drawing the parent of `patch` over it, as the field has it.
fn own_error(patch: PatchId) -> f64 {
    match patch.level {
        1..=4 => quadrant_error(patch),
        level => level_error(level as u32),
    }
}

/// The field the test selections use: quadrant errors down to level 4, one error per level below.
fn error_field(max_level: u32) -> Arc<ErrorField> {
    Arc::new(ErrorField::new(max_level, 4, quadrant_error, level_error))
}

/// Every patch of `level`.
fn patches(level: u8) -> impl Iterator<Item = PatchId> {
    let n = 1u32 << level;
    (0..FACES as u8).flat_map(move |face| {
        (0..n).flat_map(move |y| (0..n).map(move |x| PatchId { face, level, x, y }))
    })
}

/// Screen-space error: no drawn quadrant (below the deepest level) shows more than the allowed pixels of its own
/// error (the parent's surface over it) at the quadrant's distance, and the flat half of the rough face is drawn
/// with fewer patches than the rough half (the error field spends triangles where the error is).
#[test]
fn screen_space_error_selection_never_draws_more_than_the_allowed_pixels() {
    let (pixels_per_radian, pixels) = (720.0 / (2.0 * (22.5f64).to_radians().tan()), 2.0);
    let p = LodParams::screen_space(RADIUS, error_field(7), pixels_per_radian, pixels, 7);
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
                let shown = own_error(quadrant) * pixels_per_radian / distance;
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
    // Above the middle of face 4, between its rough and its flat half.
    let camera = cube::sphere_point(4, 0.0, 0.0) * (RADIUS + 30.0);
    let (rough, flat) = select(camera, &p)
        .iter()
        .filter(|s| s.patch.face == 4)
        .fold((0, 0), |(r, f), s| {
            if s.patch.x < s.patch.count() / 2 {
                (r + 1, f)
            } else {
                (r, f + 1)
            }
        });
    assert!(
        2 * flat < rough,
        "the flat half draws {flat} patches, the rough half {rough}"
    );
}

/// The error field's switch distances: never below a patch's own error; at every patch's corners at least twice
/// its children's (switch distances halve per level, so patches meet only patches one level apart); the same at a
/// corner for every patch that shares it, on any face (neighbours morph alike along their shared edge).
#[test]
fn error_field_bounds_nests_and_agrees_at_shared_corners() {
    let field = error_field(6);
    let mut corner_values: Vec<(DVec3, f64)> = Vec::new();
    for level in 1..=6u8 {
        for patch in patches(level) {
            let corners = field.corners(patch);
            let own = own_error(patch);
            assert!(
                corners.iter().all(|&c| c >= own),
                "{patch:?}: {corners:?} below {own}"
            );
            if level < 6 {
                let children = (0..4)
                    .flat_map(|q| field.corners(patch.child(q)))
                    .fold(0.0, f64::max);
                assert!(
                    corners.iter().all(|&c| c >= 2.0 * children),
                    "{patch:?}: {corners:?} less than twice its children's {children}"
                );
            }
            if level == 3 {
                corner_values.extend(patch.corners().into_iter().zip(corners));
            }
        }
    }
    // Corners of level 3 that lie at the same place (within rounding) hold the same value.
    corner_values.sort_by(|a, b| a.0.x.total_cmp(&b.0.x));
    let mut shared = 0;
    for (k, (p, v)) in corner_values.iter().enumerate() {
        for (q, w) in corner_values[k + 1..]
            .iter()
            .take_while(|(q, _)| q.x - p.x < 1e-9)
        {
            if p.distance(*q) < 1e-9 {
                assert_eq!(v, w, "corner {p} holds {v} and {w}");
                shared += 1;
            }
        }
    }
    // Every corner of level 3 is shared by four patches (three at the cube's corners).
    assert!(shared > 6 * 64 * 4, "only {shared} shared corners");
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

/// A painted river's bank error (`lod::painted_bank_error`) bounds how far linear interpolation over the mesh's
/// right triangles moves the bank of the tightest bend, and is not loose: the signed distance to a circle of the
/// apex's radius, sampled at the vertices of a grid of right triangles (random offset and rotation) and
/// interpolated, misses its value on the banks by at most the bound and by more than a third of it somewhere. No
/// error where the mesh carves the river (spacing below the half width), none beyond the half width.
#[test]
fn the_painted_bank_error_bounds_the_interpolated_banks_of_the_tightest_bend() {
    let half_width = 1.0;
    let radius = 1.0 / apex_curvature(half_width);
    // The signed distance from the course, a circle about the origin; only its error counts.
    let distance = |p: glam::DVec2| p.length() - radius;
    let mut rng = Rng::new(7, &[]);
    for spacing in [1.25, 1.5, 2.0] {
        let bound = painted_bank_error(spacing, half_width);
        assert!(bound > 0.0 && bound < half_width, "{spacing}: {bound}");
        let mut worst: f64 = 0.0;
        for _ in 0..20_000 {
            let angle = rng.range_f64(0.0, 1.0) * std::f64::consts::TAU;
            let (sin, cos) = angle.sin_cos();
            let rotate =
                |p: glam::DVec2| glam::DVec2::new(cos * p.x - sin * p.y, sin * p.x + cos * p.y);
            let offset =
                glam::DVec2::new(rng.range_f64(0.0, 1.0), rng.range_f64(0.0, 1.0)) * spacing;
            // A point on either bank, in the grid's frame.
            let side = if rng.range_f64(0.0, 1.0) < 0.5 {
                -half_width
            } else {
                half_width
            };
            let along = rng.range_f64(0.0, 1.0) * std::f64::consts::TAU;
            let bank = glam::DVec2::new(along.cos(), along.sin()) * (radius + side);
            let local = rotate(bank) + offset;
            let cell = (local / spacing).floor();
            let (u, v) = (local.x / spacing - cell.x, local.y / spacing - cell.y);
            let at = |i: f64, j: f64| {
                let grid = (cell + glam::DVec2::new(i, j)) * spacing - offset;
                distance(glam::DVec2::new(
                    cos * grid.x + sin * grid.y,
                    -sin * grid.x + cos * grid.y,
                ))
            };
            let interpolated = if u + v < 1.0 {
                at(0.0, 0.0) + u * (at(1.0, 0.0) - at(0.0, 0.0)) + v * (at(0.0, 1.0) - at(0.0, 0.0))
            } else {
                at(1.0, 1.0)
                    + (1.0 - u) * (at(0.0, 1.0) - at(1.0, 1.0))
                    + (1.0 - v) * (at(1.0, 0.0) - at(1.0, 1.0))
            };
            worst = worst.max((interpolated - distance(bank)).abs());
        }
        assert!(
            worst <= bound && worst > bound / 3.0,
            "spacing {spacing}: the banks miss by up to {worst:.4}, the bound is {bound:.4}"
        );
    }
    assert_eq!(painted_bank_error(0.9, half_width), 0.0);
    assert_eq!(painted_bank_error(40.0, half_width), half_width);
}
