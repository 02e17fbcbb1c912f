//! Seeded 3D value noise on the unit sphere, and its fractal sums: every value is a hash of the seed and an
//! integer lattice point, so the same direction gives the same value whatever is generated first.

use glam::DVec3;

use crate::rng;

/// Value noise in [-1, 1]: random values at the integer points of a 3D lattice, blended with smoothstep weights.
pub fn value(seed: u64, p: DVec3) -> f64 {
    let base = p.floor();
    let f = p - base;
    let s = f * f * (DVec3::splat(3.0) - 2.0 * f);
    let corner = |dx: i64, dy: i64, dz: i64| {
        let key = [
            (base.x as i64 + dx) as u64,
            (base.y as i64 + dy) as u64,
            (base.z as i64 + dz) as u64,
        ];
        (rng::hash(seed, &key) >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    };
    let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
    let x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), s.x);
    let x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), s.x);
    let x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), s.x);
    let x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), s.x);
    lerp(lerp(x00, x10, s.y), lerp(x01, x11, s.y), s.z)
}

/// Fractal sum of `octaves` octaves of [`value`] from `frequency`, each twice as fine and half as strong,
/// normalised to [-1, 1].
pub fn fbm(seed: u64, p: DVec3, frequency: f64, octaves: u32) -> f64 {
    let (mut sum, mut norm, mut amplitude, mut f) = (0.0, 0.0, 1.0, frequency);
    for octave in 0..octaves {
        sum += amplitude * value(rng::mix(seed ^ octave as u64), p * f);
        norm += amplitude;
        amplitude *= 0.5;
        f *= 2.0;
    }
    sum / norm
}

/// Ridged fractal noise in [0, 1]: 1 - |noise| makes sharp crests where the noise crosses zero (mountain ranges),
/// and each octave is weighted by the one before it, so detail gathers on the ridges (Musgrave's ridged
/// multifractal, simplified).
pub fn ridged(seed: u64, p: DVec3, frequency: f64, octaves: u32) -> f64 {
    let (mut sum, mut norm, mut amplitude, mut f, mut weight) = (0.0, 0.0, 1.0, frequency, 1.0);
    for octave in 0..octaves {
        let ridge = 1.0 - value(rng::mix(seed ^ (0x5249 + octave as u64)), p * f).abs();
        let ridge = ridge * ridge * weight;
        sum += amplitude * ridge;
        norm += amplitude;
        weight = ridge.clamp(0.0, 1.0);
        amplitude *= 0.5;
        f *= 2.0;
    }
    sum / norm
}
