//! Height data (Sections 3.6 and 4.2): one lattice per face at the finest level of detail, holding every level at
//! once (level L is every 2^(max - L)-th point, because diamond-square never changes a point once created).
//!
//! Seams: every lattice point is identified by its integer position on the cube, shared by the faces that meet
//! there. Its random displacement is a hash of that position, and its average sums its four neighbours in
//! ascending order of value, so each face computes bit-identical heights on shared edges and corners. The square
//! step on a face border reads its missing neighbour from the adjacent face (3.6).

use glam::{DVec3, I64Vec3};
use rayon::prelude::*;

use super::cube::{FACES, FACE_AXES};
use crate::rng;

const STREAM_DIAMOND_SQUARE: u64 = 0xD5_0001;

/// Heights of the six faces at `cells` cells per face edge: `(cells + 1)^2` values per face, row-major (j rows of
/// i), with u = -1 + 2 i / cells and v = -1 + 2 j / cells.
#[derive(Clone)]
pub struct FaceLattice {
    pub cells: u32,
    pub data: Vec<f32>,
}

fn axis(v: DVec3) -> I64Vec3 {
    I64Vec3::new(v.x as i64, v.y as i64, v.z as i64)
}

impl FaceLattice {
    pub fn new(cells: u32, fill: f32) -> Self {
        let side = cells as usize + 1;
        Self {
            cells,
            data: vec![fill; FACES * side * side],
        }
    }

    pub fn side(&self) -> usize {
        self.cells as usize + 1
    }

    pub fn index(&self, face: usize, i: u32, j: u32) -> usize {
        let side = self.side();
        face * side * side + j as usize * side + i as usize
    }

    pub fn get(&self, face: usize, i: u32, j: u32) -> f32 {
        self.data[self.index(face, i, j)]
    }

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

    /// Runs one diamond-square step, turning the level with stride `2 * half` into the level with stride `half`.
    /// `amplitude` scales the random displacement of the new points.
    pub fn diamond_square_step(&mut self, seed: u64, half: u32, amplitude: f32) {
        let stride = 2 * half;
        let c = self.cells;
        let side = self.side();
        let noise = |key: I64Vec3| -> f32 {
            let h = rng::hash(
                seed,
                &[
                    STREAM_DIAMOND_SQUARE,
                    key.x as u64,
                    key.y as u64,
                    key.z as u64,
                ],
            );
            ((h >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0) * amplitude
        };
        let average = |mut v: [f32; 4]| -> f32 {
            v.sort_by(|a, b| a.total_cmp(b));
            (v[0] + v[1] + v[2] + v[3]) * 0.25
        };

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
                            average(corners) + noise(lattice.key(face, x, y)),
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
                            average(values) + noise(key),
                        ))
                    })
                })
            })
            .collect();
        for (index, value) in edges {
            self.data[index] = value;
        }
    }

    /// The `(n + 2) x (n + 2)` heights of a patch with a one-vertex border taken from the neighbouring patches (on
    /// this face or, across a face border, on the adjacent face), so that normals at patch edges see the same
    /// neighbours on both sides. At a cube corner the missing diagonal neighbour repeats the nearest border value.
    pub fn patch_with_border(&self, face: usize, level: u32, x: u32, y: u32, n: u32) -> Vec<f32> {
        let span = self.cells >> level;
        let stride = (span / (n - 1)) as i64;
        let c = self.cells as i64;
        let normal = axis(FACE_AXES[face].0);
        let (x0, y0) = ((x * span) as i64, (y * span) as i64);
        let mut out = Vec::with_capacity(((n + 2) * (n + 2)) as usize);
        for j in -1..=n as i64 {
            for i in -1..=n as i64 {
                let (gi, gj) = (x0 + i * stride, y0 + j * stride);
                let inside = |g: i64| (0..=c).contains(&g);
                let h = if inside(gi) && inside(gj) {
                    self.get(face, gi as u32, gj as u32)
                } else {
                    // Step from the nearest border point into the adjacent face (against this face's normal).
                    let (ci, cj) = (gi.clamp(0, c), gj.clamp(0, c));
                    let over = (gi - ci).abs().max((gj - cj).abs());
                    if (gi - ci) != 0 && (gj - cj) != 0 {
                        self.get(face, ci as u32, cj as u32)
                    } else {
                        self.at_key(self.key(face, ci as u32, cj as u32) - normal * over)
                    }
                };
                out.push(h);
            }
        }
        out
    }

    /// The `n x n` heights of a patch at `level`, where a patch at level L spans `cells / 2^L` cells.
    pub fn patch(&self, face: usize, level: u32, x: u32, y: u32, n: u32) -> Vec<f32> {
        let span = self.cells >> level;
        let stride = span / (n - 1);
        let mut out = Vec::with_capacity((n * n) as usize);
        for j in 0..n {
            for i in 0..n {
                out.push(self.get(face, x * span + i * stride, y * span + j * stride));
            }
        }
        out
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
