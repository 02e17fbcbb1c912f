//! Frames in flight (beyond the thesis, docs/rendering.md): what a submitted frame leaves to read back, and how the
//! renderer takes it in when the GPU has finished the frame (its context comes round again, or `finish`).

use std::collections::BTreeMap;

use glam::DVec3;

use super::{draw::Drawn, FrameStats, Renderer};
use crate::gpu::{
    frames::{Finished, FrameRing},
    GpuError,
};

/// Timestamp scopes per frame: heights, kernel, vertices, sky dome, terrain, water, sky, with room to spare.
pub(super) const TIMESTAMP_SCOPES: u32 = 8;

/// What a frame in flight leaves to read back once the GPU has finished it.
pub(super) struct InFlight {
    pub(super) frame: u64,
    pub(super) new_patches: usize,
    pub(super) ranges: Option<crate::refine::RefinedRanges>,
    pub(super) drawn: Drawn,
    pub(super) camera: DVec3,
}

/// The GPU time per pass of one finished frame.
#[derive(Clone, Debug)]
pub struct GpuTimes {
    /// The frame's number.
    pub frame: u64,
    /// Milliseconds per pass.
    pub ms: BTreeMap<String, f64>,
    /// Fragment shader invocations per pass, where the device counts them (empty where not).
    pub fragments: BTreeMap<String, u64>,
}

impl Renderer<'_> {
    /// Sets how many frames may be in flight (1 to 3; 1 waits for every frame before the next, as the thesis's
    /// renderer did). Waits for the frames in flight first.
    pub fn set_frames_in_flight(&mut self, count: usize) -> Result<(), GpuError> {
        self.finish()?;
        let ring = FrameRing::new(self.ctx, count, TIMESTAMP_SCOPES, "frame")?;
        self.frames = ring;
        Ok(())
    }

    /// How many frames may be in flight.
    pub fn frames_in_flight(&self) -> usize {
        self.frames.contexts()
    }

    /// Waits for every frame in flight and collects what they left: afterwards `last_capture`, the height ranges
    /// and `take_gpu_times` hold everything rendered so far.
    pub fn finish(&mut self) -> Result<(), GpuError> {
        let finished = self.frames.drain(self.ctx)?;
        self.collect(finished)
    }

    /// The GPU times of the frames finished since the last call, oldest first.
    pub fn take_gpu_times(&mut self) -> Vec<GpuTimes> {
        self.gpu_times.drain(..).collect()
    }

    /// Puts the newest finished frame's GPU times into `stats`.
    pub(super) fn report_latest_gpu_times(&self, stats: &mut FrameStats) {
        if let Some(latest) = &self.latest_gpu_times {
            stats.gpu_ms = latest.ms.clone();
            stats.gpu_fragments = latest.fragments.clone();
            stats.gpu_frame = latest.frame;
        }
    }

    /// Takes in what finished frames left: refined patches' height ranges (for culling), the vertex capture, and
    /// GPU times (which also steer the generation budget).
    pub(super) fn collect(&mut self, finished: Vec<Finished<InFlight>>) -> Result<(), GpuError> {
        let n = self.config.rendering.vertices;
        for Finished {
            timings, payload, ..
        } in finished
        {
            if let Some(ranges) = payload.ranges {
                for (patch, range) in ranges.read()? {
                    if let Some(data) = self.cache.get_mut(&patch) {
                        data.height_range = range;
                    }
                }
            }
            if let Some(capture) = payload.drawn.read_capture(payload.camera, n) {
                self.last_capture = Some(capture);
            }
            let mut ms = BTreeMap::new();
            let mut fragments = BTreeMap::new();
            for scope in timings {
                if let Some(count) = scope.fragments {
                    *fragments.entry(scope.name.clone()).or_default() += count;
                }
                *ms.entry(scope.name).or_default() += scope.ms;
            }
            self.measure_generation(payload.new_patches, &ms);
            self.synchronized_frame = self.synchronized_frame.max(payload.frame);
            let times = GpuTimes {
                frame: payload.frame,
                ms,
                fragments,
            };
            self.latest_gpu_times = Some(times.clone());
            // A bounded backlog for callers that never take them (the viewer reads FrameStats instead).
            if self.gpu_times.len() >= 1024 {
                self.gpu_times.pop_front();
            }
            self.gpu_times.push_back(times);
        }
        Ok(())
    }
}
