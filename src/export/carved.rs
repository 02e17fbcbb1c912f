//! The planet's terrain at one level of detail with the rivers carved in, as the renderer draws it (beyond the
//! thesis, for exports): every patch of the level made as `runtime::surface` makes it, into one lattice per face. A vertex on a patch edge belongs to two patches (four at a corner, three at a cube corner), whose
//! kernels measure distances in their own face planes: within a face they agree to f32 rounding, across a face
//! edge they can differ by more than the basin depth where a river is near (on the default planet up to 0.15 at
//! 14 % of the face-edge points of level 2; the renderer's skirts cover the step). The export writes the mean of
//! every patch's value there, so that the faces meet without a step.

use std::collections::HashMap;

use glam::I64Vec3;
use rayon::prelude::*;

use crate::{
    config::Config,
    kernel::KernelParams,
    planet::{cube::PatchId, cube::FACES, detail, heights::FaceLattice, Planet},
    river::network::RiverNetwork,
    runtime::surface::{bilinear, carve_patch, CarvedPatch},
};

/// The finest level an export computes: level 7 holds 6 x 4097 x 4097 heights (403 MB of f32, about three times
/// that while it is made).
pub const MAX_EXPORT_LEVEL: u32 = 7;

/// Terrain heights (above the sphere of the planet's radius, with the river beds) of every vertex of `level`, one
/// lattice per face: point (i, j) of face f is the direction of cube point u = -1 + 2 i / cells, v = -1 + 2 j /
/// cells ([`FaceLattice`]). `carved` is called with the number of patches to carve as each one is done (from any
/// thread: progress).
pub fn carved_terrain(
    planet: &Planet,
    network: &RiverNetwork,
    config: &Config,
    level: u32,
    carved: &(dyn Fn(usize) + Sync),
) -> FaceLattice {
    let n = config.rendering.vertices;
    let params = KernelParams::from_config(config);
    let mut lattice = planet.face_lattice(level);
    let count = 1u32 << level;
    // Per lattice point on a patch edge, the sum and number of the values patches gave it.
    let mut shared: HashMap<I64Vec3, (f32, u32)> = HashMap::new();
    for face in 0..FACES {
        let patches: Vec<PatchId> = (0..count * count)
            .map(|k| PatchId {
                face: face as u8,
                level: level as u8,
                x: k % count,
                y: k / count,
            })
            .collect();
        let surfaces: Vec<CarvedPatch> = patches
            .par_iter()
            .map(|&patch| {
                let (x0, y0) = detail::origin(patch, n);
                let base = |i: u32, j: u32| lattice.get(face, x0 as u32 + i, y0 as u32 + j);
                let surface = carve_patch(patch, base, planet, network, n, &params);
                carved(FACES * (count * count) as usize);
                surface
            })
            .collect();
        for CarvedPatch { patch, terrain, .. } in surfaces {
            let (x0, y0) = detail::origin(patch, n);
            for (k, h) in terrain.into_iter().enumerate() {
                let (i, j) = (x0 as u32 + k as u32 % n, y0 as u32 + k as u32 / n);
                let on_edge = [i % (n - 1), j % (n - 1)].contains(&0);
                if on_edge {
                    let entry = shared.entry(lattice.key(face, i, j)).or_insert((0.0, 0));
                    *entry = (entry.0 + h, entry.1 + 1);
                } else {
                    let index = lattice.index(face, i, j);
                    lattice.data[index] = h;
                }
            }
        }
    }
    for face in 0..FACES {
        for j in 0..=lattice.cells {
            for i in 0..=lattice.cells {
                if let Some(&(sum, count)) = shared.get(&lattice.key(face, i, j)) {
                    let index = lattice.index(face, i, j);
                    lattice.data[index] = sum / count as f32;
                }
            }
        }
    }
    lattice
}

/// The height of `lattice` in the direction `d`, bilinear between the four lattice points around it.
pub fn height_towards(lattice: &FaceLattice, d: glam::DVec3) -> f32 {
    let (face, u, v) = crate::planet::cube::face_of(d);
    let cells = lattice.cells as f64;
    let grid = ((u + 1.0) * 0.5 * cells, (v + 1.0) * 0.5 * cells);
    bilinear(lattice.cells, grid, |i, j| lattice.get(face, i, j))
}
