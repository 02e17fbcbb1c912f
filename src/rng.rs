//! Seeded, order-independent randomness: every random value is a hash of the master seed and the *identity* of
//! what it belongs to (a face and cell, a river and segment and level), never of how many values were drawn
//! before. So the same seed gives the same planet whatever is generated first.

/// SplitMix64's finaliser: a bijective 64-bit mix with good avalanche.
pub fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Hashes a seed and a sequence of keys (e.g. `[STREAM, face, level, x, y]`) into one 64-bit value.
pub fn hash(seed: u64, keys: &[u64]) -> u64 {
    keys.iter()
        .fold(mix(seed ^ 0x9e37_79b9_7f4a_7c15), |h, &k| {
            mix(h ^ k.wrapping_add(0x9e37_79b9_7f4a_7c15))
        })
}

/// A small sequential generator for a local stream, itself seeded by [`hash`] of an identity.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// The stream belonging to `keys` under `seed`.
    pub fn new(seed: u64, keys: &[u64]) -> Self {
        Self {
            state: hash(seed, keys),
        }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix(self.state)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in [lo, hi) for 64-bit floats.
    pub fn range_f64(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }

    /// Uniform integer in [0, n).
    pub fn below(&mut self, n: u64) -> u64 {
        if n == 0 {
            0
        } else {
            self.next_u64() % n
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_depend_on_identity_not_order() {
        let a = Rng::new(7, &[1, 2, 3]).next_u64();
        let _ = Rng::new(7, &[9, 9]).next_u64();
        assert_eq!(a, Rng::new(7, &[1, 2, 3]).next_u64());
        assert_ne!(a, Rng::new(7, &[1, 2, 4]).next_u64());
        assert_ne!(a, Rng::new(8, &[1, 2, 3]).next_u64());
    }

    #[test]
    fn unit_is_in_range() {
        let mut r = Rng::new(1, &[]);
        for _ in 0..10_000 {
            let u = r.unit();
            assert!((0.0..1.0).contains(&u));
        }
    }
}
