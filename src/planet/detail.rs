//! Base heights on demand (Sections 3.6 and 4.2; the thesis's "generate additional detail on the fly", 4.2 and
//! 6.3): one diamond-square step turns a patch's heights into those of one of its children, so any level of
//! detail is reached from the precomputed coarse lattice one generation at a time. This is the CPU reference;
//! `refine::HeightRefiner` runs the same step on the GPU and must equal it bit for bit (docs/planet.md).
//!
//! Every patch stores its `n x n` lattice points plus a border of [`BORDER`] points on each side, which is what
//! one step needs from the parent: the square step of a child's border point reads diamond centres one point
//! further out, and those read parent points one more point out. A lattice point's value depends only on its
//! integer position on the cube (its key), its level and the seed:
//! - its random displacement is [`lattice_hash`] of the seed, the level at which it is created and its key at
//!   that level, scaled by `detail-amplitude / 2^level` (halving per level, so detail continues at every depth);
//! - its average sums its four neighbours in ascending order of value, so the order in which a patch meets them
//!   does not matter.
//!
//! Points beyond a face edge are the adjacent face's, reached by folding the face's plane about the edge (one
//! step outwards = one step against this face's normal). Beyond two edges at once (the corner quadrants of a
//! patch at a cube corner) the unfolded plane has no points: three faces meet there, not four. A square-step
//! neighbour that falls there is rotated about the cube corner into the strip of the face it really lies on
//! ([`unfold_neighbour`]); the corner quadrants' own texels hold the corner point's height and are never read as
//! lattice points.

use glam::I64Vec3;

use super::cube::{PatchId, FACE_AXES};

/// Lattice points stored beyond each patch edge: enough for one child step (docs/planet.md).
pub const BORDER: i64 = 2;

/// A 32-bit mix with good avalanche (Wellons' "lowbias32"); shared bit for bit with glsl/heights_refine.comp.
pub fn mix32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// The hash of a lattice point: seed, the level at which the point is created, and its cube key at that level.
/// 32-bit throughout so that the GPU computes the same bits without 64-bit integers.
pub fn lattice_hash(seed: u32, level: u32, key: [u32; 3]) -> u32 {
    [level, key[0], key[1], key[2]]
        .iter()
        .fold(mix32(seed ^ 0x9e37_79b9), |h, &k| {
            mix32(h ^ k.wrapping_add(0x9e37_79b9))
        })
}

/// The diamond-square rule at every level: seed, the displacement amplitude of level 0, and how the displacement
/// follows the ground's slope.
#[derive(Clone, Copy, Debug)]
pub struct DetailRule {
    /// The planet's seed, from which every displacement hashes.
    pub seed: u32,
    /// `detail-amplitude`: the displacement of points created at level 0; level L gets `2^-L` of it.
    pub amplitude: f32,
    /// `flat-detail`: the share of the displacement a point gets where its four neighbours lie level; 1 (the
    /// thesis, 3.6) gives every point all of it.
    pub flat_share: f32,
    /// How fast the share grows with the neighbours' spread ([`Self::spread_gain`]): set with the other two by
    /// [`Self::new`], never apart from them.
    spread_gain: f32,
}

/// The spread of a point's four neighbours (highest less lowest), in amplitudes of its level, from which it gets
/// the whole displacement. Slopes and amplitudes both halve per level, so this is a slope: on the default planet
/// (base cells 12.6 units, amplitude 2) about 0.08, a valley side; a floodplain falls 0.003.
pub const STEEP_SPREAD: f32 = 4.0;

impl DetailRule {
    /// The rule of `seed` with displacement `amplitude` at level 0, `flat_share` of it on level ground.
    pub fn new(seed: u32, amplitude: f32, flat_share: f32) -> Self {
        let spread_gain = if amplitude > 0.0 {
            (1.0 - flat_share) / (STEEP_SPREAD * amplitude)
        } else {
            0.0
        };
        Self {
            seed,
            amplitude,
            flat_share,
            spread_gain,
        }
    }

    /// `(1 - flat_share) / (STEEP_SPREAD x amplitude)`, rounded once, so that the shader (which gets it as a push
    /// constant) multiplies by the same f32 as the CPU.
    pub fn spread_gain(&self) -> f32 {
        self.spread_gain
    }

    /// The displacement amplitude of points created at `level`: a multiplication by the exact f32 of 2^-level
    /// (built from its bits, as the shader does), so CPU and GPU agree.
    pub fn amplitude_at(&self, level: u32) -> f32 {
        self.amplitude * f32::from_bits((127 - level.min(126)) << 23)
    }

    /// The height of the point created at `level` with cube key `key` (at that level) between the four heights
    /// `around`: their average plus a random displacement, uniform in [-a, a) with 24 random bits (so the scaling
    /// to [-1, 1) is exact in f32), where a is the level's amplitude times the point's share of it: `flat_share`
    /// where the four lie level, growing with their spread to all of it from [`STEEP_SPREAD`] amplitudes (beyond
    /// the thesis: rough slopes and smooth floodplains, docs/planet.md, "Detail that follows the slope"). Every
    /// operation rounds once, in the order glsl/heights_refine.comp takes, so CPU and GPU agree bit for bit.
    pub fn displaced(&self, around: [f32; 4], level: u32, key: I64Vec3) -> f32 {
        let (average, spread) = sorted_average_and_spread(around);
        let h = lattice_hash(self.seed, level, [key.x as u32, key.y as u32, key.z as u32]);
        let unit = (h >> 8) as f32 * (1.0 / 16_777_216.0) * 2.0 - 1.0;
        // The spread in units of the level's amplitude, less the amplitude itself: times 2^level, exact.
        let levels = f32::from_bits((127 + level.min(127)) << 23);
        let share = (self.flat_share + (spread * levels) * self.spread_gain).min(1.0);
        average + unit * (self.amplitude_at(level) * share)
    }

    /// How far below the lowest (or above the highest) height of a patch at `level`, border included, any
    /// descendant's height can lie: a step widens the range by at most twice its amplitude (the diamond
    /// displacement, then the square displacement on top of it), and the amplitudes halve per level, so the sum
    /// over all finer levels is `2 x amplitude_at(level)`.
    pub fn remaining_range(&self, level: u32) -> f32 {
        2.0 * self.amplitude_at(level)
    }
}

/// The average of four neighbours in ascending order of value: the same bits whatever order they come in.
pub fn sorted_average(v: [f32; 4]) -> f32 {
    sorted_average_and_spread(v).0
}

/// [`sorted_average`] and the highest of the four less the lowest.
fn sorted_average_and_spread(mut v: [f32; 4]) -> (f32, f32) {
    v.sort_by(|a, b| a.total_cmp(b));
    ((v[0] + v[1] + v[2] + v[3]) * 0.25, v[3] - v[0])
}

fn axis(v: glam::DVec3) -> I64Vec3 {
    I64Vec3::new(v.x as i64, v.y as i64, v.z as i64)
}

/// How a point of a face's extended lattice (coordinates may leave [0, cells]) lies relative to the face.
fn outside(g: i64, cells: i64) -> i64 {
    if g < 0 {
        -1
    } else if g > cells {
        1
    } else {
        0
    }
}

/// Whether (gi, gj) is beyond two edges of the face at once: a corner quadrant, where no lattice point is.
pub fn in_corner_quadrant(cells: i64, (gi, gj): (i64, i64)) -> bool {
    outside(gi, cells) != 0 && outside(gj, cells) != 0
}

/// The cube key of point (gi, gj) of `face`'s lattice with `cells` cells per edge: a point of the face, or of the
/// strip beyond one edge, folded onto the adjacent face. `None` in a corner quadrant. Keys lie in [0, cells]^3 and
/// are the same for every face that holds the point.
pub fn key(face: usize, cells: i64, (gi, gj): (i64, i64)) -> Option<I64Vec3> {
    if in_corner_quadrant(cells, (gi, gj)) {
        return None;
    }
    let (n, a, b) = FACE_AXES[face];
    let (n, a, b) = (axis(n), axis(a), axis(b));
    let (ci, cj) = (gi.clamp(0, cells), gj.clamp(0, cells));
    let over = (gi - ci).abs() + (gj - cj).abs();
    let h = cells / 2;
    Some((n + I64Vec3::ONE) * h + a * (ci - h) + b * (cj - h) - n * over)
}

/// Where the stencil neighbour `q` of point `p` lies in `p`'s face's extended lattice: `q` itself, unless `q` is
/// in a corner quadrant. Then `p` is in the strip beyond one edge (on face G, say), `q` has crossed G's edge with
/// the third face H at that cube corner, and H's strip holds it: a quarter turn about the corner. In outward
/// distances (a, b) from the corner, `q` at (a, b) seen from the i-strip is at (-b, a) in the j-strip, and from
/// the j-strip at (b, -a) in the i-strip.
pub fn unfold_neighbour(cells: i64, p: (i64, i64), q: (i64, i64)) -> (i64, i64) {
    let (sx, sy) = (outside(q.0, cells), outside(q.1, cells));
    if sx == 0 || sy == 0 {
        return q;
    }
    let corner = (
        if sx < 0 { 0 } else { cells },
        if sy < 0 { 0 } else { cells },
    );
    let (a, b) = ((q.0 - corner.0) * sx, (q.1 - corner.1) * sy);
    let (a, b) = if outside(p.0, cells) != 0 {
        (-b, a)
    } else {
        (b, -a)
    };
    (corner.0 + a * sx, corner.1 + b * sy)
}

/// The nearest face corner of a point in a corner quadrant (whose height its texel repeats).
pub fn corner_of(cells: i64, (gi, gj): (i64, i64)) -> (i64, i64) {
    (gi.clamp(0, cells), gj.clamp(0, cells))
}

/// One patch's base heights with a border of [`BORDER`] points: `side x side` values, row-major, where point
/// (i, j) of the patch (i, j in [-BORDER, n - 1 + BORDER]) is at `(j + BORDER) * side + i + BORDER`.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchHeights {
    /// The patch.
    pub patch: PatchId,
    /// Vertices per patch edge.
    pub n: u32,
    /// The heights, as above.
    pub data: Vec<f32>,
}

impl PatchHeights {
    /// Values per row: the patch's vertices and the border on both sides.
    pub fn side(n: u32) -> usize {
        n as usize + 2 * BORDER as usize
    }

    /// Fills a patch from `value(gi, gj)` at face-lattice coordinates of the patch's level.
    pub fn from_fn(patch: PatchId, n: u32, mut value: impl FnMut((i64, i64)) -> f32) -> Self {
        let side = Self::side(n) as i64;
        let (x0, y0) = origin(patch, n);
        let mut data = Vec::with_capacity((side * side) as usize);
        for j in 0..side {
            for i in 0..side {
                data.push(value((x0 + i - BORDER, y0 + j - BORDER)));
            }
        }
        Self { patch, n, data }
    }

    /// The height of patch point (i, j), i, j in [-BORDER, n - 1 + BORDER].
    pub fn get(&self, i: i64, j: i64) -> f32 {
        let side = Self::side(self.n) as i64;
        self.data[((j + BORDER) * side + i + BORDER) as usize]
    }

    /// The height at face-lattice coordinates (of this patch's level) within the stored region.
    pub fn at(&self, (gi, gj): (i64, i64)) -> f32 {
        let (x0, y0) = origin(self.patch, self.n);
        self.get(gi - x0, gj - y0)
    }

    /// The patch's own `n x n` heights, without the border.
    pub fn interior(&self) -> Vec<f32> {
        let n = self.n as i64;
        (0..n)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .map(|(i, j)| self.get(i, j))
            .collect()
    }

    /// Lowest and highest stored height (border included).
    pub fn range(&self) -> (f32, f32) {
        self.data
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), &h| (lo.min(h), hi.max(h)))
    }
}

/// Face-lattice coordinates (at the patch's level) of a patch's vertex (0, 0).
pub fn origin(patch: PatchId, n: u32) -> (i64, i64) {
    let cells = (n - 1) as i64;
    (patch.x as i64 * cells, patch.y as i64 * cells)
}

/// Cells per face edge of the lattice of `level`.
pub fn lattice_cells(n: u32, level: u32) -> i64 {
    ((n - 1) as i64) << level
}

/// One diamond-square step (3.6): the heights of `child` from those of its parent `parent` (the CPU reference of
/// glsl/heights_refine.comp). Even points of the child's lattice are the parent's; cell centres (odd, odd) are
/// the diamond step; edge midpoints the square step, which reads centres one point beyond the child's border.
pub fn refine(parent: &PatchHeights, child: PatchId, rule: &DetailRule) -> PatchHeights {
    debug_assert_eq!(child.parent(), Some(parent.patch));
    let n = parent.n;
    let level = child.level as u32;
    let cells = lattice_cells(n, level);
    let face = child.face as usize;
    let (x0, y0) = origin(child, n);
    let parent_at = |(gi, gj): (i64, i64)| parent.at((gi.div_euclid(2), gj.div_euclid(2)));
    let amp_key = |g: (i64, i64)| key(face, cells, g);
    let diamond = |g: (i64, i64)| {
        let corners =
            [(-1, -1), (1, -1), (-1, 1), (1, 1)].map(|(di, dj)| parent_at((g.0 + di, g.1 + dj)));
        amp_key(g).map_or_else(
            || sorted_average(corners),
            |k| rule.displaced(corners, level, k),
        )
    };
    // Diamond centres from one point beyond the border on each side (odd coordinates only).
    let reach = BORDER + 1;
    let span = (n as i64 - 1 + 2 * reach) / 2 + 1;
    let mut centres = vec![0.0f32; (span * span) as usize];
    for cj in 0..span {
        for ci in 0..span {
            let g = (x0 - reach + 2 * ci, y0 - reach + 2 * cj);
            centres[(cj * span + ci) as usize] = diamond(g);
        }
    }
    let value = |g: (i64, i64)| -> f32 {
        match (g.0.rem_euclid(2), g.1.rem_euclid(2)) {
            (0, 0) => parent_at(g),
            (1, 1) => centres[(((g.1 - y0 + reach) / 2) * span + (g.0 - x0 + reach) / 2) as usize],
            _ => unreachable!("only lattice points of the parent or diamond centres are read"),
        }
    };
    PatchHeights::from_fn(child, n, |g| {
        if in_corner_quadrant(cells, g) {
            return parent_at(corner_of(cells, g));
        }
        match (g.0.rem_euclid(2), g.1.rem_euclid(2)) {
            (0, 0) | (1, 1) => value(g),
            _ => {
                let neighbours = [(-1, 0), (1, 0), (0, -1), (0, 1)]
                    .map(|(di, dj)| value(unfold_neighbour(cells, g, (g.0 + di, g.1 + dj))));
                amp_key(g).map_or_else(
                    || sorted_average(neighbours),
                    |k| rule.displaced(neighbours, level, k),
                )
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest displacement of the diamond centres of a level-4 patch refined from a tilted plane rising
    /// `slope` per parent lattice step (a plane's centres average to the plane exactly).
    fn largest_displacement(rule: &DetailRule, slope: f32) -> f32 {
        let child = PatchId {
            face: 0,
            level: 4,
            x: 5,
            y: 6,
        };
        let parent = child.parent().unwrap();
        let plane = |gi: f64| (slope as f64 * gi) as f32;
        let heights = PatchHeights::from_fn(parent, 33, |(gi, _)| plane(gi as f64));
        let refined = refine(&heights, child, rule);
        let (x0, y0) = origin(child, 33);
        (0..16)
            .flat_map(|cj| (0..16).map(move |ci| (x0 + 2 * ci + 1, y0 + 2 * cj + 1)))
            .map(|g| (refined.at(g) - plane(g.0 as f64 / 2.0)).abs())
            .fold(0.0, f32::max)
    }

    #[test]
    fn detail_follows_the_slope_and_the_thesis_keeps_it_everywhere() {
        let amplitude = DetailRule::new(7, 2.0, 1.0).amplitude_at(4);
        let thesis = DetailRule::new(7, 2.0, 1.0);
        let shaped = DetailRule::new(7, 2.0, 0.15);
        // The thesis: the whole amplitude on level ground.
        assert!(largest_displacement(&thesis, 0.0) > 0.9 * amplitude);
        // Level ground: the flat share of it.
        let flat = largest_displacement(&shaped, 0.0);
        assert!(
            flat <= 0.15 * amplitude && flat > 0.13 * amplitude,
            "{flat} of {amplitude}"
        );
        // A slope whose diamond corners spread STEEP_SPREAD amplitudes and more: all of it.
        let steep = largest_displacement(&shaped, STEEP_SPREAD * amplitude);
        assert!(steep > 0.9 * amplitude, "{steep} of {amplitude}");
    }
}
