//! Frames in flight: a ring of frame contexts, each with its own command pool and buffer, transient descriptor
//! pool and timestamp query pool, reused once that frame's timeline value has passed (as Granite's and wgpu-hal's
//! per-frame contexts are). The CPU records frame N+1 while the GPU runs frame N; it waits only when it comes
//! round to a context whose frame has not finished, so at most `FRAMES_IN_FLIGHT` frames are queued. What a frame
//! leaves to read back (timestamps, and the caller's payload) is handed back when its context comes round again,
//! one or two frames later, or at `drain`.

use ash::vk;

use super::{
    retire::{RetireOnDrop, Retired},
    submit::{allocate_command_buffer, transient_command_pool, transient_descriptor_pool},
    Context, GpuError, Profiler, Recorder, ScopeTiming, SubmissionId, VkResultExt,
};

/// Frames the CPU may be ahead of the GPU by default: two, so recording overlaps execution without adding a further
/// frame of latency.
pub const FRAMES_IN_FLIGHT: usize = 2;

/// The most frame contexts a ring may have (the swapchain keeps one acquire semaphore more than this).
pub const MAX_FRAMES_IN_FLIGHT: usize = 3;

/// What a finished frame left behind: its GPU timings and the caller's payload.
pub struct Finished<T> {
    /// The frame's submission.
    pub submission: SubmissionId,
    /// Its profiler scopes' GPU times.
    pub timings: Vec<ScopeTiming>,
    /// What the caller handed in with the frame.
    pub payload: T,
}

struct FrameContext<T> {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    descriptor_pool: vk::DescriptorPool,
    profiler: Profiler,
    in_flight: Option<(SubmissionId, T)>,
    _retire: RetireOnDrop,
}

/// The ring of frame contexts; `T` is what the caller reads back once a frame has finished.
pub struct FrameRing<T> {
    frames: Vec<FrameContext<T>>,
    /// The context being recorded, or the next one to record.
    current: usize,
}

impl<T> FrameRing<T> {
    /// A ring of `count` frame contexts (1 to `MAX_FRAMES_IN_FLIGHT`; 1: every frame waits for the one before,
    /// as the thesis's renderer did), each holding up to `max_scopes` timestamp scopes.
    pub fn new(ctx: &Context, count: usize, max_scopes: u32, name: &str) -> Result<Self, GpuError> {
        if !(1..=MAX_FRAMES_IN_FLIGHT).contains(&count) {
            return Err(GpuError::Invalid(format!(
                "frames in flight {count} must be in [1, {MAX_FRAMES_IN_FLIGHT}]"
            )));
        }
        let frames = (0..count)
            .map(|i| {
                let pool = transient_command_pool(ctx)?;
                let mut retire = ctx.retire_on_drop(vec![Retired::Pool(pool)]);
                let cmd = allocate_command_buffer(ctx, pool)?;
                ctx.set_name(pool, &format!("{name} {i} commands"));
                let descriptor_pool = transient_descriptor_pool(ctx)?;
                retire.push(Retired::DescriptorPool(descriptor_pool));
                let profiler = Profiler::new(ctx, max_scopes, &format!("{name} {i} timestamps"))?;
                Ok(FrameContext {
                    pool,
                    cmd,
                    descriptor_pool,
                    profiler,
                    in_flight: None,
                    _retire: retire,
                })
            })
            .collect::<Result<_, GpuError>>()?;
        Ok(Self { frames, current: 0 })
    }

    /// Starts recording the next frame named `name`. Waits only if that context's previous frame is still running
    /// on the GPU, and returns what it left behind.
    #[allow(clippy::type_complexity)]
    pub fn begin<'a>(
        &mut self,
        ctx: &'a Context,
        name: &str,
    ) -> Result<(Recorder<'a>, Option<Finished<T>>), GpuError> {
        let finished = self.retire(ctx, self.current)?;
        ctx.collect_garbage();
        let frame = &mut self.frames[self.current];
        // SAFETY: the frame's submission has completed, so nothing uses its pools or queries.
        unsafe {
            ctx.device
                .reset_command_pool(frame.pool, vk::CommandPoolResetFlags::empty())
                .vk("vkResetCommandPool")?;
            ctx.device
                .reset_descriptor_pool(frame.descriptor_pool, vk::DescriptorPoolResetFlags::empty())
                .vk("vkResetDescriptorPool")?;
        }
        frame.profiler.reset(ctx);
        let rec = Recorder::begin_pooled(ctx, name, frame.pool, frame.cmd, frame.descriptor_pool)?;
        Ok((rec, finished))
    }

    /// The timestamp scopes of the frame being recorded.
    pub fn profiler(&mut self) -> &mut Profiler {
        &mut self.frames[self.current].profiler
    }

    /// Submits the frame recorded in `rec` (from `begin`) with its payload, and moves to the next context.
    pub fn submit(
        &mut self,
        rec: Recorder,
        waits: &[(vk::Semaphore, super::Access)],
        signals: &[vk::Semaphore],
        payload: T,
    ) -> Result<SubmissionId, GpuError> {
        let id = rec.submit_with(waits, signals)?;
        self.frames[self.current].in_flight = Some((id, payload));
        self.current = (self.current + 1) % self.frames.len();
        Ok(id)
    }

    /// How many frame contexts the ring has.
    pub fn contexts(&self) -> usize {
        self.frames.len()
    }

    /// Frames submitted whose completion has not been observed yet.
    pub fn in_flight(&self, ctx: &Context) -> Result<usize, GpuError> {
        let completed = ctx.timeline.completed(&ctx.device)?;
        Ok(self
            .frames
            .iter()
            .filter(|f| f.in_flight.as_ref().is_some_and(|(id, _)| id.0 > completed))
            .count())
    }

    /// Waits for every frame in flight and returns what they left, oldest first.
    pub fn drain(&mut self, ctx: &Context) -> Result<Vec<Finished<T>>, GpuError> {
        let mut finished = Vec::new();
        for i in 0..self.frames.len() {
            let index = (self.current + i) % self.frames.len();
            finished.extend(self.retire(ctx, index)?);
        }
        Ok(finished)
    }

    /// Waits for the frame of context `index` if it has one, and reads back its timings.
    fn retire(&mut self, ctx: &Context, index: usize) -> Result<Option<Finished<T>>, GpuError> {
        let frame = &mut self.frames[index];
        let Some((submission, payload)) = frame.in_flight.take() else {
            return Ok(None);
        };
        ctx.wait(submission)?;
        let timings = frame.profiler.read(ctx)?;
        Ok(Some(Finished {
            submission,
            timings,
            payload,
        }))
    }
}
