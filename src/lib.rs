//! riverplanet: a Vulkan planet renderer that generates river networks on procedural planets in real time,
//! after Kurz, *Parallel River Networks* (TU Graz 2020).
//!
//! Layers, dependencies pointing down: `kernel` (the river-height kernel: CPU reference and GPU dispatch),
//! `config` (the XML of Table 6.1 / Appendix A), `gpu` (the only module that imports ash).

pub mod bench;
pub mod config;
pub mod export;
pub mod gpu;
pub mod kernel;
pub mod planet;
pub mod river;
pub mod rng;
pub mod runtime;

/// SPIR-V of every shader in `glsl/`, compiled by build.rs.
pub mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
