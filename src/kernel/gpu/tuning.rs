//! The tiled kernel's shapes: vertex block, tile size and the simple kernel's workgroup, checked against the
//! kernels' layout rules and the device's limits.

use crate::gpu::Context;

/// Workgroup shapes and tile size, chosen by measurement (docs/kernel.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct KernelTuning {
    /// Invocations per workgroup of the simple kernel (1D over a patch's vertices).
    pub simple_workgroup: u32,
    /// Vertex block per workgroup of the tiled kernel (x, y).
    pub tiled_block: [u32; 2],
    /// Samples staged per tile by the tiled kernel.
    pub tile_size: u32,
}

impl Default for KernelTuning {
    /// The best of the sweep in docs/kernel.md (lavapipe): 8x4 vertex blocks, 1024-sample tiles then; 992 now
    /// that a staged sample carries its river's number (the most lavapipe's 32 KiB hold).
    fn default() -> Self {
        Self {
            simple_workgroup: 64,
            tiled_block: [8, 4],
            tile_size: 992,
        }
    }
}

impl KernelTuning {
    /// The default fitted to the device ([`Self::fitted`]); the renderer uses the measured choice
    /// ([`super::autotune::tuned`]).
    pub fn for_device(ctx: &Context) -> Self {
        let d = Self::default();
        Self::fitted(ctx, d.tiled_block, d.tile_size)
    }

    /// A tiled shape made valid on the device: the block grown until it holds whole subgroups of the device's
    /// largest size, the tile shrunk (by 32 samples, one mask word, at a time) to what the device's shared memory
    /// holds: lavapipe's 32 KiB take 992 samples.
    pub fn fitted(ctx: &Context, block: [u32; 2], tile_size: u32) -> Self {
        let mut t = Self {
            tiled_block: block,
            tile_size,
            ..Self::default()
        };
        while t.tiled_invocations() < ctx.subgroup.max_size {
            let [x, y] = t.tiled_block;
            t.tiled_block = if x > y { [x, y * 2] } else { [x * 2, y] };
        }
        let shared = ctx.properties.limits.max_compute_shared_memory_size;
        while t.tile_size > 32 && tiled_shared_bytes(t.tile_size, t.tiled_invocations()) > shared {
            t.tile_size -= 32;
        }
        t
    }

    /// Invocations per workgroup of the tiled kernel: one per vertex of the block.
    pub fn tiled_invocations(&self) -> u32 {
        self.tiled_block[0] * self.tiled_block[1]
    }

    /// Checks the tuning against the kernels' layout rules and the device's limits; the message names the value
    /// and its valid range.
    pub fn validate(&self, ctx: &Context) -> Result<(), String> {
        let limit = ctx.properties.limits.max_compute_work_group_invocations;
        let subgroup = ctx.subgroup.max_size.max(1);
        let [x, y] = self.tiled_block;
        let invocations = self.tiled_invocations();
        if self.simple_workgroup == 0 || self.simple_workgroup > limit {
            return Err(format!(
                "simple workgroup of {} invocations must be in [1, {limit}]",
                self.simple_workgroup
            ));
        }
        if !x.is_power_of_two() || !y.is_power_of_two() || !(x == y || x == 2 * y) {
            return Err(format!(
                "tiled block {x}x{y} must be powers of two, square or twice as wide as high (Morton layout)"
            ));
        }
        // The tiled kernel requires full subgroups of the largest size, which caps its workgroup at that many
        // subgroups.
        let limit = limit.min(subgroup.saturating_mul(ctx.subgroup.max_workgroup_subgroups.max(1)));
        if invocations > limit || invocations % subgroup != 0 {
            return Err(format!(
                "tiled block {x}x{y} has {invocations} invocations; it must be a multiple of the largest \
                 subgroup size {subgroup} and at most {limit}"
            ));
        }
        if self.tile_size == 0 || self.tile_size % 32 != 0 || self.tile_size > 32 * invocations {
            return Err(format!(
                "tile size {} must be a positive multiple of 32 (one reach-mask word) and at most 32 x the \
                 block's {invocations} invocations",
                self.tile_size
            ));
        }
        let shared = ctx.properties.limits.max_compute_shared_memory_size;
        let needed = tiled_shared_bytes(self.tile_size, invocations);
        if needed > shared {
            return Err(format!(
                "tile size {} needs {needed} bytes of shared memory; the device has {shared}",
                self.tile_size
            ));
        }
        Ok(())
    }
}

/// Shared memory of the tiled kernel: the staged samples (32 bytes each) and two counts per possible subgroup.
pub fn tiled_shared_bytes(tile_size: u32, invocations: u32) -> u32 {
    tile_size * 32 + 2 * invocations * 4
}
