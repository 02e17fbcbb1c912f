// Vertex blocks of the tiled kernel and the reach masks that say which samples can influence which block
// (docs/kernel.md). Included after river_kernel.glsl by kernel_reach.comp, which writes the masks, and by
// kernel_tiled.comp, which stages only the samples the masks name.
//
// A row's masks hold one bit per sample (words of 32 samples, in sample order) for each of its blocks; they start
// at the row's maskOffset, the sum of the mask words of the rows before it.
layout(set = 1, binding = 2, std430) buffer ReachMasks { uint reachMasks[]; };

// How far a sample may be from a block's bounding box and still influence one of its vertices: the influence
// distance, with a margin so that f32 rounding never drops a sample the per-vertex test keeps.
float blockReach() {
    return params.influenceDistance * 1.0001 + 1e-4;
}

// Blocks along x and y of a row's lattice.
uvec2 blockCount(PatchJob job, uvec2 blockSize) {
    return (latticeSize(job) + blockSize - 1) / blockSize;
}

// Whether `p` is within reach of the bounding box of block `b` (from its first to its last vertex).
bool blockInReach(PatchJob job, uvec2 b, uvec2 blockSize, vec2 p) {
    uvec2 first = b * blockSize;
    uvec2 last = min(first + blockSize, latticeSize(job)) - 1;
    vec2 boxMin = vec2(patchVertex(job, first)) * job.spacing;
    vec2 boxMax = vec2(patchVertex(job, last)) * job.spacing;
    return length(p - clamp(p, boxMin, boxMax)) <= blockReach();
}

// Mask words per block of a row: one bit per sample.
uint wordsOf(PatchJob job) {
    return (job.sampleCount + 31) / 32;
}

// Index of word `word` of block `block` (row-major over the row's blocks) in reachMasks.
uint reachMaskIndex(PatchJob job, uint block, uint word) {
    return job.maskOffset + block * wordsOf(job) + word;
}
