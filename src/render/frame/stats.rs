//! What one frame did (FrameStats), as the viewer shows it and the benchmarks record it.

use std::collections::BTreeMap;

use serde::Serialize;

/// What one frame did, for the viewer, the benchmarks and the plots (Chapter 9).
#[derive(Clone, Debug, Default, Serialize)]
pub struct FrameStats {
    /// The frame's number, from 0.
    pub frame: u64,
    /// Patches selected by the level of detail (before culling).
    pub selected_patches: usize,
    /// Of those, the patches inside the view (drawn).
    pub visible_patches: usize,
    /// Patches whose data was made this frame.
    pub new_patches: usize,
    /// New patches influenced by rivers (computed by the kernel this frame).
    pub river_patches: usize,
    /// Of those, patches that took their even vertices from their parent (10.2).
    pub river_patches_from_parent: usize,
    /// Visible patches drawn with an ancestor's data because theirs has not arrived yet.
    pub fallback_patches: usize,
    /// Patches still waiting for data after this frame.
    pub pending_patches: usize,
    /// The finest level drawn with its own data.
    pub deepest_level: u32,
    /// Triangles the terrain pass draws (the patches' quadrants with their skirts; the water pass spawns its own).
    pub terrain_triangles: u64,
    /// River samples given to the kernel this frame (6.4).
    pub samples: usize,
    /// Patches whose textures are resident.
    pub resident_patches: usize,
    /// Patches evicted this frame (least recently used).
    pub evicted_patches: usize,
    /// Bytes of resident patch textures.
    pub patch_texture_bytes: u64,
    /// Array images the patch textures lie in, both kinds (each image holds many patches' layers).
    pub patch_texture_images: usize,
    /// Bytes of this frame's sample buffers.
    pub temporary_sample_bytes: u64,
    /// Bytes of the precomputed lattice.
    pub precomputed_height_bytes: u64,
    /// The three above together.
    pub memory_bytes: u64,
    /// CPU time per stage of this frame, milliseconds.
    pub cpu_ms: BTreeMap<String, f64>,
    /// GPU time per pass of frame `gpu_frame`: the latest that finished by the end of this call, one or two
    /// frames before this one (frames in flight); empty until the first has finished.
    pub gpu_ms: BTreeMap<String, f64>,
    /// Fragment shader invocations per pass of frame `gpu_frame`, where the device counts them (pipeline
    /// statistics queries; empty where not): per pixel of the target, how often a pass shades each.
    pub gpu_fragments: BTreeMap<String, u64>,
    /// The frame `gpu_ms` belongs to.
    pub gpu_frame: u64,
    /// Frames submitted and not yet finished on the GPU when this call returned (this one included).
    pub frames_in_flight: usize,
    /// The newest frame the CPU had waited for (or seen finished) before submitting this one: with two frames in
    /// flight, the frame two back, so the previous frame was still queued while this one was recorded.
    pub synchronized_frame: u64,
    /// Wall-clock time of the call that made the frame, milliseconds.
    pub frame_ms: f64,
}

impl FrameStats {
    /// Whether every visible patch was drawn with its own data and nothing is left to make.
    pub fn streamed(&self) -> bool {
        self.pending_patches == 0 && self.fallback_patches == 0 && self.new_patches == 0
    }
}
