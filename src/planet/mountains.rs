//! The thesis's mountains (4.2): square masks on the coarsest heightmap, whose tops are the river sources of the
//! thesis's river model. The drainage model raises relief instead (`relief`).

use serde::Serialize;

use super::{cube::FACES, heights::FaceLattice};
use crate::{config::Config, rng::Rng};

const STREAM_MOUNTAINS: u64 = 0x40_0001;

/// A mountain of Section 4.2: the 3x3 mask's centre, kept as a river source.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Mountain {
    /// The cube face it stands on.
    pub face: usize,
    /// Position on the base lattice.
    pub i: u32,
    /// See `i`.
    pub j: u32,
    /// Its direction from the planet's centre (unit).
    pub direction: [f64; 3],
    /// Its height on the base lattice.
    pub height: f32,
}

/// Seeds `mountains-per-continent x continents` mountains (4.2): a 3x3 mask on the coarsest heightmap (level 0,
/// whose cells are `base.cells / (vertices - 1)` base cells wide), placed where all nine points are continental and
/// not part of another mountain. The centre gets `max-mountain-height`, the eight around it
/// `mountain-shoulder-factor` of that; the mask is spread bilinearly onto the base lattice, so a mountain is a
/// peak about four level-0 cells wide. Masks and their ring stay inside a face,
/// so shared border points are never touched.
pub fn seed_mountains(base: &mut FaceLattice, config: &Config, seed: u64) -> Vec<Mountain> {
    let p = &config.planet;
    let wanted = (p.mountains_per_continent * p.continents.max(1)) as usize;
    let mut rng = Rng::new(seed, &[STREAM_MOUNTAINS]);
    let coarse = config.rendering.vertices - 1;
    if coarse < 8 {
        log::warn!(
            "vertices {} leaves no room for 3x3 mountain masks inside a face; no mountains",
            coarse + 1
        );
        return Vec::new();
    }
    let k = base.cells / coarse;
    let mut used = vec![false; FACES * (coarse as usize + 1).pow(2)];
    let used_index = |f: usize, x: u32, y: u32| {
        (f * (coarse as usize + 1) + y as usize) * (coarse as usize + 1) + x as usize
    };
    let shoulder = p.max_mountain_height * p.mountain_shoulder_factor;
    let mut mountains = Vec::new();
    for _ in 0..wanted * 200 {
        if mountains.len() == wanted {
            break;
        }
        let face = rng.below(FACES as u64) as usize;
        // The mask and its surrounding ring stay off the face border, which adjacent faces share.
        let ci = 3 + rng.below(coarse as u64 - 5) as u32;
        let cj = 3 + rng.below(coarse as u64 - 5) as u32;
        let free = (0..9).all(|m| {
            let (x, y) = (ci + m % 3 - 1, cj + m / 3 - 1);
            base.get(face, x * k, y * k) > p.sea_level_height && !used[used_index(face, x, y)]
        });
        if !free {
            continue;
        }
        for y in cj - 2..=cj + 2 {
            for x in ci - 2..=ci + 2 {
                used[used_index(face, x, y)] = true;
            }
        }
        // Mask value at level-0 offset (dx, dy) from the centre: top, shoulders, then the land around.
        let mask = |dx: i32, dy: i32| match dx.abs().max(dy.abs()) {
            0 => p.max_mountain_height,
            1 => shoulder,
            _ => p.continent_height,
        };
        let (i0, j0) = (ci * k, cj * k);
        for j in (j0 - 2 * k)..=(j0 + 2 * k) {
            for i in (i0 - 2 * k)..=(i0 + 2 * k) {
                let fx = (i as f32 - i0 as f32) / k as f32;
                let fy = (j as f32 - j0 as f32) / k as f32;
                let (x0, y0) = (fx.floor() as i32, fy.floor() as i32);
                let (tx, ty) = (fx - x0 as f32, fy - y0 as f32);
                let value = mask(x0, y0) * (1.0 - tx) * (1.0 - ty)
                    + mask(x0 + 1, y0) * tx * (1.0 - ty)
                    + mask(x0, y0 + 1) * (1.0 - tx) * ty
                    + mask(x0 + 1, y0 + 1) * tx * ty;
                let index = base.index(face, i, j);
                base.data[index] = base.data[index].max(value);
            }
        }
        let direction = base.direction(base.key(face, i0, j0));
        mountains.push(Mountain {
            face,
            i: i0,
            j: j0,
            direction: direction.to_array(),
            height: p.max_mountain_height,
        });
    }
    mountains
}
