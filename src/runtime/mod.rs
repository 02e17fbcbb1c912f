//! The run-time algorithm (Chapter 6): level of detail, culling, and the patch cache.

pub mod cache;
pub mod camera;
pub mod cull;
pub mod lod;
