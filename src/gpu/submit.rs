//! Command buffers and their submission (what they record is commands.rs's). Every submission signals the next
//! value of one timeline semaphore, which orders deferred deletion and lets callers wait for exactly the work they
//! need (never `vkDeviceWaitIdle` per upload).

use std::sync::{
    atomic::{AtomicU64, Ordering},
    Arc,
};

use ash::vk;

use super::{access::Access, retire::Retired, Buffer, Context, GpuError, VkResultExt};

/// The timeline semaphore that every submission signals.
pub(crate) struct Timeline {
    semaphore: vk::Semaphore,
    /// The last value submitted; the deletion queue tags what is retired with it.
    pub(crate) last: Arc<AtomicU64>,
}

impl Timeline {
    pub(crate) fn new(device: &ash::Device) -> Result<Self, GpuError> {
        let mut kind = vk::SemaphoreTypeCreateInfo::default()
            .semaphore_type(vk::SemaphoreType::TIMELINE)
            .initial_value(0);
        let info = vk::SemaphoreCreateInfo::default().push_next(&mut kind);
        // SAFETY: valid create info.
        let semaphore = unsafe { device.create_semaphore(&info, None) }.vk("vkCreateSemaphore")?;
        Ok(Self {
            semaphore,
            last: Arc::new(AtomicU64::new(0)),
        })
    }

    pub(crate) fn last_submitted(&self) -> u64 {
        self.last.load(Ordering::Acquire)
    }

    pub(crate) fn completed(&self, device: &ash::Device) -> Result<u64, GpuError> {
        // SAFETY: the semaphore belongs to this device.
        unsafe { device.get_semaphore_counter_value(self.semaphore) }
            .vk("vkGetSemaphoreCounterValue")
    }

    pub(crate) fn destroy(&self, device: &ash::Device) {
        // SAFETY: called at shutdown after the device is idle.
        unsafe { device.destroy_semaphore(self.semaphore, None) };
    }
}

/// Identifies one submission; wait for it with [`Context::wait`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct SubmissionId(pub u64);

/// A command buffer being recorded, with the staging buffers its uploads use.
pub struct Recorder<'a> {
    pub(super) ctx: &'a Context,
    pool: vk::CommandPool,
    pub(super) cmd: vk::CommandBuffer,
    /// Buffers this recording uses and frees once its submission completed (staging, per-dispatch inputs).
    pub(super) owned: Vec<Buffer>,
    /// Transient pool for per-dispatch descriptor sets.
    descriptor_pool: Option<vk::DescriptorPool>,
    /// Whether the pools belong to a frame context that resets and reuses them (`gpu::frames`); otherwise they
    /// belong to this recording and are retired with its submission.
    pooled: bool,
}

/// Per-dispatch descriptor sets one recording can allocate.
const TRANSIENT_SETS: u32 = 64;

/// A pool for the per-dispatch storage-buffer descriptor sets of one recording.
pub(crate) fn transient_descriptor_pool(ctx: &Context) -> Result<vk::DescriptorPool, GpuError> {
    let sizes = [vk::DescriptorPoolSize {
        ty: vk::DescriptorType::STORAGE_BUFFER,
        descriptor_count: TRANSIENT_SETS * 4,
    }];
    let info = vk::DescriptorPoolCreateInfo::default()
        .max_sets(TRANSIENT_SETS)
        .pool_sizes(&sizes);
    // SAFETY: valid create info; the owner retires or resets it after the submission.
    unsafe { ctx.device.create_descriptor_pool(&info, None) }.vk("vkCreateDescriptorPool")
}

/// A command pool for one-time command buffers on the queue's family.
pub(crate) fn transient_command_pool(ctx: &Context) -> Result<vk::CommandPool, GpuError> {
    let pool_info = vk::CommandPoolCreateInfo::default()
        .queue_family_index(ctx.queue_family)
        .flags(vk::CommandPoolCreateFlags::TRANSIENT);
    // SAFETY: valid create info; the owner retires or resets it after the submission.
    unsafe { ctx.device.create_command_pool(&pool_info, None) }.vk("vkCreateCommandPool")
}

/// One primary command buffer from `pool`.
pub(crate) fn allocate_command_buffer(
    ctx: &Context,
    pool: vk::CommandPool,
) -> Result<vk::CommandBuffer, GpuError> {
    let alloc = vk::CommandBufferAllocateInfo::default()
        .command_pool(pool)
        .level(vk::CommandBufferLevel::PRIMARY)
        .command_buffer_count(1);
    // SAFETY: valid allocate info.
    Ok(unsafe { ctx.device.allocate_command_buffers(&alloc) }.vk("vkAllocateCommandBuffers")?[0])
}

impl<'a> Recorder<'a> {
    /// Starts recording a one-time command buffer named `name` in a pool of its own.
    pub fn begin(ctx: &'a Context, name: &str) -> Result<Self, GpuError> {
        let pool = transient_command_pool(ctx)?;
        let cmd = match allocate_command_buffer(ctx, pool) {
            Ok(cmd) => cmd,
            Err(e) => {
                // SAFETY: the pool is unused.
                unsafe { ctx.device.destroy_command_pool(pool, None) };
                return Err(e);
            }
        };
        Self::start(ctx, name, pool, cmd, None, false)
    }

    /// Starts recording into a frame context's command buffer `cmd` of `pool` (both reset by the caller), with
    /// its descriptor pool; the pools are kept after the submission.
    pub(crate) fn begin_pooled(
        ctx: &'a Context,
        name: &str,
        pool: vk::CommandPool,
        cmd: vk::CommandBuffer,
        descriptor_pool: vk::DescriptorPool,
    ) -> Result<Self, GpuError> {
        Self::start(ctx, name, pool, cmd, Some(descriptor_pool), true)
    }

    fn start(
        ctx: &'a Context,
        name: &str,
        pool: vk::CommandPool,
        cmd: vk::CommandBuffer,
        descriptor_pool: Option<vk::DescriptorPool>,
        pooled: bool,
    ) -> Result<Self, GpuError> {
        ctx.set_name(cmd, name);
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: the command buffer is in the initial state (fresh or its pool reset).
        let begun =
            unsafe { ctx.device.begin_command_buffer(cmd, &begin) }.vk("vkBeginCommandBuffer");
        ctx.deletion.recording_opened();
        let recorder = Self {
            ctx,
            pool,
            cmd,
            owned: Vec::new(),
            descriptor_pool,
            pooled,
        };
        begun.map(|()| recorder)
    }

    /// The context it records for.
    pub fn ctx(&self) -> &'a Context {
        self.ctx
    }

    /// Keeps `buffer` alive until this recording's submission has completed, then frees it.
    pub fn free_after_completion(&mut self, buffer: Buffer) {
        self.owned.push(buffer);
    }

    /// A descriptor set of `layout` pointing at `buffers` (binding i = `buffers[i]`, whole range), valid for this
    /// recording only.
    pub fn buffer_set(
        &mut self,
        layout: &super::pipeline::BufferSetLayout,
        buffers: &[&Buffer],
    ) -> Result<vk::DescriptorSet, GpuError> {
        if buffers.len() as u32 != layout.count {
            return Err(GpuError::Invalid(format!(
                "descriptor set wants {} buffers, got {}",
                layout.count,
                buffers.len()
            )));
        }
        let device = &self.ctx.device;
        let pool = match self.descriptor_pool {
            Some(p) => p,
            None => *self
                .descriptor_pool
                .insert(transient_descriptor_pool(self.ctx)?),
        };
        let layouts = [layout.layout];
        let alloc = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(pool)
            .set_layouts(&layouts);
        // SAFETY: valid allocate info.
        let set =
            unsafe { device.allocate_descriptor_sets(&alloc) }.vk("vkAllocateDescriptorSets")?[0];
        let infos: Vec<[vk::DescriptorBufferInfo; 1]> = buffers
            .iter()
            .map(|b| {
                // The requested size, not the whole buffer: a reused buffer may be larger (retire.rs).
                [vk::DescriptorBufferInfo::default()
                    .buffer(b.raw)
                    .range(b.size.max(4))]
            })
            .collect();
        let writes: Vec<_> = infos
            .iter()
            .enumerate()
            .map(|(i, info)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(i as u32)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .buffer_info(info)
            })
            .collect();
        // SAFETY: the set is fresh and unused.
        unsafe { device.update_descriptor_sets(&writes, &[]) };
        Ok(set)
    }

    /// Ends recording and submits; `waits`/`signals` are binary semaphores (swapchain acquire/present).
    pub fn submit_with(
        self,
        waits: &[(vk::Semaphore, Access)],
        signals: &[vk::Semaphore],
    ) -> Result<SubmissionId, GpuError> {
        let ctx = self.ctx;
        // SAFETY: the command buffer is recording.
        unsafe { ctx.device.end_command_buffer(self.cmd) }.vk("vkEndCommandBuffer")?;
        let queue = ctx.queue();
        let value = ctx.timeline.last_submitted() + 1;
        let wait_infos: Vec<_> = waits
            .iter()
            .map(|&(s, access)| {
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(s)
                    .stage_mask(access.stages())
            })
            .collect();
        let mut signal_infos: Vec<_> = signals
            .iter()
            .map(|&s| {
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(s)
                    .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
            })
            .collect();
        signal_infos.push(
            vk::SemaphoreSubmitInfo::default()
                .semaphore(ctx.timeline.semaphore)
                .value(value)
                .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS),
        );
        let cmd_infos = [vk::CommandBufferSubmitInfo::default().command_buffer(self.cmd)];
        let submit = [vk::SubmitInfo2::default()
            .wait_semaphore_infos(&wait_infos)
            .command_buffer_infos(&cmd_infos)
            .signal_semaphore_infos(&signal_infos)];
        // SAFETY: queue access is serialised by the lock; all referenced objects live until `value` completes.
        unsafe { ctx.device.queue_submit2(*queue, &submit, vk::Fence::null()) }
            .vk("vkQueueSubmit2")?;
        ctx.timeline
            .last
            .store(value, std::sync::atomic::Ordering::Release);
        drop(queue);
        // Dropping the recorder closes it: its own pools, staging and per-dispatch buffers are retired after this
        // submission's value (or the last open recording's), so freed once it completes.
        Ok(SubmissionId(value))
    }

    /// Submits the recording, waiting on nothing and signalling only the timeline.
    pub fn submit(self) -> Result<SubmissionId, GpuError> {
        self.submit_with(&[], &[])
    }
}

impl Drop for Recorder<'_> {
    /// Closes the recording, submitted or not: what was retired while it was open, its pools when they are its
    /// own, and the buffers it kept wait for its submission (none, if it was abandoned).
    fn drop(&mut self) {
        self.ctx.deletion.recording_closed();
        if !self.pooled {
            self.ctx.deletion.retire(Retired::Pool(self.pool));
            if let Some(pool) = self.descriptor_pool {
                self.ctx.deletion.retire(Retired::DescriptorPool(pool));
            }
        }
    }
}

impl Context {
    /// Blocks until `id` has completed on the GPU, then frees what it guarded.
    pub fn wait(&self, id: SubmissionId) -> Result<(), GpuError> {
        let semaphores = [self.timeline.semaphore];
        let values = [id.0];
        let info = vk::SemaphoreWaitInfo::default()
            .semaphores(&semaphores)
            .values(&values);
        // SAFETY: the semaphore belongs to this device.
        unsafe { self.device.wait_semaphores(&info, u64::MAX) }.vk("vkWaitSemaphores")?;
        self.collect_garbage();
        Ok(())
    }

    /// Runs `record` in a fresh command buffer, submits it and waits. For tests, tools and set-up, not per frame.
    pub fn run_and_wait<T>(
        &self,
        name: &str,
        record: impl FnOnce(&mut Recorder) -> Result<T, GpuError>,
    ) -> Result<T, GpuError> {
        let mut rec = Recorder::begin(self, name)?;
        let out = record(&mut rec)?;
        let id = rec.submit()?;
        self.wait(id)?;
        Ok(out)
    }
}
