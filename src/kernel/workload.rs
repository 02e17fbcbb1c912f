//! Synthetic kernel workloads: patches crossed by random cubic rivers, sampled as Section 6.4 prescribes (at most
//! a sixth of the width apart). For kernel tests and the kernel benchmark until the planet's own rivers feed
//! them; every value derives from the seed.

use super::{KernelParams, RiverSample};
use crate::rng::Rng;

/// Samples along a cubic Hermite curve from `p0` to `p1` with tangents `d0`, `d1`, heights and widths varying
/// linearly, spaced by at most `width / spacing_divisor` along the curve.
pub fn sample_hermite(
    p0: [f32; 2],
    d0: [f32; 2],
    p1: [f32; 2],
    d1: [f32; 2],
    heights: (f32, f32),
    widths: (f32, f32),
    spacing_divisor: f32,
) -> Vec<RiverSample> {
    let eval = |t: f32| -> ([f32; 2], [f32; 2]) {
        let (t2, t3) = (t * t, t * t * t);
        let h = [
            2.0 * t3 - 3.0 * t2 + 1.0,
            t3 - 2.0 * t2 + t,
            -2.0 * t3 + 3.0 * t2,
            t3 - t2,
        ];
        let dh = [
            6.0 * t2 - 6.0 * t,
            3.0 * t2 - 4.0 * t + 1.0,
            -6.0 * t2 + 6.0 * t,
            3.0 * t2 - 2.0 * t,
        ];
        let f = |c: [f32; 4], k: usize| c[0] * p0[k] + c[1] * d0[k] + c[2] * p1[k] + c[3] * d1[k];
        ([f(h, 0), f(h, 1)], [f(dh, 0), f(dh, 1)])
    };
    let mut out = Vec::new();
    let mut t = 0.0f32;
    while t <= 1.0 {
        let (p, d) = eval(t);
        let width = widths.0 + (widths.1 - widths.0) * t;
        out.push(RiverSample::new(
            p,
            d,
            heights.0 + (heights.1 - heights.0) * t,
            width,
        ));
        let speed = (d[0] * d[0] + d[1] * d[1]).sqrt().max(1e-6);
        t += (width / spacing_divisor) / speed;
    }
    out
}

/// `count` patches of `grid_size` vertices with spacing `spacing`, each crossed by 1-3 random rivers (numbered
/// from 1) whose widths stay below the influence distance.
pub fn random_patches(
    seed: u64,
    count: usize,
    grid_size: u32,
    spacing: f32,
    params: &KernelParams,
) -> Vec<(f32, Vec<RiverSample>)> {
    let extent = (grid_size - 1) as f32 * spacing;
    (0..count)
        .map(|k| {
            let mut rng = Rng::new(seed, &[0x6b65_726e, k as u64]);
            let rivers = 1 + rng.below(3) as usize;
            let mut samples = Vec::new();
            for river in 0..rivers {
                let point =
                    |rng: &mut Rng| [rng.range(-0.2, 1.2) * extent, rng.range(-0.2, 1.2) * extent];
                let p0 = point(&mut rng);
                let p1 = point(&mut rng);
                let tangent =
                    |rng: &mut Rng| [rng.range(-1.0, 1.0) * extent, rng.range(-1.0, 1.0) * extent];
                let d0 = tangent(&mut rng);
                let d1 = tangent(&mut rng);
                let w0 = rng.range(0.2, 0.6) * params.influence_distance;
                let w1 = w0 * rng.range(1.0, 1.5);
                let h0 = rng.range(1.0, 10.0);
                samples.extend(
                    sample_hermite(p0, d0, p1, d1, (h0, h0 * 0.5), (w0, w1), 6.0)
                        .into_iter()
                        .map(|s| s.on_river(river as u64 + 1)),
                );
            }
            (spacing, samples)
        })
        .collect()
}
