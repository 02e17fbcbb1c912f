#version 460
// Pre-pass of the tiled kernel (docs/kernel.md): for each sample, an atomic OR sets the bit of that sample in the
// reach mask of every vertex block the sample can influence. Work is proportional to the (sample, block) pairs
// within reach, instead of every block testing every sample of its patch.
// One workgroup per row (y selects it in the job table); its invocations stride over the row's samples.
layout(local_size_x = 64) in;
layout(constant_id = 0) const uint BLOCK_X = 8;
layout(constant_id = 1) const uint BLOCK_Y = 4;
#include "river_kernel.glsl"
#include "kernel_blocks.glsl"

void main() {
    PatchJob job = jobs[params.firstJob + gl_WorkGroupID.y];
    uvec2 size = uvec2(BLOCK_X, BLOCK_Y);
    uvec2 count = blockCount(job, size);
    // A block's cell: its vertices and the gap to the next block, on the row's lattice.
    vec2 extent = vec2(size * latticeStride(job)) * job.spacing;
    vec2 origin = vec2(latticeParity(job)) * job.spacing;
    float reach = blockReach();
    vec2 limit = vec2(count) - 1.0;
    for (uint i = gl_LocalInvocationID.x; i < job.sampleCount; i += gl_WorkGroupSize.x) {
        vec2 p = samples[job.sampleOffset + i].positionDerivative.xy;
        // The blocks whose cells (a block's box plus the gap to the next block) the reach square touches; the
        // exact test below decides. Rounding cannot drop a block: a box ends a full vertex spacing before its
        // cell does, and a box just at the edge of the reach square is beyond the influence distance anyway
        // (blockReach). Clamped as floats first: a sample far outside the patch must not overflow the conversion.
        uvec2 lo = uvec2(clamp(floor((p - origin - reach) / extent), vec2(0.0), limit));
        uvec2 hi = uvec2(clamp(floor((p - origin + reach) / extent), vec2(0.0), limit));
        uint bit = 1u << (i % 32);
        for (uint y = lo.y; y <= hi.y; ++y) {
            for (uint x = lo.x; x <= hi.x; ++x) {
                if (blockInReach(job, uvec2(x, y), size, p)) {
                    atomicOr(reachMasks[reachMaskIndex(job, y * count.x + x, i / 32)], bit);
                }
            }
        }
    }
}
