//! Beyond the thesis: the screen-space rule's geometric error where it differs from place to place. A level's
//! worst error anywhere on the planet (a mountain range's) refines a plain as finely as the range; here each
//! patch is visited by the error its parent's surface shows over the patch's own area, while switch distances
//! stay a continuous field, so that same-level neighbours still morph alike along their shared edge and a patch
//! still meets coarser patches only where it is fully morphed (docs/rendering.md, "Screen-space error").
//!
//! The field of a level holds one value at each corner of that level's patches, the largest error of the patches
//! touching the corner (on whichever faces they lie), and is bilinear across each patch: at every point of a patch
//! it is then at least the patch's own error, and along an edge it depends only on the edge's two corners. Each
//! level's field is at least twice the next finer one's over the same and the neighbouring patches (the field's
//! form of halving switch distances), so a patch's surroundings are refined at most one level apart.

use glam::I64Vec3;

use crate::planet::{
    cube::{PatchId, FACES},
    detail,
};

/// Errors (world units) that decide whether the children of a patch are visited, per child level: a field over
/// the levels up to `field_levels`, one value per level beyond (where errors are the same everywhere).
#[derive(Clone, Debug)]
pub struct ErrorField {
    /// Per level 1..=field levels (index level - 1), per face, the `(2^level + 1)^2` corner values, row-major.
    corners: Vec<Vec<f64>>,
    /// Per level 0..=max_level: the error of a child of that level where no field holds it, nested (level 0,
    /// the roots, is always drawn: infinite).
    uniform: Vec<f64>,
}

impl ErrorField {
    /// The field for children of levels 1..=`max_level`: `quadrant_error(patch)` for patches of levels up to
    /// `field_levels` (how far drawing its parent over its area can stand from the finest surface), and
    /// `level_error(level)` for every level (the worst of `quadrant_error` over the level, or its bound).
    pub fn new(
        max_level: u32,
        field_levels: u32,
        quadrant_error: impl Fn(PatchId) -> f64,
        level_error: impl Fn(u32) -> f64,
    ) -> Self {
        let field_levels = field_levels.min(max_level);
        let mut uniform: Vec<f64> = (0..=max_level)
            .map(|level| match level {
                0 => f64::INFINITY,
                _ => level_error(level),
            })
            .collect();
        for level in (1..max_level as usize).rev() {
            uniform[level] = uniform[level].max(2.0 * uniform[level + 1]);
        }
        let mut corners: Vec<Vec<f64>> = vec![Vec::new(); field_levels as usize];
        for level in (1..=field_levels).rev() {
            let mut own = corner_maxima(level, &quadrant_error);
            if level < max_level {
                let finer: Box<dyn Fn(PatchId) -> f64 + '_> = match corners.get(level as usize) {
                    Some(finer) => Box::new(move |p: PatchId| 2.0 * finest_corner(finer, p)),
                    None => Box::new(|_| 2.0 * uniform[level as usize + 1]),
                };
                let nested = corner_maxima(level, &finer);
                for (a, b) in own.iter_mut().zip(nested) {
                    *a = a.max(b);
                }
            }
            corners[level as usize - 1] = own;
        }
        Self { corners, uniform }
    }

    /// The error at `patch`'s corners (0,0), (1,0), (0,1), (1,1) that decides whether it is visited and how its
    /// vertices morph (switch distances are this over the pixels' angle).
    pub fn corners(&self, patch: PatchId) -> [f64; 4] {
        match patch.level {
            0 => [f64::INFINITY; 4],
            level => match self.corners.get(level as usize - 1) {
                Some(field) => {
                    let side = (1usize << level) + 1;
                    let at = |dx: u32, dy: u32| {
                        field[(patch.face as usize * side + (patch.y + dy) as usize) * side
                            + (patch.x + dx) as usize]
                    };
                    [at(0, 0), at(1, 0), at(0, 1), at(1, 1)]
                }
                None => [self.uniform[(level as usize).min(self.uniform.len() - 1)]; 4],
            },
        }
    }

    /// The largest error of a level anywhere (what the rule was before the field: the same at every patch).
    pub fn worst(&self, level: u32) -> f64 {
        match self.corners.get((level as usize).wrapping_sub(1)) {
            Some(field) => field.iter().copied().fold(0.0, f64::max),
            None => self.uniform[(level as usize).min(self.uniform.len() - 1)],
        }
    }
}

/// The largest corner value of the finer level's field over `patch`'s area (its four children's nine corners).
fn finest_corner(finer: &[f64], patch: PatchId) -> f64 {
    let side = (1usize << (patch.level + 1)) + 1;
    let (x, y) = (2 * patch.x as usize, 2 * patch.y as usize);
    (0..3)
        .flat_map(|dy| (0..3).map(move |dx| (dx, dy)))
        .map(|(dx, dy)| finer[(patch.face as usize * side + y + dy) * side + x + dx])
        .fold(0.0, f64::max)
}

/// Per face, at every corner of `level`'s patches, the largest `value` of the patches that touch it, on any face
/// (a corner on a face edge belongs to two faces, a cube corner to three: they are matched by their cube key).
fn corner_maxima(level: u32, value: &dyn Fn(PatchId) -> f64) -> Vec<f64> {
    let count = 1u32 << level;
    let side = count as usize + 1;
    let mut out = vec![0.0f64; FACES * side * side];
    for face in 0..FACES {
        for y in 0..count {
            for x in 0..count {
                let e = value(PatchId {
                    face: face as u8,
                    level: level as u8,
                    x,
                    y,
                });
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let k = (face * side + (y + dy) as usize) * side + (x + dx) as usize;
                    out[k] = out[k].max(e);
                }
            }
        }
    }
    // Corners on face edges: the largest over every face that holds them.
    let key = |face: usize, i: usize, j: usize| -> I64Vec3 {
        detail::key(face, count as i64, (i as i64, j as i64)).expect("a point of the face")
    };
    let edge_points = |face: usize| {
        (0..side)
            .flat_map(move |j| (0..side).map(move |i| (face, i, j)))
            .filter(|&(_, i, j)| i == 0 || j == 0 || i == side - 1 || j == side - 1)
    };
    let mut shared = std::collections::HashMap::<I64Vec3, f64>::new();
    for (face, i, j) in (0..FACES).flat_map(edge_points) {
        let v = out[(face * side + j) * side + i];
        let e = shared.entry(key(face, i, j)).or_insert(v);
        *e = e.max(v);
    }
    for (face, i, j) in (0..FACES).flat_map(edge_points) {
        out[(face * side + j) * side + i] = shared[&key(face, i, j)];
    }
    out
}
