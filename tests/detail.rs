//! Base heights on demand: the per-patch diamond-square step against the whole-face lattice, seams by lattice key
//! at deep levels (patch borders, face borders, cube corners), and the GPU step against the CPU reference.

mod common;

use std::collections::HashMap;

use riverplanet::{
    config::Config,
    gpu::bindless::Bindless,
    planet::{
        cube::{PatchId, FACES},
        detail::{self, PatchHeights, BORDER},
        Planet,
    },
    refine::{generate_on_gpu, HeightRefiner},
};

/// A planet whose precomputed lattice is level 4 and whose base lattice is level 1, so that levels 2-4 exist both
/// as the whole-face diamond-square and as per-patch refinement; its detail follows the slope (`flat-detail`
/// [`SHAPED`]), which every step's share of the displacement must agree on.
fn planet(max_level: u32, seed: u32) -> Planet {
    planet_with(max_level, seed, SHAPED)
}

/// A `flat-detail` below 1: a floodplain's displacement a share of a slope's.
const SHAPED: f32 = 0.15;

/// [`planet`] with `flat-detail` `flat` (1: the thesis's displacement everywhere).
fn planet_with(max_level: u32, seed: u32, flat: f32) -> Planet {
    let mut c = Config::appendix_a();
    c.rendering.max_level_of_detail = max_level;
    c.planet.base_resolution = 65;
    c.planet.flat_detail = flat;
    Planet::generate(&c, seed, |_| {}).unwrap()
}

/// Every stored point of `patches` that is a lattice point (not in a corner quadrant), by cube key.
fn by_key(planet: &Planet, patches: &[PatchHeights]) -> Vec<([i64; 3], f32, PatchId)> {
    let n = planet.vertices;
    let mut out = Vec::new();
    for p in patches {
        let level = p.patch.level as u32;
        let cells = detail::lattice_cells(n, level);
        let (x0, y0) = detail::origin(p.patch, n);
        for j in -BORDER..n as i64 + BORDER {
            for i in -BORDER..n as i64 + BORDER {
                if let Some(k) = detail::key(p.patch.face as usize, cells, (x0 + i, y0 + j)) {
                    out.push((k.to_array(), p.get(i, j), p.patch));
                }
            }
        }
    }
    out
}

/// Fails unless every lattice point held by several patches (of one level) has the same bits in all of them;
/// returns how many points were shared.
fn assert_seams_agree(planet: &Planet, patches: &[PatchHeights]) -> usize {
    let mut seen: HashMap<[i64; 3], (f32, PatchId)> = HashMap::new();
    let mut shared = 0;
    for (key, h, patch) in by_key(planet, patches) {
        match seen.get(&key) {
            Some(&(other, owner)) => {
                shared += 1;
                assert_eq!(
                    h.to_bits(),
                    other.to_bits(),
                    "key {key:?}: {patch:?} has {h}, {owner:?} has {other}"
                );
            }
            None => {
                seen.insert(key, (h, patch));
            }
        }
    }
    shared
}

/// The patches of `level` around the cube corner shared by faces 0 (+X), 2 (+Y) and 5 (-Z) at (+X, +Y, -Z)...
/// and, for every face, its corner patch at (0, 0) and a patch on its west edge, with same-level neighbours.
fn corner_and_edge_patches(level: u8) -> Vec<PatchId> {
    let last = (1u32 << level) - 1;
    let mut out = Vec::new();
    for face in 0..FACES as u8 {
        for (x, y) in [
            (0, 0),
            (last, last),
            (0, last),
            (last, 0),
            (0, last / 2),
            (1.min(last), 0),
        ] {
            out.push(PatchId { face, level, x, y });
        }
    }
    out.sort();
    out.dedup();
    out
}

#[test]
fn refined_patches_equal_the_whole_face_diamond_square() {
    // Levels 2-4 of the precomputed lattice are the whole-face step; the same levels refined per patch from
    // level 1 must give the same bits everywhere, borders included (the folding across face edges and the turn
    // about cube corners are what make the borders right).
    let planet = planet(4, 3);
    assert_eq!(planet.precomputed_level, 4);
    let n = planet.vertices;
    for face in 0..FACES as u8 {
        let mut level_patches: Vec<PatchHeights> = (0..4)
            .map(|k| PatchId {
                face,
                level: 1,
                x: k % 2,
                y: k / 2,
            })
            .map(|p| planet.lattice.patch_heights(p, n))
            .collect();
        for level in 2..=4u32 {
            level_patches = level_patches
                .iter()
                .flat_map(|parent| {
                    (0..4).map(|q| detail::refine(parent, parent.patch.child(q), &planet.rule))
                })
                .collect();
            for refined in &level_patches {
                let cut = planet.lattice.patch_heights(refined.patch, n);
                let cells = detail::lattice_cells(n, level);
                let (x0, y0) = detail::origin(refined.patch, n);
                for j in -BORDER..n as i64 + BORDER {
                    for i in -BORDER..n as i64 + BORDER {
                        if detail::in_corner_quadrant(cells, (x0 + i, y0 + j)) {
                            continue;
                        }
                        assert_eq!(
                            refined.get(i, j).to_bits(),
                            cut.get(i, j).to_bits(),
                            "{:?} point ({i}, {j}): refined {} vs whole-face {}",
                            refined.patch,
                            refined.get(i, j),
                            cut.get(i, j)
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn seams_are_bit_equal_at_deep_levels_across_faces_and_corners() {
    let planet = planet(20, 7);
    for level in [6u8, 12, 20] {
        let patches: Vec<PatchHeights> = corner_and_edge_patches(level)
            .into_iter()
            .flat_map(|p| {
                let mut v = vec![p];
                v.extend(riverplanet::planet::cube::EDGES.map(|e| p.neighbour(e)));
                v
            })
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .map(|p| planet.patch_heights(p))
            .collect();
        let shared = assert_seams_agree(&planet, &patches);
        // Each of the 8 cube corners is held by three patches, and every patch edge by two.
        assert!(shared > 1000, "level {level}: only {shared} shared points");
    }
}

#[test]
fn detail_continues_at_every_depth() {
    // Heights keep changing between levels (the displacement halves per level, it never stops), and a deep patch
    // is not flat.
    let planet = planet(24, 11);
    let mut p = PatchId {
        face: 4,
        level: 24,
        x: 5 << 20,
        y: 9 << 20,
    };
    let deep = planet.patch_heights(p);
    let (lo, hi) = deep.range();
    assert!(hi > lo, "level 24 patch is flat");
    // Relief scales with the patch: the range at level 24 is about 2^-20 of that at level 4.
    p = PatchId {
        face: 4,
        level: 4,
        x: 5,
        y: 9,
    };
    let coarse = planet.patch_heights(p).range();
    assert!(hi - lo < (coarse.1 - coarse.0) * 1e-3);
    // Every height stays within the planet's bounds.
    let (min, max) = planet.height_bounds();
    assert!(lo >= min && hi <= max, "{lo}..{hi} outside {min}..{max}");
}

#[test]
fn gpu_refinement_equals_the_cpu_reference_bit_for_bit() {
    let Some(ctx) = common::gpu() else { return };
    for flat in [SHAPED, 1.0] {
        gpu_refinement_equals_the_cpu_reference_with(ctx, &planet_with(20, 5, flat));
    }
    common::assert_no_validation_errors(ctx);
    ctx.wait_idle().unwrap();
}

fn gpu_refinement_equals_the_cpu_reference_with(ctx: &riverplanet::gpu::Context, planet: &Planet) {
    let mut bindless = Bindless::new(ctx, 1024).unwrap();
    let refiner = HeightRefiner::new(ctx, &bindless, planet.vertices).unwrap();
    for level in [6u8, 12, 20] {
        let wanted = corner_and_edge_patches(level);
        let made = generate_on_gpu(ctx, &mut bindless, &refiner, planet, &wanted).unwrap();
        let gpu = made.heights;
        for g in &gpu {
            let cpu = planet.patch_heights(g.patch);
            let differing = g
                .data
                .iter()
                .zip(&cpu.data)
                .filter(|(a, b)| a.to_bits() != b.to_bits())
                .count();
            assert_eq!(
                differing, 0,
                "{:?}: {differing} texels differ from the CPU reference",
                g.patch
            );
            // The range the shader reduces (for the renderer's bounds) is the texture's.
            assert_eq!(made.ranges[&g.patch], cpu.range(), "{:?}", g.patch);
        }
        let shared = assert_seams_agree(planet, &gpu);
        assert!(shared > 0, "level {level}");
    }
}

/// The screen-space error's bounds (beyond the thesis): no vertex of the finest drawn level stands further from a
/// coarser patch's surface (bilinear between its vertices) than the error of the quadrant it lies in
/// (`Planet::quadrant_error`), nor than that level's error anywhere (`Planet::geometric_error`, their largest), and
/// the bounds are not vacuous (some quadrant comes within half of its own).
#[test]
fn geometric_errors_bound_the_finest_drawn_surface() {
    let planet = planet(6, 3);
    let n = planet.vertices as i64;
    let finest = planet.max_level as u8;
    let mut rng = riverplanet::rng::Rng::new(9, &[]);
    let mut tightest = 0.0f64;
    for level in 0..finest {
        let count = 1u64 << level;
        let scale = 1u32 << (finest - level);
        let mut worst = 0.0f64;
        for _ in 0..200 {
            let coarse = PatchId {
                face: rng.below(FACES as u64) as u8,
                level,
                x: rng.below(count) as u32,
                y: rng.below(count) as u32,
            };
            let fine = PatchId {
                face: coarse.face,
                level: finest,
                x: coarse.x * scale + rng.below(scale as u64) as u32,
                y: coarse.y * scale + rng.below(scale as u64) as u32,
            };
            let quadrant = PatchId {
                face: fine.face,
                level: level + 1,
                x: fine.x >> (finest - level - 1),
                y: fine.y >> (finest - level - 1),
            };
            let bound = planet.quadrant_error(quadrant);
            assert!(bound <= planet.geometric_error(level as u32));
            let mut quadrant_worst = 0.0f64;
            let (c, f) = (planet.patch_heights(coarse), planet.patch_heights(fine));
            for j in 0..n {
                for i in 0..n {
                    // The fine vertex in the coarse patch's vertex coordinates.
                    let at = |offset: u32, k: i64| {
                        (offset as f64 * (n - 1) as f64 + k as f64) / scale as f64
                    };
                    let (x, y) = (
                        at(fine.x - coarse.x * scale, i),
                        at(fine.y - coarse.y * scale, j),
                    );
                    let (ci, cj) = ((x as i64).min(n - 2), (y as i64).min(n - 2));
                    let (fx, fy) = (x - ci as f64, y - cj as f64);
                    let h = |di: i64, dj: i64| c.get(ci + di, cj + dj) as f64;
                    let bilinear = (h(0, 0) * (1.0 - fx) + h(1, 0) * fx) * (1.0 - fy)
                        + (h(0, 1) * (1.0 - fx) + h(1, 1) * fx) * fy;
                    quadrant_worst = quadrant_worst.max((f.get(i, j) as f64 - bilinear).abs());
                }
            }
            assert!(
                quadrant_worst <= bound,
                "{quadrant:?}: a level-{finest} vertex stands {quadrant_worst} from its parent's surface, error {bound}"
            );
            tightest = tightest.max(quadrant_worst / bound);
            worst = worst.max(quadrant_worst);
        }
        let bound = planet.geometric_error(level as u32);
        assert!(
            worst <= bound,
            "level {level}: a level-{finest} vertex stands {worst} from the surface, error {bound}"
        );
    }
    assert!(
        tightest > 0.5,
        "the errors are at least twice too large ({tightest})"
    );
}
