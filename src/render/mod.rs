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

/// The colour behind the planet where no air is (the dark blue of space): the viewer's, the flights' and
/// `render`'s default clear colour.
pub const SPACE: [f32; 3] = [0.02, 0.03, 0.06];

/// [`SPACE`] as an opaque clear colour.
pub const SPACE_CLEAR: [f32; 4] = [SPACE[0], SPACE[1], SPACE[2], 1.0];
