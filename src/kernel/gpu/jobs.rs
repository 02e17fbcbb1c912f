//! The range table of a dispatch (std430 rows the kernels read, glsl/river_kernel.glsl): which samples, output
//! texture's place, reach masks and vertex lattice each row covers.

use super::KernelBatch;
pub use crate::shader_types::GpuPatchJob;

/// `parent_place` of a row computed by the kernel.
pub const NO_PARENT: u32 = u32::MAX;

impl GpuPatchJob {
    /// Reach-mask words per vertex block of this row: one bit per sample.
    pub fn mask_words(&self) -> u32 {
        self.sample_count.div_ceil(32)
    }

    /// Vertices along x and y of this row's lattice in an `n x n` patch.
    pub fn lattice_size(&self, n: u32) -> [u32; 2] {
        let stride = self.lattice & 0xff;
        let parity = [(self.lattice >> 8) & 0xff, (self.lattice >> 16) & 0xff];
        parity.map(|p| (n - p).div_ceil(stride))
    }
}

/// The rows of a batch (patches computed from scratch first, then the four rows of each patch that takes river
/// data from its parent) and where each patch's samples start in the sample buffer.
pub struct RangeTable {
    /// One per dispatched grid of vertices.
    pub rows: Vec<GpuPatchJob>,
    /// Rows over all vertices of a patch (the first ones); the rest cover every second vertex.
    pub full_rows: usize,
    /// Per patch, the index of its first sample in the sample buffer.
    pub sample_offsets: Vec<u32>,
    /// Reach-mask words of all rows, with blocks of `block` vertices.
    pub mask_words: u64,
}

/// The range table of `batch` for `n x n` patches and the tiled kernel's `block`.
pub fn range_table(batch: &KernelBatch, n: u32, block: [u32; 2]) -> RangeTable {
    let mut sample_offsets = Vec::with_capacity(batch.jobs.len());
    let mut offset = 0;
    for job in batch.jobs {
        sample_offsets.push(offset);
        offset += job.samples.len() as u32;
    }
    let parent = |k: usize| batch.parents.get(k).copied().flatten();
    let row = |k: usize, lattice: u32, parent_place: u32, parent_offset: u32| GpuPatchJob {
        spacing: batch.jobs[k].spacing,
        sample_offset: sample_offsets[k],
        sample_count: if parent_place == NO_PARENT {
            batch.jobs[k].samples.len() as u32
        } else {
            0
        },
        place: batch.places[k].shader_index(),
        mask_offset: 0,
        lattice,
        parent_place,
        parent_offset,
    };
    let mut rows: Vec<GpuPatchJob> = (0..batch.jobs.len())
        .filter(|&k| parent(k).is_none())
        .map(|k| row(k, 1, NO_PARENT, 0))
        .collect();
    let full_rows = rows.len();
    for k in 0..batch.jobs.len() {
        if let Some((place, quadrant)) = parent(k) {
            let [x, y] = quadrant.offset;
            rows.push(row(k, 2, place.shader_index(), x | y << 16));
            for parity in [[1, 0], [0, 1], [1, 1]] {
                rows.push(row(k, 2 | parity[0] << 8 | parity[1] << 16, NO_PARENT, 0));
            }
        }
    }
    let mut mask_words = 0u64;
    for r in &mut rows {
        r.mask_offset = mask_words as u32;
        let [lx, ly] = r.lattice_size(n);
        mask_words += (r.mask_words() * lx.div_ceil(block[0]) * ly.div_ceil(block[1])) as u64;
    }
    RangeTable {
        rows,
        full_rows,
        sample_offsets,
        mask_words,
    }
}
