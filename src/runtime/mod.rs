//! The run-time algorithm (Chapter 6): level of detail, culling, and the patch cache; and the drawn surface on
//! the CPU.

pub mod cache;
pub mod camera;
pub mod camera_path;
pub mod cull;
pub mod error_field;
pub mod lod;
pub mod surface;
