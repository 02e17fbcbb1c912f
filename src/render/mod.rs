//! Rendering (Chapter 8): the patch mesh, the terrain and water pipelines, the frame loop, offscreen targets and
//! the viewer.

pub mod frame;
pub mod ground;
pub mod mesh;
pub mod overlay;
pub mod presets;
pub mod target;
pub mod viewer;
pub mod viewer_camera;
pub mod viewer_paths;

pub use frame::{DrawnVertex, FrameStats, GpuTimes, Renderer, VertexCapture, ViewMode, WaterMode};
