//! Whole-face height lattices (Sections 3.6 and 4.2): the precomputed coarse levels (continents, mountains and the
//! first diamond-square levels), and face images assembled at any level. A lattice of level L holds every coarser
//! level as a sub-sampling (level K is every 2^(L - K)-th point), because diamond-square never changes a point
//! once created. Finer levels are made per patch on demand (`detail`), by the same rule.
//!
//! Seams: every lattice point is identified by its integer position on the cube, shared by the faces that meet
//! there. Its random displacement is a hash of that position, and its average sums its four neighbours in
//! ascending order of value, so each face computes bit-identical heights on shared edges and corners. The square
//! step on a face border reads its missing neighbour from the adjacent face (3.6).

use glam::{DVec3, I64Vec3};
use rayon::prelude::*;

use super::{
    cube::{PatchId, FACES, FACE_AXES},
    detail::{self, DetailRule, PatchHeights},
};

/// Heights of the six faces at `cells` cells per face edge: `(cells + 1)^2` values per face, row-major (j rows of
/// i), with u = -1 + 2 i / cells and v = -1 + 2 j / cells.
#[derive(Clone)]
pub struct FaceLattice {
    /// Cells per face edge.
    pub cells: u32,
    /// The heights, face after face.
    pub data: Vec<f32>,
}

fn axis(v: DVec3) -> I64Vec3 {
    I64Vec3::new(v.x as i64, v.y as i64, v.z as i64)
}

impl FaceLattice {
    /// A lattice of `cells` cells per face edge, every height `fill`.
    pub fn new(cells: u32, fill: f32) -> Self {
        let side = cells as usize + 1;
        Self {
            cells,
            data: vec![fill; FACES * side * side],
        }
    }

    /// Points per face edge.
    pub fn side(&self) -> usize {
        self.cells as usize + 1
    }

    /// Where point (i, j) of `face` lies in `data`.
    pub fn index(&self, face: usize, i: u32, j: u32) -> usize {
        let side = self.side();
        face * side * side + j as usize * side + i as usize
    }

    /// The face and (i, j) of the point at `index` in `data` (the inverse of [`FaceLattice::index`]).
    pub fn point_of(&self, index: usize) -> (usize, u32, u32) {
        let side = self.side();
        let (face, rest) = (index / (side * side), index % (side * side));
        (face, (rest % side) as u32, (rest / side) as u32)
    }

    /// The height of point (i, j) of `face`.
    pub fn get(&self, face: usize, i: u32, j: u32) -> f32 {
        self.data[self.index(face, i, j)]
    }

    /// The heights' size in memory.
    pub fn bytes(&self) -> u64 {
        (self.data.len() * std::mem::size_of::<f32>()) as u64
    }

    /// The integer cube position of lattice point (i, j) of `face`, in [0, cells]^3: the same for every face that
    /// shares the point.
    pub fn key(&self, face: usize, i: u32, j: u32) -> I64Vec3 {
        let (n, a, b) = FACE_AXES[face];
        let h = self.cells as i64 / 2;
        (axis(n) + I64Vec3::ONE) * h + axis(a) * (i as i64 - h) + axis(b) * (j as i64 - h)
    }

    /// The unit-sphere direction of a key.
    pub fn direction(&self, key: I64Vec3) -> DVec3 {
        (key.as_dvec3() * (2.0 / self.cells as f64) - DVec3::ONE).normalize()
    }

    /// The lattice point at `key` on the lowest-index face that contains it.
    fn locate(&self, key: I64Vec3) -> Option<(usize, u32, u32)> {
        let c = self.cells as i64;
        let h = c / 2;
        for (face, (n, a, b)) in FACE_AXES.iter().enumerate() {
            let n = axis(*n);
            let on_plane = (key * n).element_sum() == if n.element_sum() > 0 { c } else { 0 };
            if !on_plane {
                continue;
            }
            let rel = key - (n + I64Vec3::ONE) * h;
            let i = (rel * axis(*a)).element_sum() + h;
            let j = (rel * axis(*b)).element_sum() + h;
            if (0..=c).contains(&i) && (0..=c).contains(&j) {
                return Some((face, i as u32, j as u32));
            }
        }
        None
    }

    /// The height at a cube key; keys just outside one face are taken from the face beyond (the caller folds them).
    fn at_key(&self, key: I64Vec3) -> f32 {
        self.locate(key).map_or(0.0, |(f, i, j)| self.get(f, i, j))
    }

    /// Runs one diamond-square step, turning the level with stride `2 * half` into the level with stride `half`,
    /// whose points are created at `level` (displacements by [`DetailRule`], as in the per-patch step).
    pub fn diamond_square_step(&mut self, rule: &DetailRule, half: u32, level: u32) {
        let stride = 2 * half;
        let c = self.cells;
        let side = self.side();
        // The key at the new points' level: this lattice's key divided by the stride of that level.
        let displaced =
            |around: [f32; 4], key: I64Vec3| rule.displaced(around, level, key / half as i64);

        // Diamond step: the centre of every cell of the coarser level.
        let centres: Vec<(usize, f32)> = (0..FACES)
            .into_par_iter()
            .flat_map_iter(|face| {
                let lattice = &*self;
                (0..c / stride).flat_map(move |cj| {
                    (0..c / stride).map(move |ci| {
                        let (i, j) = (ci * stride, cj * stride);
                        let corners = [
                            lattice.get(face, i, j),
                            lattice.get(face, i + stride, j),
                            lattice.get(face, i, j + stride),
                            lattice.get(face, i + stride, j + stride),
                        ];
                        let (x, y) = (i + half, j + half);
                        (
                            lattice.index(face, x, y),
                            displaced(corners, lattice.key(face, x, y)),
                        )
                    })
                })
            })
            .collect();
        for (index, value) in centres {
            self.data[index] = value;
        }

        // Square step: the midpoint of every edge, from its two ends and the two centres beside it. On a face
        // border one centre lies on the adjacent face: step from the border into that face (against this face's
        // normal).
        let edges: Vec<(usize, f32)> = (0..FACES)
            .into_par_iter()
            .flat_map_iter(|face| {
                let lattice = &*self;
                let normal = axis(FACE_AXES[face].0);
                (0..=c / half).flat_map(move |gj| {
                    (0..=c / half).filter_map(move |gi| {
                        let (x, y) = (gi * half, gj * half);
                        // Midpoints have exactly one odd coordinate in units of `half`.
                        if (gi + gj) % 2 == 0 {
                            return None;
                        }
                        let (ends, across) = if gi % 2 == 1 {
                            (
                                [(x - half, y), (x + half, y)],
                                [
                                    (x as i64, y as i64 - half as i64),
                                    (x as i64, (y + half) as i64),
                                ],
                            )
                        } else {
                            (
                                [(x, y - half), (x, y + half)],
                                [
                                    (x as i64 - half as i64, y as i64),
                                    ((x + half) as i64, y as i64),
                                ],
                            )
                        };
                        let key = lattice.key(face, x, y);
                        let centre = |(ci, cj): (i64, i64)| {
                            if (0..=c as i64).contains(&ci) && (0..=c as i64).contains(&cj) {
                                lattice.get(face, ci as u32, cj as u32)
                            } else {
                                lattice.at_key(key - normal * half as i64)
                            }
                        };
                        let values = [
                            lattice.get(face, ends[0].0, ends[0].1),
                            lattice.get(face, ends[1].0, ends[1].1),
                            centre(across[0]),
                            centre(across[1]),
                        ];
                        Some((
                            y as usize * side + x as usize + face * side * side,
                            displaced(values, key),
                        ))
                    })
                })
            })
            .collect();
        for (index, value) in edges {
            self.data[index] = value;
        }
    }

    /// The heights of `patch` (at a level no finer than this lattice's) with its border of
    /// [`detail::BORDER`] points: points beyond a face edge are read from the adjacent face, corner quadrants
    /// repeat the corner (as the per-patch step writes them).
    pub fn patch_heights(&self, patch: PatchId, n: u32) -> PatchHeights {
        let cells = detail::lattice_cells(n, patch.level as u32);
        let scale = self.cells as i64 / cells;
        let face = patch.face as usize;
        PatchHeights::from_fn(patch, n, |g| {
            let g = if detail::in_corner_quadrant(cells, g) {
                detail::corner_of(cells, g)
            } else {
                g
            };
            let key = detail::key(face, cells, g).expect("outside the corner quadrants");
            self.at_key(key * scale)
        })
    }

    /// The whole planet at `level` as one lattice per face, assembled from every patch of that level refined
    /// patch by patch from this lattice (of level `own_level`), as the renderer makes them; a sub-sampling for
    /// levels no finer than this one.
    pub fn refined_to(&self, own_level: u32, level: u32, rule: &DetailRule, n: u32) -> FaceLattice {
        let cells = (n - 1) << level;
        let mut out = FaceLattice::new(cells, 0.0);
        let fill = |out: &mut FaceLattice, p: &PatchHeights| {
            let (x0, y0) = detail::origin(p.patch, n);
            for j in 0..n as i64 {
                for i in 0..n as i64 {
                    let index = out.index(p.patch.face as usize, (x0 + i) as u32, (y0 + j) as u32);
                    out.data[index] = p.get(i, j);
                }
            }
        };
        let start = level.min(own_level);
        for face in 0..FACES {
            let count = 1u32 << start;
            let mut patches: Vec<PatchHeights> = (0..count * count)
                .map(|k| PatchId {
                    face: face as u8,
                    level: start as u8,
                    x: k % count,
                    y: k / count,
                })
                .map(|p| self.patch_heights(p, n))
                .collect();
            for _ in start..level {
                patches = patches
                    .par_iter()
                    .flat_map_iter(|parent| {
                        (0..4).map(move |q| detail::refine(parent, parent.patch.child(q), rule))
                    })
                    .collect();
            }
            for p in &patches {
                fill(&mut out, p);
            }
        }
        out
    }

    /// The height range of every patch of levels 0..=`top`, from the lattice of level `top`: level `top` with its
    /// border (what its descendants are refined from), coarser levels as the union of their children (which holds
    /// every vertex of theirs).
    pub fn patch_bounds_pyramid(&self, top: u32, n: u32) -> Vec<Vec<(f32, f32)>> {
        let count = 1u32 << top;
        let finest: Vec<(f32, f32)> = (0..FACES as u32 * count * count)
            .into_par_iter()
            .map(|k| {
                let patch = PatchId {
                    face: (k / (count * count)) as u8,
                    level: top as u8,
                    x: k % count,
                    y: (k / count) % count,
                };
                self.patch_heights(patch, n).range()
            })
            .collect();
        let mut levels = vec![finest];
        for level in (0..top).rev() {
            let count = 1usize << level;
            let finer = levels.last().expect("the finest level is there");
            let coarse: Vec<(f32, f32)> = (0..FACES * count * count)
                .map(|k| {
                    let (face, y, x) = (k / (count * count), (k / count) % count, k % count);
                    (0..4)
                        .map(|q| {
                            let (cx, cy) = (2 * x + (q & 1), 2 * y + (q >> 1));
                            finer[(face * 2 * count + cy) * 2 * count + cx]
                        })
                        .fold((f32::MAX, f32::MIN), |(lo, hi), (a, b)| {
                            (lo.min(a), hi.max(b))
                        })
                })
                .collect();
            levels.push(coarse);
        }
        levels.reverse();
        levels
    }

    /// Per level 1..=`top` (index level - 1; this lattice being level `top` with `n` vertices per patch edge), per
    /// patch of that level (face, then row-major): the largest vertical distance between a lattice point in the
    /// patch's closed area and the bilinear surface through its parent's vertices there, i.e. how far drawing the
    /// parent's quadrant instead of the patch can stand from this lattice (the screen-space rule's error,
    /// docs/rendering.md). A quadrant holds `(n - 1) / 2` of its parent's cells per edge.
    pub fn quadrant_deviations(&self, top: u32, n: u32) -> Vec<Vec<f32>> {
        (1..=top)
            .map(|level| {
                let count = 1u32 << level;
                // The parent's vertex spacing in lattice points, and the quadrant's width in lattice points.
                let stride = 1u32 << (top + 1 - level);
                let width = (n - 1) / 2 * stride;
                (0..FACES as u32 * count * count)
                    .into_par_iter()
                    .map(|k| {
                        let face = (k / (count * count)) as usize;
                        let (x, y) = (k % count, (k / count) % count);
                        let mut worst = 0.0f32;
                        for j in y * width..=(y + 1) * width {
                            for i in x * width..=(x + 1) * width {
                                let (ci, cj) = (
                                    (i / stride).min(self.cells / stride - 1),
                                    (j / stride).min(self.cells / stride - 1),
                                );
                                let (fx, fy) = (
                                    (i - ci * stride) as f32 / stride as f32,
                                    (j - cj * stride) as f32 / stride as f32,
                                );
                                let corner = |di: u32, dj: u32| {
                                    self.get(face, (ci + di) * stride, (cj + dj) * stride)
                                };
                                let bilinear = (corner(0, 0) * (1.0 - fx) + corner(1, 0) * fx)
                                    * (1.0 - fy)
                                    + (corner(0, 1) * (1.0 - fx) + corner(1, 1) * fx) * fy;
                                worst = worst.max((self.get(face, i, j) - bilinear).abs());
                            }
                        }
                        worst
                    })
                    .collect()
            })
            .collect()
    }
}

/// Area on the unit sphere represented by lattice point (i, j) of one face: the gnomonic Jacobian times the
/// trapezoid-rule cell area. Summed over all six faces this integrates the whole sphere (4 pi); a shared border
/// point gets its other part from the adjacent face.
pub fn area_weight(cells: u32, i: u32, j: u32) -> f64 {
    let step = 2.0 / cells as f64;
    let u = -1.0 + i as f64 * step;
    let v = -1.0 + j as f64 * step;
    let jacobian = 1.0 / (1.0 + u * u + v * v).powf(1.5);
    let edge_i = i == 0 || i == cells;
    let edge_j = j == 0 || j == cells;
    let trapezoid = (if edge_i { 0.5 } else { 1.0 }) * (if edge_j { 0.5 } else { 1.0 });
    jacobian * step * step * trapezoid
}
