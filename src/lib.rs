//! riverplanet: a Vulkan planet renderer that generates river networks on procedural planets in real time,
//! after Kurz, *Parallel River Networks* (TU Graz 2020).
//!
//! Layers, dependencies pointing down (docs/architecture.md):
//! - app: `world` (planet + rivers from a configuration), `bench`, `export`, and the `riverplanet` binary;
//! - `render`: the frame loop, terrain and water pipelines, offscreen targets, the viewer;
//! - `runtime`: level of detail, culling, camera, patch cache;
//! - `kernel`: the river-height kernel (CPU reference and GPU dispatch); `refine`: base heights on demand on the
//!   GPU (its CPU reference is `planet::detail`);
//! - model: `planet`, `river`, `config`, `rng`;
//! - `gpu`: the only module that imports ash; it knows nothing of planets.

// Every public item says what it is for (issue "Your own terrain, your own program": the planet as a library).
#![warn(missing_docs)]

pub mod bench;
pub mod config;
pub mod drainage;
pub mod export;
pub mod fast_hash;
pub mod geomorphology;
pub mod gpu;
pub mod interrupt;
pub mod kernel;
pub mod named;
pub mod planet;
pub mod refine;
pub mod render;
pub mod river;
pub mod rng;
pub mod runtime;
pub mod shader_types;
pub mod world;

/// SPIR-V of every shader in `glsl/`, compiled by build.rs.
pub mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
