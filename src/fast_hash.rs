//! A fast hasher for the program's own integer keys (grid cells, patches): the Fx hash's rotate, xor and multiply
//! per word. The default SipHash resists keys an attacker chooses, which these never are, and costs several times
//! more: it was a third of a stream level's point queries (drainage/streams.rs) and a seventh of the culling and
//! level of detail in the thesis's stress flight (docs/rendering.md).

use std::{
    collections::HashMap,
    hash::{BuildHasherDefault, Hasher},
};

/// A map whose keys are hashed by [`FastHasher`].
pub type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<FastHasher>>;

/// The Fx hash: each word rotated into the state and multiplied.
#[derive(Clone, Copy, Debug, Default)]
pub struct FastHasher(u64);

impl Hasher for FastHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u32(b as u32);
        }
    }

    fn write_u8(&mut self, n: u8) {
        self.write_u32(n as u32);
    }

    fn write_i32(&mut self, n: i32) {
        self.write_u32(n as u32);
    }

    fn write_u32(&mut self, n: u32) {
        self.0 = (self.0.rotate_left(5) ^ n as u64).wrapping_mul(0x517c_c1b7_2722_0a95);
    }

    fn finish(&self) -> u64 {
        self.0
    }
}
