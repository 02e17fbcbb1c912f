//! Fractal coasts (beyond the thesis, with the eroded relief; docs/planet.md, "Fractal coasts"): the continents'
//! coast is moved in and out by fractal noise measured in distance from it, so coasts gain bays, peninsulas and
//! islands at every scale instead of the Voronoi cells' straight edges, while continents' cores stay whole.
//!
//! The noise sums value-noise octaves from a few hundred kilometres on Earth down to the base lattice's own
//! spacing, each twice as fine and `PERSISTENCE` as strong (a Hurst exponent H of 0.6): the level set of such a
//! field has a box-counting dimension near 2 - H (Mandelbrot 1975; Voss 1985), and real coasts measure 1.15-1.4.

use rayon::prelude::*;

use super::{heights::FaceLattice, noise, relief::CoastDistances};
use crate::{drainage::grid::SphereGrid, rng};

const STREAM_COAST: u64 = 0x434f_4153;
/// Largest displacement of the coast by the coarsest octave (radians; about 190 km on Earth).
const AMPLITUDE: f64 = 0.045;
/// Frequency of the coarsest octave, per radian.
const FREQUENCY: f64 = 8.0;
/// Amplitude kept per octave: 2^-0.6.
const PERSISTENCE: f64 = 0.66;

/// The land of `lattice`'s points (`land`, in the order of `points`) with its coasts roughened.
pub fn roughen(
    grid: &SphereGrid,
    lattice: &FaceLattice,
    points: &[(usize, u32, u32)],
    land: &[bool],
    seed: u64,
) -> Vec<bool> {
    let mut node_land = vec![false; grid.len()];
    for (k, &(f, i, j)) in points.iter().enumerate() {
        node_land[grid.node(lattice, f, i, j) as usize] = land[k];
    }
    // Far from the coast nothing can change: the distances are needed only near it.
    let reach = 3.0 * AMPLITUDE;
    let CoastDistances { to_sea, to_land } = CoastDistances::within(grid, &node_land, reach);
    // Octaves down to the lattice's own spacing (cells about 1.3 nodes wide), so the coast moves node by node and
    // no stretch of it follows a lattice row or diagonal (which diamond-square draws as a straight line); octaves
    // down to two cells left runs of up to 1.02 % of the circumference (docs/planet.md, "Fractal coasts").
    let finest = grid.cells as f64 / std::f64::consts::FRAC_PI_2;
    points
        .par_iter()
        .map(|&(f, i, j)| {
            let node = grid.node(lattice, f, i, j) as usize;
            let signed = match node_land[node] {
                true => to_sea[node],
                false => -to_land[node],
            };
            if signed.abs() > reach {
                return signed > 0.0;
            }
            let d = grid.directions[node];
            let (mut sum, mut amplitude, mut frequency, mut octave) =
                (0.0, AMPLITUDE, FREQUENCY, 0);
            while frequency <= finest {
                sum += amplitude
                    * noise::value(rng::hash(seed, &[STREAM_COAST, octave]), d * frequency);
                amplitude *= PERSISTENCE;
                frequency *= 2.0;
                octave += 1;
            }
            signed + sum > 0.0
        })
        .collect()
}
