//! GPU timestamps: a query pool of named begin/end pairs, reset from the host, read after the submission's
//! completion, masked to `timestampValidBits` and scaled by `timestampPeriod`. Where the device has pipeline
//! statistics queries, each scope also counts its fragment shader invocations (how many times the pass shades a
//! pixel: its overdraw, with the helper invocations of partly covered quads that a device reports).
//! Each scope is also a debug label, so captures show the same names.

use ash::vk;

use super::{
    retire::{RetireOnDrop, Retired},
    Context, GpuError, Recorder, VkResultExt,
};

/// The GPU time of one named scope.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ScopeTiming {
    /// The scope's name (a pass, or a kernel stage).
    pub name: String,
    /// Between its begin and end timestamps, milliseconds.
    pub ms: f64,
    /// Its fragment shader invocations, where the device counts them.
    pub fragments: Option<u64>,
}

/// Timestamp queries around named scopes of a recording, read back once its submission has finished.
pub struct Profiler {
    pool: vk::QueryPool,
    /// One pipeline statistics query (fragment shader invocations) per scope, where the device has them.
    fragments: Option<vk::QueryPool>,
    capacity: u32,
    names: Vec<String>,
    period_ns: f64,
    valid_mask: u64,
    _retire: RetireOnDrop,
}

/// An open scope ([`Profiler::scope`] closes it).
#[must_use]
pub struct Scope(u32);

impl Profiler {
    /// A profiler that holds up to `max_scopes` scopes between resets.
    pub fn new(ctx: &Context, max_scopes: u32, name: &str) -> Result<Self, GpuError> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(max_scopes * 2);
        // SAFETY: valid create info; destroyed through the deletion queue.
        let pool = unsafe { ctx.device.create_query_pool(&info, None) }.vk("vkCreateQueryPool")?;
        ctx.set_name(pool, name);
        let mut retired = vec![Retired::QueryPool(pool)];
        let fragments = if ctx.pipeline_statistics {
            let info = vk::QueryPoolCreateInfo::default()
                .query_type(vk::QueryType::PIPELINE_STATISTICS)
                .pipeline_statistics(vk::QueryPipelineStatisticFlags::FRAGMENT_SHADER_INVOCATIONS)
                .query_count(max_scopes);
            // SAFETY: valid create info (the feature is enabled); destroyed through the deletion queue.
            let stats =
                unsafe { ctx.device.create_query_pool(&info, None) }.vk("vkCreateQueryPool")?;
            ctx.set_name(stats, &format!("{name} fragments"));
            retired.push(Retired::QueryPool(stats));
            Some(stats)
        } else {
            None
        };
        let bits = ctx.timestamp_valid_bits;
        let mut profiler = Self {
            pool,
            fragments,
            capacity: max_scopes,
            _retire: ctx.retire_on_drop(retired),
            names: Vec::new(),
            period_ns: ctx.properties.limits.timestamp_period as f64,
            valid_mask: if bits >= 64 {
                u64::MAX
            } else {
                (1u64 << bits) - 1
            },
        };
        profiler.reset(ctx);
        Ok(profiler)
    }

    /// Clears all scopes (host query reset). Only after the previous results were read or abandoned.
    pub fn reset(&mut self, ctx: &Context) {
        // SAFETY: hostQueryReset is a required feature; no pending submission uses these queries (caller's contract).
        unsafe { ctx.device.reset_query_pool(self.pool, 0, self.capacity * 2) };
        if let Some(fragments) = self.fragments {
            // SAFETY: as above.
            unsafe { ctx.device.reset_query_pool(fragments, 0, self.capacity) };
        }
        self.names.clear();
    }

    /// Records `body` as the timed scope `name`, inside a debug label of that name: what it records is one pass
    /// of the frame, timed and named without a begin and an end to pair by hand.
    pub fn scope<T>(
        &mut self,
        rec: &mut Recorder,
        name: &str,
        body: impl FnOnce(&mut Recorder) -> T,
    ) -> Result<T, GpuError> {
        let scope = self.begin(rec, name)?;
        let out = body(rec);
        self.end(rec, scope);
        Ok(out)
    }

    /// Writes the begin timestamp of scope `name` and opens a debug label.
    fn begin(&mut self, rec: &mut Recorder, name: &str) -> Result<Scope, GpuError> {
        let index = self.names.len() as u32;
        if index >= self.capacity {
            return Err(GpuError::Invalid(format!(
                "profiler full ({} scopes); cannot open '{name}'",
                self.capacity
            )));
        }
        self.names.push(name.to_string());
        let ctx = rec.ctx();
        ctx.begin_label(rec.cmd, name);
        // SAFETY: query index within the pool, reset since last use.
        unsafe {
            ctx.device.cmd_write_timestamp2(
                rec.cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                index * 2,
            );
            // Scopes do not nest, so no other statistics query is active; begun and ended in the same place
            // relative to a rendering (the scope's body begins and ends any rendering it records).
            if let Some(fragments) = self.fragments {
                ctx.device.cmd_begin_query(
                    rec.cmd,
                    fragments,
                    index,
                    vk::QueryControlFlags::empty(),
                );
            }
        };
        Ok(Scope(index))
    }

    /// Writes the end timestamp of `scope` and closes its label.
    fn end(&mut self, rec: &mut Recorder, scope: Scope) {
        let ctx = rec.ctx();
        // SAFETY: as in begin.
        unsafe {
            if let Some(fragments) = self.fragments {
                ctx.device.cmd_end_query(rec.cmd, fragments, scope.0);
            }
            ctx.device.cmd_write_timestamp2(
                rec.cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                scope.0 * 2 + 1,
            )
        };
        ctx.end_label(rec.cmd);
    }

    /// Reads every scope written since the last reset. Call after the submission completed.
    pub fn read(&self, ctx: &Context) -> Result<Vec<ScopeTiming>, GpuError> {
        let count = self.names.len() as u32 * 2;
        if count == 0 {
            return Ok(Vec::new());
        }
        let mut raw = vec![0u64; count as usize];
        // SAFETY: the queries were written by a completed submission; WAIT makes this robust anyway.
        unsafe {
            ctx.device.get_query_pool_results(
                self.pool,
                0,
                &mut raw,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .vk("vkGetQueryPoolResults")?;
        let fragments = match self.fragments {
            Some(pool) => {
                let mut counts = vec![0u64; self.names.len()];
                // SAFETY: as above; one 64-bit value per query (one statistic).
                unsafe {
                    ctx.device.get_query_pool_results(
                        pool,
                        0,
                        &mut counts,
                        vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                    )
                }
                .vk("vkGetQueryPoolResults")?;
                Some(counts)
            }
            None => None,
        };
        Ok(self
            .names
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let begin = raw[2 * i] & self.valid_mask;
                let end = raw[2 * i + 1] & self.valid_mask;
                let ticks = end.wrapping_sub(begin) & self.valid_mask;
                ScopeTiming {
                    name: name.clone(),
                    ms: ticks as f64 * self.period_ns * 1e-6,
                    fragments: fragments.as_ref().map(|counts| counts[i]),
                }
            })
            .collect())
    }
}
